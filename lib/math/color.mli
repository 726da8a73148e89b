(** Linear RGB colours.

    Every colour inside lancer is linear RGB with components nominally in [0, 1] but not
    clamped (lights may be brighter than 1). sRGB appears only when an image is encoded
    ({!Lancer_image.Image}) or an image texture is decoded. *)

type t = { r : float; g : float; b : float }

val v : float -> float -> float -> t
(** [v r g b] is the colour (r, g, b). *)

val black : t
(** (0, 0, 0). *)

val white : t
(** (1, 1, 1). *)

val add : t -> t -> t
(** Component-wise sum. *)

val mul : t -> t -> t
(** [mul a b] is the component-wise (filter) product a ⊙ b. *)

val scale : float -> t -> t
(** [scale s c] is [s·c]. *)

val madd : t -> float -> t -> t
(** [madd a s b] is [a + s·b]. *)

val of_vec3 : Vec3.t -> t
(** The vector (x, y, z) read as the colour (r, g, b). *)

val to_vec3 : t -> Vec3.t
(** The colour (r, g, b) as the vector (x, y, z). *)

val is_finite : t -> bool
(** [is_finite c] is false when any component is NaN or infinite. *)
