(* Row-major 3×4 affine matrices: p' = M·p + t. *)
type m = {
  a00 : float;
  a01 : float;
  a02 : float;
  a03 : float;
  a10 : float;
  a11 : float;
  a12 : float;
  a13 : float;
  a20 : float;
  a21 : float;
  a22 : float;
  a23 : float;
}

type t = { m : m; inv : m; id : bool }

let m_identity =
  {
    a00 = 1.;
    a01 = 0.;
    a02 = 0.;
    a03 = 0.;
    a10 = 0.;
    a11 = 1.;
    a12 = 0.;
    a13 = 0.;
    a20 = 0.;
    a21 = 0.;
    a22 = 1.;
    a23 = 0.;
  }

let identity = { m = m_identity; inv = m_identity; id = true }

(* [mul a b] applies b first, then a. *)
let mul a b =
  {
    a00 = (a.a00 *. b.a00) +. (a.a01 *. b.a10) +. (a.a02 *. b.a20);
    a01 = (a.a00 *. b.a01) +. (a.a01 *. b.a11) +. (a.a02 *. b.a21);
    a02 = (a.a00 *. b.a02) +. (a.a01 *. b.a12) +. (a.a02 *. b.a22);
    a03 = (a.a00 *. b.a03) +. (a.a01 *. b.a13) +. (a.a02 *. b.a23) +. a.a03;
    a10 = (a.a10 *. b.a00) +. (a.a11 *. b.a10) +. (a.a12 *. b.a20);
    a11 = (a.a10 *. b.a01) +. (a.a11 *. b.a11) +. (a.a12 *. b.a21);
    a12 = (a.a10 *. b.a02) +. (a.a11 *. b.a12) +. (a.a12 *. b.a22);
    a13 = (a.a10 *. b.a03) +. (a.a11 *. b.a13) +. (a.a12 *. b.a23) +. a.a13;
    a20 = (a.a20 *. b.a00) +. (a.a21 *. b.a10) +. (a.a22 *. b.a20);
    a21 = (a.a20 *. b.a01) +. (a.a21 *. b.a11) +. (a.a22 *. b.a21);
    a22 = (a.a20 *. b.a02) +. (a.a21 *. b.a12) +. (a.a22 *. b.a22);
    a23 = (a.a20 *. b.a03) +. (a.a21 *. b.a13) +. (a.a22 *. b.a23) +. a.a23;
  }

let translate (v : Vec3.t) =
  {
    m = { m_identity with a03 = v.x; a13 = v.y; a23 = v.z };
    inv = { m_identity with a03 = -.v.x; a13 = -.v.y; a23 = -.v.z };
    id = false;
  }

let scale (v : Vec3.t) =
  {
    m = { m_identity with a00 = v.x; a11 = v.y; a22 = v.z };
    inv = { m_identity with a00 = 1. /. v.x; a11 = 1. /. v.y; a22 = 1. /. v.z };
    id = false;
  }

(* Exact values at multiples of 90° so that axis-aligned rotations introduce no error. *)
let sin_cos_deg d =
  let r = Float.rem d 360. in
  let r = if r < 0. then r +. 360. else r in
  if r = 0. then (0., 1.)
  else if r = 90. then (1., 0.)
  else if r = 180. then (0., -1.)
  else if r = 270. then (-1., 0.)
  else
    let a = r *. Float.pi /. 180. in
    (Float.sin a, Float.cos a)

(* Left-handed rotations as in POV-Ray: positive angles turn clockwise looking down the
   axis towards the origin, which is the usual right-handed matrix applied in a
   left-handed frame. *)
let rot_x d =
  let s, c = sin_cos_deg d in
  { m_identity with a11 = c; a12 = -.s; a21 = s; a22 = c }

let rot_y d =
  let s, c = sin_cos_deg d in
  { m_identity with a00 = c; a02 = s; a20 = -.s; a22 = c }

let rot_z d =
  let s, c = sin_cos_deg d in
  { m_identity with a00 = c; a01 = -.s; a10 = s; a11 = c }

(* A rotation's inverse is its transpose. *)
let transpose3 m =
  { m with a01 = m.a10; a02 = m.a20; a10 = m.a01; a12 = m.a21; a20 = m.a02; a21 = m.a12 }

let rotate (v : Vec3.t) =
  let m = mul (rot_z v.z) (mul (rot_y v.y) (rot_x v.x)) in
  { m; inv = transpose3 m; id = false }

let then_ a b =
  if a.id then b
  else if b.id then a
  else { m = mul b.m a.m; inv = mul a.inv b.inv; id = false }

let is_identity t = t.id

let linear_identity m =
  m.a00 = 1. && m.a01 = 0. && m.a02 = 0. && m.a10 = 0. && m.a11 = 1. && m.a12 = 0.
  && m.a20 = 0. && m.a21 = 0. && m.a22 = 1.

let similarity t =
  if t.id then None
  else
    let m = t.m in
    let n0 = (m.a00 *. m.a00) +. (m.a10 *. m.a10) +. (m.a20 *. m.a20)
    and n1 = (m.a01 *. m.a01) +. (m.a11 *. m.a11) +. (m.a21 *. m.a21)
    and n2 = (m.a02 *. m.a02) +. (m.a12 *. m.a12) +. (m.a22 *. m.a22)
    and d01 = (m.a00 *. m.a01) +. (m.a10 *. m.a11) +. (m.a20 *. m.a21)
    and d02 = (m.a00 *. m.a02) +. (m.a10 *. m.a12) +. (m.a20 *. m.a22)
    and d12 = (m.a01 *. m.a02) +. (m.a11 *. m.a12) +. (m.a21 *. m.a22) in
    let e = 1e-12 *. n0 in
    if
      n0 > 0. && Float.is_finite n0
      && Float.abs (n1 -. n0) <= e
      && Float.abs (n2 -. n0) <= e
      && Float.abs d01 <= e
      && Float.abs d02 <= e
      && Float.abs d12 <= e
    then Some (Float.sqrt n0)
    else None

let translation t =
  if (not t.id) && linear_identity t.m && linear_identity t.inv then
    Some
      ( { Vec3.x = t.m.a03; y = t.m.a13; z = t.m.a23 },
        { Vec3.x = t.inv.a03; y = t.inv.a13; z = t.inv.a23 } )
  else None

let apply_point m (p : Vec3.t) : Vec3.t =
  {
    x = (m.a00 *. p.x) +. (m.a01 *. p.y) +. (m.a02 *. p.z) +. m.a03;
    y = (m.a10 *. p.x) +. (m.a11 *. p.y) +. (m.a12 *. p.z) +. m.a13;
    z = (m.a20 *. p.x) +. (m.a21 *. p.y) +. (m.a22 *. p.z) +. m.a23;
  }

let apply_vector m (p : Vec3.t) : Vec3.t =
  {
    x = (m.a00 *. p.x) +. (m.a01 *. p.y) +. (m.a02 *. p.z);
    y = (m.a10 *. p.x) +. (m.a11 *. p.y) +. (m.a12 *. p.z);
    z = (m.a20 *. p.x) +. (m.a21 *. p.y) +. (m.a22 *. p.z);
  }

let point t p = if t.id then p else apply_point t.m p
let vector t p = if t.id then p else apply_vector t.m p
let inv_point t p = if t.id then p else apply_point t.inv p
let inv_vector t p = if t.id then p else apply_vector t.inv p

(* [inv_point] and [inv_vector] one coordinate at a time, the same operations, for callers
   that hold a ray as scalars. *)
let[@inline] inv_px t x y z =
  let m = t.inv in
  (m.a00 *. x) +. (m.a01 *. y) +. (m.a02 *. z) +. m.a03

let[@inline] inv_py t x y z =
  let m = t.inv in
  (m.a10 *. x) +. (m.a11 *. y) +. (m.a12 *. z) +. m.a13

let[@inline] inv_pz t x y z =
  let m = t.inv in
  (m.a20 *. x) +. (m.a21 *. y) +. (m.a22 *. z) +. m.a23

let[@inline] inv_vx t x y z =
  let m = t.inv in
  (m.a00 *. x) +. (m.a01 *. y) +. (m.a02 *. z)

let[@inline] inv_vy t x y z =
  let m = t.inv in
  (m.a10 *. x) +. (m.a11 *. y) +. (m.a12 *. z)

let[@inline] inv_vz t x y z =
  let m = t.inv in
  (m.a20 *. x) +. (m.a21 *. y) +. (m.a22 *. z)

(* Normals transform by (M⁻¹)ᵀ. *)
let normal t (n : Vec3.t) =
  if t.id then n
  else
    let i = t.inv in
    Vec3.normalize
      {
        x = (i.a00 *. n.x) +. (i.a10 *. n.y) +. (i.a20 *. n.z);
        y = (i.a01 *. n.x) +. (i.a11 *. n.y) +. (i.a21 *. n.z);
        z = (i.a02 *. n.x) +. (i.a12 *. n.y) +. (i.a22 *. n.z);
      }

(* [normal] before normalising, one coordinate at a time, the same operations. *)
let[@inline] normal_x t x y z =
  let i = t.inv in
  (i.a00 *. x) +. (i.a10 *. y) +. (i.a20 *. z)

let[@inline] normal_y t x y z =
  let i = t.inv in
  (i.a01 *. x) +. (i.a11 *. y) +. (i.a21 *. z)

let[@inline] normal_z t x y z =
  let i = t.inv in
  (i.a02 *. x) +. (i.a12 *. y) +. (i.a22 *. z)
