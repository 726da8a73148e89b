(** Framebuffers: what a render writes, linear RGB floats, row-major from the top-left
    pixel. {!Image} encodes them into image files, {!Raster} is an encoded image. *)

type t = {
  width : int;
  height : int;
  data : Float.Array.t;  (** 3·width·height linear floats *)
}

val create : int -> int -> t
(** [create w h] is a black framebuffer of [w] columns and [h] rows. *)

val get : t -> int -> int -> Color.t
(** [get fb i j] is the colour of column [i], row [j]. *)

val set : t -> int -> int -> Color.t -> unit
(** [set fb i j c] stores colour [c] at column [i], row [j]. *)

val set_rgb : t -> int -> int -> float -> float -> float -> unit
(** [set_rgb fb i j r g b] is [set fb i j (Color.v r g b)] without building the colour
    (inlined: nothing is boxed). *)
