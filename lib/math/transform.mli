(** Affine transforms of space (translate, rotate, scale), with their inverses cached.

    A transform maps object space to world space. Transforms written in a scene apply in
    the order written: [then_ a b] applies [a] first, then [b]. Rotations are in degrees
    about the world axes, X then Y then Z, left-handed as in POV-Ray. Normals go through
    the inverse transpose. *)

type t

val identity : t
(** The transform that moves nothing. *)

val translate : Vec3.t -> t
(** [translate d] moves every point by [d]. *)

val scale : Vec3.t -> t
(** [scale s] scales each axis; components must be non-zero (the loader checks). *)

val rotate : Vec3.t -> t
(** [rotate (ax, ay, az)] rotates by ax degrees about X, then ay about Y, then az about Z.
*)

val then_ : t -> t -> t
(** [then_ a b] is the transform that applies [a], then [b]. *)

val is_identity : t -> bool
(** Whether the transform is the identity (so callers can skip it). *)

val similarity : t -> float option
(** [Some s] when [t] is not the identity and scales every length by [s] (rotations,
    mirrors, one scale on the three axes, moves): its linear part's columns have the same
    length [s] and are orthogonal, to 1e-12 of their squared length. [None] otherwise. *)

val translation : t -> (Vec3.t * Vec3.t) option
(** [Some (d, e)] when [t] is not the identity and only moves points, its linear part and
    its inverse's exactly the identity: [t] adds [d] to a point and its inverse adds [e]
    (−d, up to the rounding of the transforms composed). [None] otherwise. *)

val point : t -> Vec3.t -> Vec3.t
(** Object-space point to world space. *)

val vector : t -> Vec3.t -> Vec3.t
(** Object-space direction to world space (no translation). *)

val normal : t -> Vec3.t -> Vec3.t
(** Object-space normal to world space by the inverse transpose, normalised. *)

val inv_point : t -> Vec3.t -> Vec3.t
(** World-space point to object space. *)

val inv_vector : t -> Vec3.t -> Vec3.t
(** World-space direction to object space (not renormalised). *)

val inv_px : t -> float -> float -> float -> float
(** [inv_px t x y z] is the x coordinate of [inv_point t (x, y, z)] for a transform that
    is not the identity; [inv_py], [inv_pz] likewise. Inlined: nothing is boxed. *)

val inv_py : t -> float -> float -> float -> float
val inv_pz : t -> float -> float -> float -> float

val inv_vx : t -> float -> float -> float -> float
(** [inv_vx t x y z] is the x coordinate of [inv_vector t (x, y, z)] for a transform that
    is not the identity; [inv_vy], [inv_vz] likewise. *)

val inv_vy : t -> float -> float -> float -> float
val inv_vz : t -> float -> float -> float -> float

val normal_x : t -> float -> float -> float -> float
(** [normal_x t x y z] is the x coordinate of the normal (x, y, z) taken to world space by
    the inverse transpose, before {!normal} normalises it, for a transform that is not the
    identity; [normal_y], [normal_z] likewise. Inlined: nothing is boxed. *)

val normal_y : t -> float -> float -> float -> float
val normal_z : t -> float -> float -> float -> float
