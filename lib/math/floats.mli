(** [Float.min] and [Float.max] at the cost of a comparison or two.

    The stdlib's make two C calls for sign bits on every pair; these give the same result
    for every pair (NaN and signed zeros included) and reach the stdlib's only when the
    two compare equal or one is NaN, which the hot paths rarely meet. *)

val min : float -> float -> float
(** The same as [Float.min]. *)

val max : float -> float -> float
(** The same as [Float.max]. *)
