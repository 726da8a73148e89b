(** Ray and sample counters. Each render task owns one and they are summed at the end, so
    the counts are exact and deterministic whatever the number of domains. *)

type t = {
  mutable primary : int;
  mutable shadow : int;
  mutable reflected : int;
  mutable refracted : int;
  mutable bad_samples : int;  (** samples that came out NaN or infinite *)
  mutable first_bad : (int * int) option;  (** a pixel (column, row) with a bad sample *)
}

val create : unit -> t
(** Counters at zero. *)

val add_into : t -> t -> unit
(** [add_into acc s] adds [s]'s counts to [acc]. *)

val total_rays : t -> int
(** Primary, shadow, reflected and refracted rays together. *)
