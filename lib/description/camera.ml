type kind = Perspective | Orthographic of { width : float } | Fisheye

type t = {
  kind : kind;
  position : Vec3.t;
  look_at : Vec3.t;
  up : Vec3.t;
  fov : float;
  aperture : float;
  focal_distance : float;
  lens_samples : int;
  shutter : float * float;
  shutter_samples : int;
  f : Vec3.t;
  r : Vec3.t;
  u : Vec3.t;
  h : float;
  pinhole : bool;
}

let default_shutter_samples = 8
let kind_names = [ "perspective"; "orthographic"; "fisheye" ]

let make ?(kind = Perspective) ?(position = Vec3.v 0. 0. (-5.)) ?(look_at = Vec3.zero)
    ?(up = Vec3.y_axis) ?(fov = 60.) ?(aperture = 0.) ?(focal_distance = 1.)
    ?(lens_samples = 1) ?(shutter = (0., 0.)) ?(shutter_samples = default_shutter_samples)
    () =
  let f = Vec3.normalize (Vec3.sub look_at position) in
  let r = Vec3.normalize (Vec3.cross up f) in
  let u = Vec3.cross f r in
  let h = Float.tan (fov *. Float.pi /. 360.) in
  let pinhole =
    match kind with Perspective -> aperture = 0. | Orthographic _ | Fisheye -> false
  in
  {
    kind;
    position;
    look_at;
    up;
    fov;
    aperture;
    focal_distance;
    lens_samples;
    shutter;
    shutter_samples;
    f;
    r;
    u;
    h;
    pinhole;
  }

let default = make ()
let with_lens_samples c n = { c with lens_samples = n }
let with_shutter_samples c n = { c with shutter_samples = n }
let max_shutter_samples = 64
let max_shutter = 1.

let motion_blur c =
  let o, cl = c.shutter in
  cl > o

(* The middles of [shutter_samples] equal parts of the shutter. *)
let shutter_times c =
  let o, cl = c.shutter in
  if not (cl > o) then [||]
  else
    let n = c.shutter_samples in
    Array.init n (fun k -> o +. ((cl -. o) *. (Float.of_int k +. 0.5) /. Float.of_int n))

let translate (d : Vec3.t) c =
  { c with position = Vec3.add c.position d; look_at = Vec3.add c.look_at d }

let kind_name = function
  | Perspective -> "perspective"
  | Orthographic _ -> "orthographic"
  | Fisheye -> "fisheye"

let depth_of_field c = c.aperture > 0.
let[@inline] pinhole_perspective c = c.pinhole

let validate c =
  if Vec3.length2 (Vec3.sub c.look_at c.position) = 0. then
    Error "camera look_at must differ from position"
  else if Vec3.length2 c.r = 0. then
    Error "camera up must not be parallel to the view direction"
  else
    match c.kind with
    | Perspective when not (c.fov > 0. && c.fov < 180.) ->
        Error (Printf.sprintf "camera fov must be in (0, 180) degrees (got %g)" c.fov)
    | Fisheye when not (c.fov > 0. && c.fov <= 360.) ->
        Error
          (Printf.sprintf "a fisheye camera's fov must be in (0, 360] degrees (got %g)"
             c.fov)
    | Orthographic { width } when not (Float.is_finite width && width > 0.) ->
        Error
          (Printf.sprintf "an orthographic camera's width must be a number > 0 (got %g)"
             width)
    | _ ->
        if not (Float.is_finite c.aperture && c.aperture >= 0.) then
          Error
            (Printf.sprintf "camera aperture must be a number >= 0 (got %g)" c.aperture)
        else if not (Float.is_finite c.focal_distance && c.focal_distance > 0.) then
          Error
            (Printf.sprintf "camera focal_distance must be a number > 0 (got %g)"
               c.focal_distance)
        else if c.lens_samples < 1 || c.lens_samples > 64 then
          Error
            (Printf.sprintf "camera lens_samples must be in 1–64 (got %d)" c.lens_samples)
        else
          let o, cl = c.shutter in
          if not (Float.abs o <= max_shutter && Float.abs cl <= max_shutter && cl >= o)
          then
            Error
              (Printf.sprintf
                 "camera shutter must be (open, close) with −%g ≤ open ≤ close ≤ %g \
                  frames (got (%g, %g))"
                 max_shutter max_shutter o cl)
          else if c.shutter_samples < 1 || c.shutter_samples > max_shutter_samples then
            Error
              (Printf.sprintf "camera shutter_samples must be in 1–%d (got %d)"
                 max_shutter_samples c.shutter_samples)
          else Ok ()

(* The ray through image point (x, y), into the probe: origin and unit direction, as
   scalars (the vector forms' operations, component by component). Inlined where it is
   called, so that x and y stay unboxed. *)
let[@inline] ray_into c ~width ~height x y (q : Probe.t) =
  match c.kind with
  | Perspective ->
      let a = Float.of_int width /. Float.of_int height in
      let sx = ((2. *. x /. Float.of_int width) -. 1.) *. c.h *. a in
      let sy = (1. -. (2. *. y /. Float.of_int height)) *. c.h in
      let p = c.position and f = c.f and r = c.r and u = c.u in
      Probe.set_origin q p.x p.y p.z;
      Probe.set_unit_dir q
        (f.x +. ((sx *. r.x) +. (sy *. u.x)))
        (f.y +. ((sx *. r.y) +. (sy *. u.y)))
        (f.z +. ((sx *. r.z) +. (sy *. u.z)))
  | Orthographic { width = ow } ->
      let a = Float.of_int width /. Float.of_int height in
      let sx = ((2. *. x /. Float.of_int width) -. 1.) *. ow /. 2. in
      let sy = (1. -. (2. *. y /. Float.of_int height)) *. ow /. (2. *. a) in
      let p = c.position and f = c.f and r = c.r and u = c.u in
      Probe.set_origin q
        (p.x +. (sx *. r.x) +. (sy *. u.x))
        (p.y +. (sx *. r.y) +. (sy *. u.y))
        (p.z +. (sx *. r.z) +. (sy *. u.z));
      Probe.set_unit_dir q f.x f.y f.z
  | Fisheye ->
      let s = Float.of_int (Stdlib.min width height) in
      let nx = ((2. *. x) -. Float.of_int width) /. s
      and ny = (Float.of_int height -. (2. *. y)) /. s in
      let rho = Float.sqrt ((nx *. nx) +. (ny *. ny)) in
      let p = c.position and f = c.f and r = c.r and u = c.u in
      Probe.set_origin q p.x p.y p.z;
      if rho > 1. then Probe.set_unit_dir q f.x f.y f.z
      else
        let theta = rho *. (c.fov *. Float.pi /. 180.) /. 2. in
        let phi = Float.atan2 ny nx in
        let st = Float.sin theta and ct = Float.cos theta in
        let cp = Float.cos phi and sp = Float.sin phi in
        let sdx = (cp *. r.x) +. (sp *. u.x)
        and sdy = (cp *. r.y) +. (sp *. u.y)
        and sdz = (cp *. r.z) +. (sp *. u.z) in
        Probe.set_unit_dir q
          ((ct *. f.x) +. (st *. sdx))
          ((ct *. f.y) +. (st *. sdy))
          ((ct *. f.z) +. (st *. sdz))

let ray c ~width ~height x y =
  let q = Probe.create () in
  ray_into c ~width ~height x y q;
  Probe.to_ray q

(* Inlined: x and y stay unboxed. The fisheye's normalised image coordinates are those of
   [ray_into]: the inscribed circle is ρ ≤ 1. *)
let[@inline] in_view c ~width ~height x y =
  match c.kind with
  | Perspective | Orthographic _ -> true
  | Fisheye ->
      let s = Float.of_int (Stdlib.min width height) in
      let nx = ((2. *. x) -. Float.of_int width) /. s
      and ny = (Float.of_int height -. (2. *. y)) /. s in
      Float.sqrt ((nx *. nx) +. (ny *. ny)) <= 1.

(* The polar coordinates of lens point (a, b): radius and angle. *)
let[@inline] lens_radius c a u1 =
  c.aperture *. Float.sqrt ((Float.of_int a +. u1) /. Float.of_int c.lens_samples)

let[@inline] lens_angle c b u2 =
  2. *. Float.pi *. (Float.of_int b +. u2) /. Float.of_int c.lens_samples

let lens_point c a b u1 u2 =
  let rr = lens_radius c a u1 and th = lens_angle c b u2 in
  (rr *. Float.cos th, rr *. Float.sin th)

(* The lens ray from (ox, oy, oz) + lx·r + ly·u towards (ox, oy, oz) + focal_distance·d,
   into the probe, in scalars. *)
let[@inline] lens_ray_s c ox oy oz dx dy dz lx ly (q : Probe.t) =
  let fd = c.focal_distance and r = c.r and u = c.u in
  let fx = ox +. (fd *. dx) and fy = oy +. (fd *. dy) and fz = oz +. (fd *. dz) in
  let x = ox +. (lx *. r.x) +. (ly *. u.x)
  and y = oy +. (lx *. r.y) +. (ly *. u.y)
  and z = oz +. (lx *. r.z) +. (ly *. u.z) in
  Probe.set_origin q x y z;
  Probe.set_unit_dir q (fx -. x) (fy -. y) (fz -. z)

let lens_ray c pinhole lx ly =
  let o = Ray.origin pinhole and d = Ray.dir pinhole in
  let q = Probe.create () in
  lens_ray_s c o.x o.y o.z d.x d.y d.z lx ly q;
  Probe.to_ray q

let[@inline] lens_ray_into c (pin : Probe.t) a b u1 u2 (q : Probe.t) =
  let rr = lens_radius c a u1 and th = lens_angle c b u2 in
  lens_ray_s c pin.ox pin.oy pin.oz pin.dx pin.dy pin.dz
    (rr *. Float.cos th)
    (rr *. Float.sin th)
    q
