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

val transform : Transform.t -> t -> t
(** [transform m b] bounds the image of [b]'s eight corners under [m]. *)
