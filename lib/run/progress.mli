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

(** {1 What a command's options ask for} *)

val for_options : Options.t -> label:string -> total:int -> t
(** The progress report the options ask for: redrawn in place on a terminal, lines with
    [--progress] otherwise, nothing with [--quiet]. *)

val build : Options.t -> ((string -> unit) -> 'a) -> 'a * float
(** [build o f] runs [f say], the building of a scene (loading, evaluation, acceleration
    structure), and times it: [say what] shows what it is doing ("building: what…",
    redrawn in place on a terminal, a line with [--progress], nothing otherwise), and the
    line is cleared when [f] returns or raises. The result and the seconds it took. *)

val writing : Options.t -> string -> (unit -> 'a) -> 'a
(** [writing o path f] runs [f] (the write of [path]) under a progress note,
    [writing PATH]: redrawn in place on a terminal and cleared after, a line with
    [--progress], nothing otherwise. A large PNG takes seconds to compress. *)
