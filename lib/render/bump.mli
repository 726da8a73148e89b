(** Bump maps: perturbations of the shading normal (a material's [bump:]). *)

type t = Framebuffer.t Description.bump_of
(** The description's bump map ({!Lancer_description.Description.bump_of}, where each kind
    is defined) with its height map decoded to a linear framebuffer. *)

val perturb : t -> uv:(Vec3.t -> float * float) -> Vec3.t -> Vec3.t -> Vec3.t
(** [perturb b ~uv p n] is the unit shading normal at object-space point [p] with unit
    normal [n] (world space, facing the viewer). [uv d] is the surface's (u, v) at the hit
    point moved by the world-space vector [d] (within the tangent plane): image maps
    differentiate it to find the surface directions of u and v. The result stays on the
    side of [n]. *)
