(** [Float.min] and [Float.max] at the cost of a comparison or two.

    The stdlib's make two C calls for sign bits on every pair; these give the same result
    for every pair (NaN and signed zeros included) and reach the stdlib's only when the
    two compare equal or one is NaN, which the hot paths rarely meet. *)

val min : float -> float -> float
(** The same as [Float.min]. *)

val max : float -> float -> float
(** The same as [Float.max]. *)

val above : float -> float
(** [above t] is a float at or above [Float.succ t], and for a positive finite [t] at most
    [Float.succ (Float.succ t)] (or infinity, past the largest float): a bound that keeps
    every value [<= t] strictly below it, without [Float.succ]'s C call in the common
    case. [Float.succ t] itself where [t] is zero, negative, subnormal, infinite or NaN.
*)
