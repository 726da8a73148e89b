(** A progress line on a terminal: units done, rate, elapsed and time left, redrawn at
    most a few times a second, from any domain. Silent when stderr is not a terminal or
    when disabled. *)

type t

val create : ?enabled:bool -> label:string -> total:int -> unit -> t
(** [create ~label ~total ()] is enabled by default only when stderr is a terminal. *)

val update : t -> int -> unit
(** [update p done_] records that [done_] of the total units are finished. Thread-safe. *)

val finish : t -> unit
(** Clears the line. *)
