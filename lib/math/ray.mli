(** Rays: an origin and a unit direction, with the reciprocal direction cached for
    bounding-box slab tests.

    The type is abstract so the direction is always normalised and [inv_dir] always
    matches it. Object-space rays (after an inverse transform) are built with {!make_raw}:
    their direction is not renormalised, so a parameter t means the same point in world
    and object space. *)

type t

val make : Vec3.t -> Vec3.t -> t
(** [make origin dir] is the ray from [origin] along [normalize dir]. *)

val make_raw : Vec3.t -> Vec3.t -> t
(** [make_raw origin dir] keeps [dir] as given (possibly not unit length). *)

val origin : t -> Vec3.t
(** The ray's origin. *)

val dir : t -> Vec3.t
(** The ray's direction: unit length unless built by {!make_raw}. *)

val inv_dir : t -> Vec3.t
(** Component-wise 1/dir; ±infinity for a zero component. *)

val at : t -> float -> Vec3.t
(** [at r t] is origin + t·dir. *)
