(** A progress line on a terminal: units done, rays per second, elapsed and time left, redrawn at
    most a few times a second, from any domain. Silent when stderr is not a terminal or
    when disabled. *)

type t

val create : ?enabled:bool -> label:string -> total:int -> unit -> t
(** [create ~label ~total ()] is enabled by default only when stderr is a terminal. *)

val update : ?rays:int -> t -> int -> unit
(** [update p done_] records that [done_] of the total units are finished, and [rays] more
    rays cast (the line then shows rays per second rather than units per second).
    Thread-safe. *)

val finish : t -> unit
(** Clears the line. *)
