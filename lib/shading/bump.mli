(** Bump maps: perturbations of the shading normal (SPEC §2.5, [bump:]). *)

type t = Noise of { scale : float; amount : float }
    (** gradient of 3-D Perlin noise at P/scale, times amount *)

val perturb : t -> Vec3.t -> Vec3.t -> Vec3.t
(** [perturb b p n] is the unit shading normal at object-space point [p] with unit
    geometric normal [n]. *)
