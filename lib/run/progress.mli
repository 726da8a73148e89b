(** Progress of a long command: units done, rays per second, elapsed and time left, from
    any domain. On a terminal one line redrawn in place a few times a second; otherwise a
    full line every few seconds (for logs, and for mpirun, which forwards lines). *)

type t

type mode =
  | Off
  | Terminal  (** one line, redrawn in place a few times a second *)
  | Lines  (** a full line every few seconds, for logs and for mpirun *)

val interval_variable : string
(** ["LANCER_PROGRESS_INTERVAL"]: the environment variable that sets the seconds between
    two lines when stderr is not a terminal (0: a line at every unit; [off]: none, unless
    [--progress] asks for them), for a log that wants them more or less often, and for
    tests. *)

val interval : default:float -> float option
(** The seconds between two lines that {!interval_variable} sets: [None] for [off],
    [default] when it is unset or not a number of seconds (at least 0). *)

val create :
  ?mode:mode -> ?every:float -> ?wait:bool -> label:string -> total:int -> unit -> t
(** [create ~label ~total ()] is [Terminal] when stderr is a terminal, else [Off]. [every]
    is the seconds between two lines (default: 0.2 on a terminal; for [Lines], 2 or what
    {!interval_variable} says); with [wait] the first line waits that long too, and the
    last unit is shown only if a line was. *)

val update : ?rays:int -> ?share:float -> t -> int -> unit
(** [update p done_] records that [done_] of the total units are finished, and [rays] more
    rays cast (the line then shows rays per second rather than units per second). The
    share of the work done (0 to 1), from which the percentage and the time left are
    worked out, is [done_ / total] unless [share] says otherwise (units of unequal cost).
    Thread-safe. *)

val hms : float -> string
(** A duration in seconds as a person reads it: ["8s"], ["2m05s"], ["1h03m"]. *)

val line :
  label:string ->
  done_:int ->
  total:int ->
  ?share:float ->
  elapsed:float ->
  rays:int ->
  unit ->
  string
(** The text of a line: ["tiles 12/35 ( 34%)  2.10 M rays/s  elapsed 4s  left 8s"], the
    time left being elapsed × (1 − share) / share (["?"] before any work is done). *)

val finish : t -> unit
(** Clears the line. *)

(** {1 What a command's options ask for} *)

val for_options : Options.t -> label:string -> total:int -> t
(** The progress report the options ask for: redrawn in place on a terminal; otherwise
    with [--progress] a line every 2 seconds from the start, and without it a line every 5
    seconds once the command has run that long (either interval as {!interval_variable}
    sets it); nothing with [--quiet]. *)

val build : Options.t -> ((string -> unit) -> 'a) -> 'a * float
(** [build o f] runs [f say], the building of a scene (loading, evaluation, acceleration
    structure), and times it: [say what] shows what it is doing ("building: what…",
    redrawn in place on a terminal, a line with [--progress], nothing otherwise), and the
    line is cleared when [f] returns or raises. The result and the seconds it took. *)

val writing : Options.t -> string -> (unit -> 'a) -> 'a
(** [writing o path f] runs [f] (the write of [path]) under a progress note,
    [writing PATH]: redrawn in place on a terminal and cleared after, a line with
    [--progress], nothing otherwise. A large PNG takes seconds to compress. *)
