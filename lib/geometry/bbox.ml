type t = { min : Vec3.t; max : Vec3.t }

let empty =
  { min = Vec3.v Float.infinity Float.infinity Float.infinity;
    max = Vec3.v Float.neg_infinity Float.neg_infinity Float.neg_infinity }

let union a b = { min = Vec3.min a.min b.min; max = Vec3.max a.max b.max }
let of_points ps = List.fold_left (fun b p -> union b { min = p; max = p }) empty ps
let centroid b = Vec3.smul 0.5 (Vec3.add b.min b.max)

let surface_area b =
  let d = Vec3.sub b.max b.min in
  if d.x < 0. || d.y < 0. || d.z < 0. then 0. else 2. *. ((d.x *. d.y) +. (d.y *. d.z) +. (d.z *. d.x))

let transform m b =
  if Transform.is_identity m then b
  else
    let c x y z = Transform.point m (Vec3.v x y z) in
    let l = b.min and h = b.max in
    of_points
      [ c l.x l.y l.z; c l.x l.y h.z; c l.x h.y l.z; c l.x h.y h.z;
        c h.x l.y l.z; c h.x l.y h.z; c h.x h.y l.z; c h.x h.y h.z ]

(* Slab test. A zero direction component gives ±inf in inv_dir; when the origin lies on a
   slab plane 0·inf is NaN, and Float.min/max would propagate it, so the comparisons are
   written so that NaN keeps the interval open (a false positive costs only time). *)
let hit b r tmin tmax =
  let o = Ray.origin r and inv = Ray.inv_dir r in
  let t0 = ref tmin and t1 = ref tmax in
  let slab lo hi o inv =
    let a = (lo -. o) *. inv and c = (hi -. o) *. inv in
    let near = if a < c then a else c and far = if a < c then c else a in
    if near > !t0 then t0 := near;
    if far < !t1 then t1 := far
  in
  slab b.min.x b.max.x o.x inv.x;
  slab b.min.y b.max.y o.y inv.y;
  slab b.min.z b.max.z o.z inv.z;
  !t0 <= !t1
