(** Three-dimensional vectors of doubles: points, directions and normals.

    A record of three floats, stored flat by the compiler. Coordinates are left-handed
    world units (x right, y up, z into the screen for the default camera). No function
    here checks for NaN: callers that divide guard their own denominators. *)

type t = { x : float; y : float; z : float }

val v : float -> float -> float -> t
(** [v x y z] is the vector (x, y, z). *)

val zero : t
(** (0, 0, 0). *)

val one : t
(** (1, 1, 1). *)

val x_axis : t
(** (1, 0, 0). *)

val y_axis : t
(** (0, 1, 0). *)

val z_axis : t
(** (0, 0, 1). *)

val add : t -> t -> t
(** [add a b] is [a + b]. *)

val sub : t -> t -> t
(** [sub a b] is [a − b]. *)

val neg : t -> t
(** [neg a] is [−a]. *)

val mul : t -> t -> t
(** [mul a b] is the component-wise product. *)

val smul : float -> t -> t
(** [smul s v] is [s·v]. *)

val madd : t -> float -> t -> t
(** [madd a s b] is [a + s·b], in one allocation. *)

val dot : t -> t -> float
(** [dot a b] is the scalar product a·b. *)

val cross : t -> t -> t
(** [cross a b] is the vector product a × b. *)

val length : t -> float
(** [length v] is |v|, computed with [Float.hypot]-style scaling only where needed: plain
    [sqrt (dot v v)] overflows above about 1.3e154. *)

val length3 : float -> float -> float -> float
(** [length3 x y z] is [length (v x y z)], bit for bit, without building the vector in the
    common range: for callers that hold a vector as scalars. *)

val length2 : t -> float
(** [length2 v] is [dot v v]. *)

val normalize : t -> t
(** [normalize v] is [v / |v|]; the zero vector stays zero (never NaN). *)

val max_abs : t -> float
(** [max_abs v] is max(|x|, |y|, |z|), the scale of a point for ray offsets. *)

val min : t -> t -> t
(** Component-wise minimum (typed float comparison; NaN-free inputs assumed). *)

val max : t -> t -> t
(** Component-wise maximum (typed float comparison; NaN-free inputs assumed). *)

val equal_f : ?eps:float -> t -> t -> bool
(** [equal_f ~eps a b] holds when each component differs by at most [eps] (default 1e-9).
*)
