(** A progress line on a terminal: units done, rays per second, elapsed and time left,
    redrawn at most a few times a second, from any domain. Silent when stderr is not a
    terminal or when disabled. *)

type t

type mode =
  | Off
  | Terminal  (** one line, redrawn in place a few times a second *)
  | Lines  (** a full line every 2 s, for logs and for mpirun, which forwards lines *)

val create : ?mode:mode -> label:string -> total:int -> unit -> t
(** [create ~label ~total ()] is [Terminal] when stderr is a terminal, else [Off]. *)

val update : ?rays:int -> t -> int -> unit
(** [update p done_] records that [done_] of the total units are finished, and [rays] more
    rays cast (the line then shows rays per second rather than units per second).
    Thread-safe. *)

val finish : t -> unit
(** Clears the line. *)
