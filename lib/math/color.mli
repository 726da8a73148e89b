(** Linear RGB colours.

    Every colour inside lancer is linear RGB with components nominally in [0, 1] but not
    clamped (lights may be brighter than 1). sRGB appears only when an image is encoded
    ({!Image}) or an image texture is decoded. *)

type t = { r : float; g : float; b : float }

val v : float -> float -> float -> t
val black : t
val white : t
val add : t -> t -> t
val mul : t -> t -> t
(** [mul a b] is the component-wise (filter) product a ⊙ b. *)

val scale : float -> t -> t
val madd : t -> float -> t -> t
(** [madd a s b] is [a + s·b]. *)

val of_vec3 : Vec3.t -> t
val to_vec3 : t -> Vec3.t
val is_finite : t -> bool
(** [is_finite c] is false when any component is NaN or infinite. *)

val max_component : t -> float
val equal_f : ?eps:float -> t -> t -> bool
val pp : Format.formatter -> t -> unit
