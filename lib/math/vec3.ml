type t = { x : float; y : float; z : float }

let[@inline] v x y z = { x; y; z }
let zero = { x = 0.; y = 0.; z = 0. }
let one = { x = 1.; y = 1.; z = 1. }
let x_axis = { x = 1.; y = 0.; z = 0. }
let y_axis = { x = 0.; y = 1.; z = 0. }
let z_axis = { x = 0.; y = 0.; z = 1. }
let[@inline] add a b = { x = a.x +. b.x; y = a.y +. b.y; z = a.z +. b.z }
let[@inline] sub a b = { x = a.x -. b.x; y = a.y -. b.y; z = a.z -. b.z }
let[@inline] neg a = { x = -.a.x; y = -.a.y; z = -.a.z }
let[@inline] mul a b = { x = a.x *. b.x; y = a.y *. b.y; z = a.z *. b.z }
let[@inline] smul s a = { x = s *. a.x; y = s *. a.y; z = s *. a.z }

let[@inline] madd a s b =
  { x = a.x +. (s *. b.x); y = a.y +. (s *. b.y); z = a.z +. (s *. b.z) }

let[@inline] dot a b = (a.x *. b.x) +. (a.y *. b.y) +. (a.z *. b.z)

let[@inline] cross a b =
  {
    x = (a.y *. b.z) -. (a.z *. b.y);
    y = (a.z *. b.x) -. (a.x *. b.z);
    z = (a.x *. b.y) -. (a.y *. b.x);
  }

let[@inline] length2 a = dot a a

let[@inline] max_abs a =
  Floats.max (Float.abs a.x) (Floats.max (Float.abs a.y) (Float.abs a.z))

(* Plain sqrt(dot) in the common range; rescale by the largest component only when the
   squares would overflow or underflow, so lengths stay exact to 1 ulp over the whole
   supported coordinate range. *)
let length_scaled a =
  let m = max_abs a in
  if m = 0. || m = Float.infinity then m
  else
    let s = 1. /. m in
    m *. Float.sqrt (dot (smul s a) (smul s a))

let[@inline] length a =
  let l2 = dot a a in
  if l2 > 1e-280 && l2 < 1e280 then Float.sqrt l2 else length_scaled a

let[@inline] length3 x y z =
  let l2 = (x *. x) +. (y *. y) +. (z *. z) in
  if l2 > 1e-280 && l2 < 1e280 then Float.sqrt l2 else length_scaled { x; y; z }

let[@inline] normalize a =
  let l = length a in
  if l = 0. then zero else smul (1. /. l) a

let[@inline] min a b =
  { x = Float.min a.x b.x; y = Float.min a.y b.y; z = Float.min a.z b.z }

let[@inline] max a b =
  { x = Float.max a.x b.x; y = Float.max a.y b.y; z = Float.max a.z b.z }

let equal_f ?(eps = 1e-9) a b =
  Float.abs (a.x -. b.x) <= eps
  && Float.abs (a.y -. b.y) <= eps
  && Float.abs (a.z -. b.z) <= eps
