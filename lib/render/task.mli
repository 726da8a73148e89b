(** What one render task carries while it traces: its counts of rays and bad samples (read
    out as {!Counters.t} when it is done), the cancellation token it polls, and the
    secondary rays the current camera sample may still cast. Each task (a tile) owns one,
    touched by every ray, so its fields are mutable and padded apart from the next task's.
*)

type t = {
  mutable primary : int;
  mutable shadow : int;
  mutable reflected : int;
  mutable refracted : int;
  mutable bad_samples : int;  (** samples that came out NaN or infinite *)
  mutable first_bad : (int * int) option;  (** a pixel (column, row) with a bad sample *)
  cancel : Cancel.t;  (** polled by {!tick} *)
  mutable until_poll : int;
      (** units of work (a ray, a CSG test) left before {!spend} polls [cancel] again *)
  mutable budget : int;  (** secondary rays the current camera sample may still cast *)
  mutable noise_sq : int;  (** as {!Counters.t}'s *)
  mutable noise_n : int;  (** as {!Counters.t}'s *)
  _p0 : int;
  _p1 : int;
  _p2 : int;
  _p3 : int;
  _p4 : int;
  _p5 : int;
  _p6 : int;
  _p7 : int;
  _p8 : int;
  _p9 : int;
  _p10 : int;
  _p11 : int;
  _p12 : int;
  _p13 : int;
  _p14 : int;
  _p15 : int;
      (** two cache lines of nothing after the counters (processors fetch lines in pairs):
          the counters of tasks made one after the other (so side by side in memory) that
          two domains run are never in one cache line, which every ray's count would
          otherwise pass between the cores *)
}

val create : ?cancel:Cancel.t -> unit -> t
(** Counts at zero, polling [cancel] (default: a token nobody cancels). *)

val tick : t -> unit
(** Called once per ray traced: [spend s 1]. *)

val spend : t -> int -> unit
(** [spend s n] counts [n] units of work done: once every
    {!Lancer_diag.Cancel.check_every} units it polls the token and raises [Sys.Break] if
    it is cancelled. A ray is one unit; so is each test of a simple surface inside a CSG
    object (a root sought, a point tested against its inside), which is how a ray that
    costs seconds (through a CSG object of thousands of members) still stops within
    milliseconds. A shadow ray's first try at a difference of simple surfaces (its first
    member's roots and a few points, bounded by the members' count) counts within the
    ray's own unit. Allocates nothing. *)

val current : unit -> t
(** The counters of the task that the calling domain runs inside {!with_current}, for the
    work that is not handed them (a CSG object's crossings, deep in a query); outside any,
    counters whose token nobody cancels. *)

val with_current : t -> (unit -> 'a) -> 'a
(** [with_current s f] runs [f] with [s] as the calling domain's {!current} counters, and
    puts back the ones before when it returns or raises. *)

val counters : t -> Counters.t
(** What the task has counted so far. *)
