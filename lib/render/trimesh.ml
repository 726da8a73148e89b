(* An indexed triangle mesh: shared vertex arrays, three indices per triangle, and a
   bounding volume hierarchy over the triangles whose leaves hold triangle indices. The
   walks over it are {!Walk}'s, the scene's own. *)

type ints = (int32, Bigarray.int32_elt, Bigarray.c_layout) Bigarray.Array1.t

type t = {
  pos : Float.Array.t;
  nrm : Float.Array.t;
  tex : Float.Array.t;
  tv : ints;
  tn : ints;
  tt : ints;
  count : int;
  nodes : Float.Array.t;  (** the hierarchy's nodes ({!Bvh.t}); empty without one *)
  order : int array;  (** the triangles in leaf order; in index order without a tree *)
  depth : int;
  bounds : Bbox.t;
  computed : int;  (** how many triangles' normals were computed, not read *)
}

let fget = Float.Array.unsafe_get
let[@inline] iget (a : ints) i = Int32.to_int (Bigarray.Array1.unsafe_get a i)
let ints n = Bigarray.Array1.create Bigarray.int32 Bigarray.c_layout n
let no_ints = ints 0

(* Coordinate k of three scalars. *)
let[@inline] pick3 (x : float) y z k = if k = 0 then x else if k = 1 then y else z

(* Watertight ray–triangle test (Woop, Benthin, Wald, JCGT 2013; pbrt-v4 Triangle::Intersect).
   Translate the vertices to the ray origin, permute axes so that the largest direction
   component is z, shear so that the ray becomes +z, and evaluate the three 2-D edge
   functions. A shared edge is evaluated from the same two transformed vertices in both
   triangles, and x0·y1 − y0·x1 is exactly antisymmetric in floating point, so the two
   triangles agree on the sign: no ray passes between them. *)
let[@inline] triangle_s p0x p0y p0z p1x p1y p1z p2x p2y p2z rox roy roz rdx rdy rdz tmin
    tmax =
  let ax = Float.abs rdx and ay = Float.abs rdy and az = Float.abs rdz in
  (* kz is the axis of the largest |d| component; kx, ky follow it cyclically. *)
  let kz = if ax > ay then if ax > az then 0 else 2 else if ay > az then 1 else 2 in
  let kx = if kz = 2 then 0 else kz + 1 in
  let ky = if kx = 2 then 0 else kx + 1 in
  let dx = pick3 rdx rdy rdz kx
  and dy = pick3 rdx rdy rdz ky
  and dz = pick3 rdx rdy rdz kz in
  if dz = 0. then Float.infinity (* zero direction *)
  else
    let sx = -.dx /. dz and sy = -.dy /. dz and sz = 1. /. dz in
    let ox = pick3 rox roy roz kx
    and oy = pick3 rox roy roz ky
    and oz = pick3 rox roy roz kz in
    let z0 = pick3 p0x p0y p0z kz -. oz
    and z1 = pick3 p1x p1y p1z kz -. oz
    and z2 = pick3 p2x p2y p2z kz -. oz in
    let x0 = pick3 p0x p0y p0z kx -. ox +. (sx *. z0)
    and y0 = pick3 p0x p0y p0z ky -. oy +. (sy *. z0) in
    let x1 = pick3 p1x p1y p1z kx -. ox +. (sx *. z1)
    and y1 = pick3 p1x p1y p1z ky -. oy +. (sy *. z1) in
    let x2 = pick3 p2x p2y p2z kx -. ox +. (sx *. z2)
    and y2 = pick3 p2x p2y p2z ky -. oy +. (sy *. z2) in
    let e0 = (x1 *. y2) -. (y1 *. x2) in
    let e1 = (x2 *. y0) -. (y2 *. x0) in
    let e2 = (x0 *. y1) -. (y0 *. x1) in
    if (e0 < 0. || e1 < 0. || e2 < 0.) && (e0 > 0. || e1 > 0. || e2 > 0.) then
      Float.infinity
    else
      let det = e0 +. e1 +. e2 in
      if det = 0. || Float.is_nan det then Float.infinity
      else
        let t_scaled = (e0 *. (z0 *. sz)) +. (e1 *. (z1 *. sz)) +. (e2 *. (z2 *. sz)) in
        let t = t_scaled /. det in
        if t > tmin && t < tmax then t else Float.infinity

(* Triangle [k] against the probe's ray over (p_tmin, tmax). *)
let[@inline] root m k (q : Probe.t) tmax =
  let pos = m.pos and tv = m.tv in
  let a = 3 * iget tv (3 * k)
  and b = 3 * iget tv ((3 * k) + 1)
  and c = 3 * iget tv ((3 * k) + 2) in
  triangle_s (fget pos a)
    (fget pos (a + 1))
    (fget pos (a + 2))
    (fget pos b)
    (fget pos (b + 1))
    (fget pos (b + 2))
    (fget pos c)
    (fget pos (c + 1))
    (fget pos (c + 2))
    q.ox q.oy q.oz q.dx q.dy q.dz q.p_tmin tmax

let min_bvh = 8

(* Float.min and Float.max, bit for bit (NaN, and −0 below +0): Floats.min and max. *)
let[@inline] fmin (x : float) y = Floats.min x y
let[@inline] fmax (x : float) y = Floats.max x y

let make ?(computed = 0) ~pos ~nrm ~tex ~tv ~tn ~tt () =
  let count = Bigarray.Array1.dim tv / 3 in
  let x0 = ref Float.infinity and y0 = ref Float.infinity and z0 = ref Float.infinity in
  let x1 = ref Float.neg_infinity
  and y1 = ref Float.neg_infinity
  and z1 = ref Float.neg_infinity in
  let pbox = Float.Array.create (if count >= min_bvh then 6 * count else 0) in
  for k = 0 to count - 1 do
    let a = 3 * iget tv (3 * k)
    and b = 3 * iget tv ((3 * k) + 1)
    and c = 3 * iget tv ((3 * k) + 2) in
    (* The triangle's box as Vec3.min (Vec3.min a b) c and Vec3.max of the same. *)
    let pax = fget pos a and pay = fget pos (a + 1) and paz = fget pos (a + 2) in
    let pbx = fget pos b and pby = fget pos (b + 1) and pbz = fget pos (b + 2) in
    let pcx = fget pos c and pcy = fget pos (c + 1) and pcz = fget pos (c + 2) in
    let ax = fmin (fmin pax pbx) pcx
    and ay = fmin (fmin pay pby) pcy
    and az = fmin (fmin paz pbz) pcz in
    let bx = fmax (fmax pax pbx) pcx
    and by = fmax (fmax pay pby) pcy
    and bz = fmax (fmax paz pbz) pcz in
    x0 := fmin !x0 ax;
    y0 := fmin !y0 ay;
    z0 := fmin !z0 az;
    x1 := fmax !x1 bx;
    y1 := fmax !y1 by;
    z1 := fmax !z1 bz;
    if count >= min_bvh then Bvh.pad_into pbox k ax ay az bx by bz
  done;
  let finite =
    Float.is_finite !x0 && Float.is_finite !y0 && Float.is_finite !z0
    && Float.is_finite !x1 && Float.is_finite !y1 && Float.is_finite !z1
  in
  let nodes, order, depth =
    if count >= min_bvh && finite then
      let { Bvh.nodes; order; depth } = Bvh.build pbox in
      (nodes, order, depth)
    else (Float.Array.create 0, Array.init count Fun.id, 0)
  in
  {
    pos;
    nrm;
    tex;
    tv;
    tn;
    tt;
    count;
    nodes;
    order;
    depth;
    bounds = { Bbox.min = Vec3.v !x0 !y0 !z0; max = Vec3.v !x1 !y1 !z1 };
    computed;
  }

let count m = m.count
let computed m = m.computed
let bounds m = m.bounds
let[@inline] has_normals m k = Bigarray.Array1.dim m.tn > 0 && iget m.tn (3 * k) >= 0
let[@inline] has_uvs m k = Bigarray.Array1.dim m.tt > 0 && iget m.tt (3 * k) >= 0

let vertex m k j =
  let a = 3 * iget m.tv ((3 * k) + j) in
  Vec3.v (fget m.pos a) (fget m.pos (a + 1)) (fget m.pos (a + 2))

let normal m k j =
  let a = 3 * iget m.tn ((3 * k) + j) in
  Vec3.v (fget m.nrm a) (fget m.nrm (a + 1)) (fget m.nrm (a + 2))

let uv m k j =
  let a = 2 * iget m.tt ((3 * k) + j) in
  (fget m.tex a, fget m.tex (a + 1))

let translate (d : Vec3.t) m =
  let pos =
    Float.Array.init (Float.Array.length m.pos) (fun i ->
        let x = fget m.pos i in
        match i mod 3 with 0 -> x +. d.x | 1 -> x +. d.y | _ -> x +. d.z)
  in
  make ~computed:m.computed ~pos ~nrm:m.nrm ~tex:m.tex ~tv:m.tv ~tn:m.tn ~tt:m.tt ()

let nodes m = m.nodes
let order m = m.order
let depth m = m.depth
let first m = if Float.Array.length m.nodes = 0 then m.count else 0
