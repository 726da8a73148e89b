(** Axis-aligned bounding boxes in world space, for the bounding volume hierarchy. *)

type t = { min : Vec3.t; max : Vec3.t }

val empty : t
(** The box that contains nothing (min = +inf, max = −inf); [union empty b = b]. *)

val of_points : Vec3.t list -> t
(** The smallest box containing the points; {!empty} for no point. *)

val union : t -> t -> t
(** The smallest box containing both boxes. *)

val centroid : t -> Vec3.t
(** The centre of the box, halfway between [min] and [max]. *)

val surface_area : t -> float
(** Surface area; 0 for an empty or flat box. *)

val transform : Transform.t -> t -> t
(** [transform m b] bounds the image of [b]'s eight corners under [m]. *)

val hit : t -> Ray.t -> float -> float -> bool
(** [hit b r tmin tmax] is whether [r] meets [b] for some t in [tmin, tmax] (slab test with
    the cached inverse direction; NaN from 0·inf counts as a hit, never a miss). *)
