type t = {
  position : Vec3.t;
  look_at : Vec3.t;
  up : Vec3.t;
  fov : float;
  f : Vec3.t;
  r : Vec3.t;
  u : Vec3.t;
  h : float;
}

let make ?(position = Vec3.v 0. 0. (-5.)) ?(look_at = Vec3.zero) ?(up = Vec3.y_axis) ?(fov = 60.) () =
  let f = Vec3.normalize (Vec3.sub look_at position) in
  let r = Vec3.normalize (Vec3.cross up f) in
  let u = Vec3.cross f r in
  let h = Float.tan (fov *. Float.pi /. 360.) in
  { position; look_at; up; fov; f; r; u; h }

let default = make ()

let validate c =
  if Vec3.length2 (Vec3.sub c.look_at c.position) = 0. then Error "camera look_at must differ from position"
  else if Vec3.length2 c.r = 0. then Error "camera up must not be parallel to the view direction"
  else if not (c.fov > 0. && c.fov < 180.) then Error (Printf.sprintf "camera fov must be in (0, 180) degrees (got %g)" c.fov)
  else Ok ()

let ray c ~width ~height x y =
  let a = Float.of_int width /. Float.of_int height in
  let sx = ((2. *. x /. Float.of_int width) -. 1.) *. c.h *. a in
  let sy = (1. -. (2. *. y /. Float.of_int height)) *. c.h in
  (* f + (sx·r + sy·u), component by component (one allocation instead of four). *)
  let f = c.f and r = c.r and u = c.u in
  let d = Vec3.v (f.x +. ((sx *. r.x) +. (sy *. u.x))) (f.y +. ((sx *. r.y) +. (sy *. u.y))) (f.z +. ((sx *. r.z) +. (sy *. u.z))) in
  Ray.make c.position d
