(** Deterministic integer hashing into \[0, 1): the only source of "randomness" in lancer
    (sample jitter and [rand(seed)] in scenes; area lights use a fixed stratified
    pattern). Pure functions of their arguments, so results never depend on domains, ranks
    or run order. *)

val mix : int -> int
(** A 63-bit avalanche mix (SplitMix64's finaliser on OCaml ints). *)

val combine : int -> int -> int
(** [combine h x] folds [x] into hash state [h]. *)

val to_unit : int -> float
(** [to_unit h] maps a hash to a float in \[0, 1) using its top 52 bits. *)

val of_float : float -> float
(** [of_float x] is a hash of the bits of [x] in \[0, 1) ([rand] in scenes); −0 and 0
    agree. *)
