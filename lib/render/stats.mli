(** Ray and sample counters, and the cancellation token of the work they count. Each
    render task owns one and they are summed at the end, so the counts are exact and
    deterministic whatever the number of domains. *)

type t = {
  mutable primary : int;
  mutable shadow : int;
  mutable reflected : int;
  mutable refracted : int;
  mutable bad_samples : int;  (** samples that came out NaN or infinite *)
  mutable first_bad : (int * int) option;  (** a pixel (column, row) with a bad sample *)
  cancel : Cancel.t;  (** polled by {!tick} *)
  mutable until_poll : int;  (** rays left before {!tick} polls [cancel] again *)
  mutable budget : int;  (** secondary rays the current camera sample may still cast *)
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
      (** two cache lines of nothing after the counters (processors fetch lines in
          pairs): the counters of tasks made one after the other (so side by side in
          memory) that two domains run are never in one cache line, which every ray's
          count would otherwise pass between the cores *)
}

val create : ?cancel:Cancel.t -> unit -> t
(** Counters at zero, polling [cancel] (default: a token nobody cancels). *)

val tick : t -> unit
(** Called once per ray traced: every {!Cancel.check_every} calls it polls the token and
    raises [Sys.Break] if it is cancelled. Allocates nothing. *)

val add_into : t -> t -> unit
(** [add_into acc s] adds [s]'s counts to [acc]. *)

val total_rays : t -> int
(** Primary, shadow, reflected and refracted rays together. *)
