type t =
  | Sphere of { center : Vec3.t; radius : float }
  | Plane of { normal : Vec3.t; offset : float }

let sphere ~center ~radius = Sphere { center; radius }
let plane ~normal ~offset = Plane { normal = Vec3.normalize normal; offset }

let[@inline] in_range t tmin tmax = t > tmin && t < tmax

let solve_quadratic a b c tmin tmax =
  if a = 0. then
    if b = 0. then Float.infinity
    else
      let t = -.c /. b in
      if in_range t tmin tmax then t else Float.infinity
  else
    let disc = (b *. b) -. (4. *. a *. c) in
    if disc < 0. then Float.infinity
    else
      (* q = −½(b + sign(b)√Δ): no cancellation between b and √Δ. *)
      let s = Float.sqrt disc in
      let q = if b < 0. then -0.5 *. (b -. s) else -0.5 *. (b +. s) in
      let t0 = q /. a in
      let t1 = if q = 0. then t0 else c /. q in
      let lo = Float.min t0 t1 and hi = Float.max t0 t1 in
      if in_range lo tmin tmax then lo else if in_range hi tmin tmax then hi else Float.infinity

(* Sphere, after NUMERICS.md: with f = O − C and half-b' = f·d, the discriminant
   b'² − a·c equals a·(r − ℓ)(r + ℓ) where ℓ = |f − (b'/a)·d| is the distance from the centre
   to the ray's line. That form has no cancellation when the sphere is far away or tiny;
   c = (|f| − r)(|f| + r) likewise. The far root is q/a, the near one c/q. *)
let intersect_sphere (center : Vec3.t) radius r tmin tmax =
  let o = Ray.origin r and d = Ray.dir r in
  let f = Vec3.sub o center in
  let a = Vec3.dot d d in
  let b = Vec3.dot f d in
  let perp = Vec3.madd f (-.b /. a) d in
  let l = Vec3.length perp in
  let disc = a *. (radius -. l) *. (radius +. l) in
  if disc < 0. then Float.infinity
  else
    let fl = Vec3.length f in
    let c = (fl -. radius) *. (fl +. radius) in
    let s = Float.sqrt disc in
    let q = if b < 0. then s -. b else -.(b +. s) in
    if q = 0. then
      let t = -.b /. a in
      if in_range t tmin tmax then t else Float.infinity
    else
      let t0 = q /. a and t1 = c /. q in
      let lo = Float.min t0 t1 and hi = Float.max t0 t1 in
      if in_range lo tmin tmax then lo else if in_range hi tmin tmax then hi else Float.infinity

(* Plane: d·n = 0 is a miss even when the origin lies on the plane (0/0 must not escape). *)
let intersect_plane (n : Vec3.t) offset r tmin tmax =
  let denom = Vec3.dot (Ray.dir r) n in
  if denom = 0. then Float.infinity
  else
    let t = (offset -. Vec3.dot (Ray.origin r) n) /. denom in
    if in_range t tmin tmax then t else Float.infinity

let intersect s r tmin tmax =
  match s with
  | Sphere { center; radius } -> intersect_sphere center radius r tmin tmax
  | Plane { normal; offset } -> intersect_plane normal offset r tmin tmax

let normal s p =
  match s with
  | Sphere { center; _ } -> Vec3.normalize (Vec3.sub p center)
  | Plane { normal; _ } -> normal

let frac x = x -. Float.of_int (int_of_float (Float.floor x))

let uv s (p : Vec3.t) =
  match s with
  | Sphere { center; radius } ->
      let d = Vec3.smul (1. /. radius) (Vec3.sub p center) in
      let u = 0.5 +. (Float.atan2 d.x d.z /. (2. *. Float.pi)) in
      let v = 0.5 +. (Float.asin (Float.max (-1.) (Float.min 1. d.y)) /. Float.pi) in
      (frac u, v)
  | Plane { normal; _ } ->
      (* An orthonormal frame (t, b) in the plane: t is x projected onto the plane (or y
         when the plane faces x), b = t × n; x and z for a horizontal plane. *)
      let axis = if Float.abs normal.x < 0.9 then Vec3.x_axis else Vec3.y_axis in
      let t = Vec3.normalize (Vec3.madd axis (-.Vec3.dot axis normal) normal) in
      let b = Vec3.cross t normal in
      (frac (Vec3.dot p t), frac (Vec3.dot p b))

let bbox = function
  | Sphere { center; radius } ->
      let r = Vec3.v radius radius radius in
      Some { Bbox.min = Vec3.sub center r; max = Vec3.add center r }
  | Plane _ -> None

let name = function Sphere _ -> "sphere" | Plane _ -> "plane"
