(** Ken Perlin's improved gradient noise (2002), deterministic: the permutation table is
    generated from a fixed seed, so every run and every domain sees the same field. *)

val perlin : float -> float -> float -> float
(** [perlin x y z] is smooth noise in about [−1, 1], zero at integer lattice points. *)

val turbulence : ?octaves:int -> Vec3.t -> float
(** [turbulence p] is Σ |perlin(2^i·p)| / 2^i over [octaves] (default 6), in \[0, ~2). *)

val gradient : float -> float -> float -> Vec3.t
(** [gradient x y z] is the gradient of [perlin] by central differences. *)
