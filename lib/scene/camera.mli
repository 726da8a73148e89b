(** The pinhole camera (doc/shading.md, section 1): left-handed, vertical field of view, pixel centres.

    With f = normalize(look_at − position), r = normalize(up × f), u = f × r,
    h = tan(fov/2) and a = W/H, the ray through image point (x, y), in pixel units from
    the top-left corner, has direction normalize(f + ((2x/W − 1)·h·a)·r + ((1 − 2y/H)·h)·u). *)

type t = private {
  position : Vec3.t;
  look_at : Vec3.t;
  up : Vec3.t;
  fov : float;  (** vertical field of view, degrees, in (0, 180) *)
  f : Vec3.t;
  r : Vec3.t;
  u : Vec3.t;
  h : float;
}

val make : ?position:Vec3.t -> ?look_at:Vec3.t -> ?up:Vec3.t -> ?fov:float -> unit -> t
(** Defaults: position (0,0,−5), look_at origin, up (0,1,0), fov 60. *)

val default : t
(** The camera of {!make} with every default: at (0, 0, −5) looking at the origin. *)

val validate : t -> (unit, string) result
(** [Error] when look_at = position, up is parallel to the view direction, or fov is
    outside (0, 180). *)

val ray : t -> width:int -> height:int -> float -> float -> Ray.t
(** [ray c ~width ~height x y] is the primary ray through image point (x, y). *)
