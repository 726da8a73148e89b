(** What the primary ray through each pixel's centre meets: the object, the distance and
    the shading normal, one ray per pixel and no jitter, for images that say which object
    a pixel shows (arbitrary output variables beside the colour).

    The ray is the camera's ray through the point (i + ½, j + ½) of pixel (i, j): the
    pinhole ray of a camera with depth of field, none for a fisheye point outside its
    circle. The scene seen is the one given, never its {!Scene.moments}. *)

type t = {
  width : int;
  height : int;
  item : int array;
      (** row-major, per pixel: the index in [objects] of the scene of the primitive hit
          nearest, −1 where the ray meets nothing *)
  depth : Float.Array.t;
      (** per pixel: the distance along the (unit) ray to that hit, +∞ where none *)
  normal : Float.Array.t;
      (** three per pixel: the unit normal shading uses there (turned towards the ray, a
          bump map's perturbation included), 0 where none *)
}

val primary : Scene.t -> t
(** [primary scene]: the image of the scene's [width]×[height] pixels, on the calling
    domain. Its hot loop allocates nothing but for a bump map's normal. *)
