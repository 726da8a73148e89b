(** Bump maps: perturbations of the shading normal (a material's [bump:]). *)

type t =
  | Noise of { scale : float; amount : float }
      (** gradient of 3-D Perlin noise at P/scale, times amount *)
  | Image of { img : Image.t; amount : float }
      (** a height map on (u, v): the luminance of the linear image, sampled bilinearly
          with wrapping; the normal tilts by amount × (height change per texel) along the
          surface directions in which u and v grow *)

val perturb : t -> uv:(Vec3.t -> float * float) -> Vec3.t -> Vec3.t -> Vec3.t
(** [perturb b ~uv p n] is the unit shading normal at object-space point [p] with unit
    normal [n] (world space, facing the viewer). [uv d] is the surface's (u, v) at the hit
    point moved by the world-space vector [d] (within the tangent plane): image maps
    differentiate it to find the surface directions of u and v. The result stays on the
    side of [n]. *)
