(** The scratch of one shading step, as scalars: a point, a normal, texture coordinates
    and a colour, in one flat record of floats that the functions computing them read and
    write in place. Nothing is boxed and no vector is built: the form in which shading
    asks shapes, primitives and textures about a hit point.

    The fields are registers rather than a fixed meaning: each function says what it reads
    and what it writes (see {!Shape.normal_into}, {!Lancer_render.Primitive.normal_into},
    {!Lancer_render.Texture.eval_into}). A fragment is scratch, owned by one domain at a
    time. *)

type t = {
  mutable x : float;
  mutable y : float;
  mutable z : float;  (** a point *)
  mutable nx : float;
  mutable ny : float;
  mutable nz : float;  (** a normal *)
  mutable u : float;
  mutable v : float;  (** texture coordinates *)
  mutable r : float;
  mutable g : float;
  mutable b : float;  (** a colour *)
}

val create : unit -> t
(** A fresh fragment, all zero. *)

val set_point : t -> float -> float -> float -> unit
(** [set_point f x y z] makes (x, y, z) the point. *)

val point : t -> Vec3.t
(** The point, as a vector (allocated). *)

val set_normal : t -> Vec3.t -> unit
(** [set_normal f n] copies [n] into the normal. *)

val set_color : t -> Color.t -> unit
(** [set_color f c] copies [c] into the colour. *)
