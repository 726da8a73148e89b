type csg_op = Union | Merge | Intersection | Difference

type t =
  | Sphere of { center : Vec3.t; radius : float }
  | Plane of { normal : Vec3.t; offset : float }
  | Parallelogram of {
      origin : Vec3.t;
      edge1 : Vec3.t;
      edge2 : Vec3.t;
      pn : Vec3.t;
      w : Vec3.t;
      pd : float;
    }
  | Triangle of {
      a : Vec3.t;
      b : Vec3.t;
      c : Vec3.t;
      tn : Vec3.t;
      normals : (Vec3.t * Vec3.t * Vec3.t) option;
      uvs : ((float * float) * (float * float) * (float * float)) option;
    }
  | Paraboloid of {
      vertex : Vec3.t;
      axis : Vec3.t;
      radius : float;
      height : float;
      k : float;
      e1 : Vec3.t;
      e2 : Vec3.t;
    }
  | Box of { min : Vec3.t; max : Vec3.t }
  | Cylinder of {
      base : Vec3.t;
      axis : Vec3.t;
      height : float;
      radius : float;
      caps : bool;
      e1 : Vec3.t;
      e2 : Vec3.t;
    }
  | Disk of { center : Vec3.t; normal : Vec3.t; radius : float; e1 : Vec3.t; e2 : Vec3.t }
  | Cone of {
      base : Vec3.t;
      axis : Vec3.t;
      height : float;
      r0 : float;
      r1 : float;
      caps : bool;
      e1 : Vec3.t;
      e2 : Vec3.t;
    }
  | Torus of {
      center : Vec3.t;
      axis : Vec3.t;
      major : float;
      minor : float;
      e1 : Vec3.t;
      e2 : Vec3.t;
    }
  | Mesh of { mesh : Trimesh.t; solid : bool }
  | Csg of {
      op : csg_op;
      members : csg_member array;
      leaf_count : int;
      cbounds : Bbox.t option;
    }

and csg_member = { shape : t; transform : Transform.t; first_leaf : int }
and csg_leaf = { leaf_shape : t; leaf_transform : Transform.t; flipped : bool }

(* An orthonormal pair (e1, e2) perpendicular to the unit vector n, with e1 × e2 = n
   up to orientation: e1 is x (or y when n is near x) made perpendicular to n. *)
let frame (n : Vec3.t) =
  let helper = if Float.abs n.x < 0.9 then Vec3.x_axis else Vec3.y_axis in
  let e1 = Vec3.normalize (Vec3.madd helper (-.Vec3.dot helper n) n) in
  let e2 = Vec3.cross n e1 in
  (e1, e2)

let sphere ~center ~radius = Sphere { center; radius }
let plane ~normal ~offset = Plane { normal = Vec3.normalize normal; offset }

let parallelogram ~origin ~edge1 ~edge2 =
  let n = Vec3.cross edge1 edge2 in
  let pn = Vec3.normalize n in
  Parallelogram
    {
      origin;
      edge1;
      edge2;
      pn;
      w = Vec3.smul (1. /. Vec3.dot n n) n;
      pd = Vec3.dot pn origin;
    }

let triangle_gen ?normals ?uvs a b c =
  let tn = Vec3.normalize (Vec3.cross (Vec3.sub b a) (Vec3.sub c a)) in
  let normals =
    Option.map
      (fun (na, nb, nc) -> (Vec3.normalize na, Vec3.normalize nb, Vec3.normalize nc))
      normals
  in
  Triangle { a; b; c; tn; normals; uvs }

let triangle ~a ~b ~c = triangle_gen a b c
let mesh_triangle ?normals ?uvs ~a ~b ~c () = triangle_gen ?normals ?uvs a b c

let paraboloid ~vertex ~axis ~radius ~height =
  let axis = Vec3.normalize axis in
  let e1, e2 = frame axis in
  Paraboloid { vertex; axis; radius; height; k = radius *. radius /. height; e1; e2 }

let box ~min ~max = Box { min = Vec3.min min max; max = Vec3.max min max }

let cylinder ~base ~top ~radius ~caps =
  let d = Vec3.sub top base in
  let height = Vec3.length d in
  let axis = Vec3.smul (1. /. height) d in
  let e1, e2 = frame axis in
  Cylinder { base; axis; height; radius; caps; e1; e2 }

let cone ~base ~top ~base_radius ~top_radius ~caps =
  let d = Vec3.sub top base in
  let height = Vec3.length d in
  let axis = Vec3.smul (1. /. height) d in
  let e1, e2 = frame axis in
  Cone { base; axis; height; r0 = base_radius; r1 = top_radius; caps; e1; e2 }

let torus ~center ~axis ~major ~minor =
  let axis = Vec3.normalize axis in
  let e1, e2 = frame axis in
  Torus { center; axis; major; minor; e1; e2 }

let disk ~center ~normal ~radius =
  let normal = Vec3.normalize normal in
  let e1, e2 = frame normal in
  Disk { center; normal; radius; e1; e2 }

let[@inline] in_range (t : float) tmin tmax = t > tmin && t < tmax

(* Sphere (doc/reference/numerics.md): with f = O − C and half-b' = f·d, the discriminant
   b'² − a·c equals a·(r − ℓ)(r + ℓ) where ℓ = |f − (b'/a)·d| is the distance from the centre
   to the ray's line. That form has no cancellation when the sphere is far away or tiny;
   c = (|f| − r)(|f| + r) likewise. The far root is q/a, the near one c/q. *)
(* The tests below are written once for two uses, which [~all] chooses where they are
   inlined (the compiler drops the branches it rules out): with [~all:false] the nearest
   root in (tmin, tmax); with [~all:true], for a CSG object that needs every root, each
   candidate root (valid in (tmin, tmax), else infinity) into a slot of [out] (from 0, in
   no order), which {!roots} sorts. The candidates are computed the same whatever tmin and
   tmax are, so they are the roots that asking again past each one finds. *)
let no_out = Float.Array.create 0

let[@inline] sphere_gen ~all cx cy cz radius ox oy oz dx dy dz tmin tmax out =
  (* The same operations as the vector form (f = O − C, perp = f − (b/a)·d, the lengths
     of perp and f), in scalars so that nothing is allocated, and with an early miss
     when |perp|² is clearly beyond r²: most rays miss most spheres, and the exact
     test would say the same. Walk.sphere_candidates (lib/render/spheres_stubs.c) takes
     this early miss for a leaf's spheres, by the same operations: change both. *)
  let fx = ox -. cx and fy = oy -. cy and fz = oz -. cz in
  let a = (dx *. dx) +. (dy *. dy) +. (dz *. dz) in
  let b = (fx *. dx) +. (fy *. dy) +. (fz *. dz) in
  let k = -.b /. a in
  let px = fx +. (k *. dx) and py = fy +. (k *. dy) and pz = fz +. (k *. dz) in
  let l2 = (px *. px) +. (py *. py) +. (pz *. pz) in
  if l2 > radius *. radius *. (1. +. 1e-9) && l2 < 1e280 then Float.infinity
  else
    let l =
      if l2 > 1e-280 && l2 < 1e280 then Float.sqrt l2 else Vec3.length (Vec3.v px py pz)
    in
    let disc = a *. (radius -. l) *. (radius +. l) in
    if disc < 0. then Float.infinity
    else
      let fl2 = (fx *. fx) +. (fy *. fy) +. (fz *. fz) in
      let fl =
        if fl2 > 1e-280 && fl2 < 1e280 then Float.sqrt fl2
        else Vec3.length (Vec3.v fx fy fz)
      in
      let c = (fl -. radius) *. (fl +. radius) in
      let s = Float.sqrt disc in
      let q = if b < 0. then s -. b else -.(b +. s) in
      if q = 0. then (
        let t = -.b /. a in
        if all then
          Float.Array.unsafe_set out 0
            (if in_range t tmin tmax then t else Float.infinity);
        if in_range t tmin tmax then t else Float.infinity)
      else
        let t0 = q /. a and t1 = c /. q in
        (* Typed comparisons (no NaN here: disc ≥ 0 and q ≠ 0); Float.min costs a C call. *)
        let lo = if t0 < t1 then t0 else t1 and hi = if t0 < t1 then t1 else t0 in
        if all then (
          Float.Array.unsafe_set out 0
            (if in_range lo tmin tmax then lo else Float.infinity);
          Float.Array.unsafe_set out 1
            (if in_range hi tmin tmax then hi else Float.infinity));
        if in_range lo tmin tmax then lo
        else if in_range hi tmin tmax then hi
        else Float.infinity

let[@inline] sphere_sc cx cy cz radius ox oy oz dx dy dz tmin tmax =
  sphere_gen ~all:false cx cy cz radius ox oy oz dx dy dz tmin tmax no_out

let[@inline] sphere_s (center : Vec3.t) radius ox oy oz dx dy dz tmin tmax =
  sphere_sc center.x center.y center.z radius ox oy oz dx dy dz tmin tmax

let[@inline] intersect_sphere center radius r tmin tmax =
  let o = Ray.origin r and d = Ray.dir r in
  sphere_s center radius o.x o.y o.z d.x d.y d.z tmin tmax

(* Plane: d·n = 0 is a miss even when the origin lies on the plane (0/0 must not escape). *)
let[@inline] plane_sc nx ny nz offset ox oy oz dx dy dz tmin tmax =
  let denom = (dx *. nx) +. (dy *. ny) +. (dz *. nz) in
  if denom = 0. then Float.infinity
  else
    let t = (offset -. ((ox *. nx) +. (oy *. ny) +. (oz *. nz))) /. denom in
    if in_range t tmin tmax then t else Float.infinity

let[@inline] plane_s (n : Vec3.t) offset ox oy oz dx dy dz tmin tmax =
  plane_sc n.x n.y n.z offset ox oy oz dx dy dz tmin tmax

let[@inline] intersect_plane n offset r tmin tmax =
  let o = Ray.origin r and d = Ray.dir r in
  plane_s n offset o.x o.y o.z d.x d.y d.z tmin tmax

(* Parallelograms tile edge to edge without cracks thanks to a tiny parametric tolerance:
   a, b ∈ [−ε, 1 + ε] with ε = 1e-9. The rounding of a and b is about 1e-16·|P|/|E|, so
   a ray aimed at a shared edge is accepted by at least one of the two tiles as long as
   the tiles are not 1e7 times smaller than their distance to the origin. The plane part
   is the plane test above (parallel rays miss). *)
let para_eps = 1e-9

let para_coords origin edge1 edge2 w p =
  let q = Vec3.sub p origin in
  let a = Vec3.dot w (Vec3.cross q edge2) and b = Vec3.dot w (Vec3.cross edge1 q) in
  (a, b)

(* The vector form (q = O + t·d − origin, a = w·(q × e2), b = w·(e1 × q)) in scalars. *)
let[@inline] parallelogram_s (origin : Vec3.t) (edge1 : Vec3.t) (edge2 : Vec3.t) pn
    (w : Vec3.t) pd ox oy oz dx dy dz tmin tmax =
  let t = plane_s pn pd ox oy oz dx dy dz tmin tmax in
  if t = Float.infinity then t
  else
    let qx = ox +. (t *. dx) -. origin.x
    and qy = oy +. (t *. dy) -. origin.y
    and qz = oz +. (t *. dz) -. origin.z in
    let cx = (qy *. edge2.z) -. (qz *. edge2.y)
    and cy = (qz *. edge2.x) -. (qx *. edge2.z)
    and cz = (qx *. edge2.y) -. (qy *. edge2.x) in
    let a = (w.x *. cx) +. (w.y *. cy) +. (w.z *. cz) in
    if a >= -.para_eps && a <= 1. +. para_eps then
      let cx = (edge1.y *. qz) -. (edge1.z *. qy)
      and cy = (edge1.z *. qx) -. (edge1.x *. qz)
      and cz = (edge1.x *. qy) -. (edge1.y *. qx) in
      let b = (w.x *. cx) +. (w.y *. cy) +. (w.z *. cz) in
      if b >= -.para_eps && b <= 1. +. para_eps then t else Float.infinity
    else Float.infinity

let[@inline] intersect_parallelogram origin edge1 edge2 pn w pd r tmin tmax =
  let o = Ray.origin r and d = Ray.dir r in
  parallelogram_s origin edge1 edge2 pn w pd o.x o.y o.z d.x d.y d.z tmin tmax

(* The watertight ray–triangle test of Trimesh, on a triangle's corners. *)
let[@inline] triangle_s (p0 : Vec3.t) (p1 : Vec3.t) (p2 : Vec3.t) rox roy roz rdx rdy rdz
    tmin tmax =
  Trimesh.triangle_s p0.x p0.y p0.z p1.x p1.y p1.z p2.x p2.y p2.z rox roy roz rdx rdy rdz
    tmin tmax

let[@inline] intersect_triangle p0 p1 p2 r tmin tmax =
  let o = Ray.origin r and d = Ray.dir r in
  triangle_s p0 p1 p2 o.x o.y o.z d.x d.y d.z tmin tmax

(* Paraboloid in its frame: y' = (P − V)·axis, x⊥ = (P − V) − y'·axis, surface
   |x⊥|² = k·y' with k = r²/h, kept for 0 ≤ y' ≤ h (open cup, seen from both sides).
   Along the ray, with f = O − V: a = |d⊥|², b = 2·f⊥·d⊥ − k·d_y, c = |f⊥|² − k·f_y. A ray
   parallel to the axis has a = 0 and one root; nearly parallel (a = 1e-18) the stable
   formula keeps the finite root (9.4999999905 in doc/reference/numerics.md) where the naive one gives 0. *)
let[@inline] height_root t fy dy height tmin tmax =
  in_range t tmin tmax
  &&
  let y = fy +. (t *. dy) in
  y >= 0. && y <= height

(* The same test on scalars, with [roots] written out: no vector, tuple or ray is made. *)
let[@inline] paraboloid_s (vertex : Vec3.t) (axis : Vec3.t) height k ox oy oz dx dy dz
    tmin tmax =
  let ex = ox -. vertex.x and ey = oy -. vertex.y and ez = oz -. vertex.z in
  let f_y = (ex *. axis.x) +. (ey *. axis.y) +. (ez *. axis.z)
  and d_y = (dx *. axis.x) +. (dy *. axis.y) +. (dz *. axis.z) in
  let fpx = ex +. (-.f_y *. axis.x)
  and fpy = ey +. (-.f_y *. axis.y)
  and fpz = ez +. (-.f_y *. axis.z) in
  let dpx = dx +. (-.d_y *. axis.x)
  and dpy = dy +. (-.d_y *. axis.y)
  and dpz = dz +. (-.d_y *. axis.z) in
  let a = (dpx *. dpx) +. (dpy *. dpy) +. (dpz *. dpz)
  and b = (2. *. ((fpx *. dpx) +. (fpy *. dpy) +. (fpz *. dpz))) -. (k *. d_y)
  and c = (fpx *. fpx) +. (fpy *. fpy) +. (fpz *. fpz) -. (k *. f_y) in
  if a = 0. then
    if b = 0. then Float.infinity
    else
      let t = -.c /. b in
      if height_root t f_y d_y height tmin tmax then t else Float.infinity
  else
    let disc = (b *. b) -. (4. *. a *. c) in
    if disc < 0. || Float.is_nan disc then Float.infinity
    else
      let s = Float.sqrt disc in
      let q = if b < 0. then -0.5 *. (b -. s) else -0.5 *. (b +. s) in
      if q = 0. then
        if height_root 0. f_y d_y height tmin tmax then 0. else Float.infinity
      else
        let u = q /. a and v = c /. q in
        let t0 = Floats.min u v and t1 = Floats.max u v in
        if height_root t0 f_y d_y height tmin tmax then t0
        else if height_root t1 f_y d_y height tmin tmax then t1
        else Float.infinity

let intersect_paraboloid vertex axis height k r tmin tmax =
  let o = Ray.origin r and d = Ray.dir r in
  paraboloid_s vertex axis height k o.x o.y o.z d.x d.y d.z tmin tmax

(* Slab test for an axis-aligned box: the entry t if it lies in (tmin, tmax), else the
   exit t (origin inside). Zero direction components give ±inf bounds; 0·inf (origin on
   a face plane) gives NaN, which the comparisons ignore. *)
let[@inline] box_gen ~all (mn : Vec3.t) (mx : Vec3.t) ox oy oz ix iy iz tmin tmax out =
  let a = (mn.x -. ox) *. ix and c = (mx.x -. ox) *. ix in
  let near = if a < c then a else c and far = if a < c then c else a in
  let t0 = if near > Float.neg_infinity then near else Float.neg_infinity in
  let t1 = if far < Float.infinity then far else Float.infinity in
  let a = (mn.y -. oy) *. iy and c = (mx.y -. oy) *. iy in
  let near = if a < c then a else c and far = if a < c then c else a in
  let t0 = if near > t0 then near else t0 and t1 = if far < t1 then far else t1 in
  let a = (mn.z -. oz) *. iz and c = (mx.z -. oz) *. iz in
  let near = if a < c then a else c and far = if a < c then c else a in
  let t0 = if near > t0 then near else t0 and t1 = if far < t1 then far else t1 in
  if not (t0 <= t1) then Float.infinity
  else (
    if all then (
      Float.Array.unsafe_set out 0 (if in_range t0 tmin tmax then t0 else Float.infinity);
      Float.Array.unsafe_set out 1 (if in_range t1 tmin tmax then t1 else Float.infinity));
    if in_range t0 tmin tmax then t0
    else if in_range t1 tmin tmax then t1
    else Float.infinity)

let[@inline] box_s mn mx ox oy oz ix iy iz tmin tmax =
  box_gen ~all:false mn mx ox oy oz ix iy iz tmin tmax no_out

let intersect_box mn mx r tmin tmax =
  let o = Ray.origin r and inv = Ray.inv_dir r in
  box_s mn mx o.x o.y o.z inv.x inv.y inv.z tmin tmax

(* A disk of radius r at [center] in the plane of [normal], t from the plane test. *)
let[@inline] disk_sc cx cy cz (normal : Vec3.t) radius ox oy oz dx dy dz tmin tmax =
  let denom = (dx *. normal.x) +. (dy *. normal.y) +. (dz *. normal.z) in
  if denom = 0. then Float.infinity
  else
    let t =
      (((cx -. ox) *. normal.x) +. ((cy -. oy) *. normal.y) +. ((cz -. oz) *. normal.z))
      /. denom
    in
    if in_range t tmin tmax then
      let qx = ox +. (t *. dx) -. cx
      and qy = oy +. (t *. dy) -. cy
      and qz = oz +. (t *. dz) -. cz in
      if (qx *. qx) +. (qy *. qy) +. (qz *. qz) <= radius *. radius then t
      else Float.infinity
    else Float.infinity

let[@inline] disk_s (center : Vec3.t) normal radius ox oy oz dx dy dz tmin tmax =
  disk_sc center.x center.y center.z normal radius ox oy oz dx dy dz tmin tmax

let disk_hit center normal radius r tmin tmax =
  let o = Ray.origin r and d = Ray.dir r in
  disk_s center normal radius o.x o.y o.z d.x d.y d.z tmin tmax

(* Of an axial side's roots [t0] ≤ [t1], the nearer that lies between the ends (0 ≤ y' ≤
   [height], y' = [f_y] + t·[d_y]) in (tmin, tmax), or infinity; with [all], each of the
   two kept (or infinity) into [out] at 0 and 1. *)
let[@inline] side_roots ~all t0 t1 f_y d_y height tmin tmax out =
  if all then (
    Float.Array.unsafe_set out 0
      (if height_root t0 f_y d_y height tmin tmax then t0 else Float.infinity);
    Float.Array.unsafe_set out 1
      (if height_root t1 f_y d_y height tmin tmax then t1 else Float.infinity));
  if height_root t0 f_y d_y height tmin tmax then t0
  else if height_root t1 f_y d_y height tmin tmax then t1
  else Float.infinity

(* An axial solid's nearest root in (tmin, tmax): its side's ([side]) or a cap's, the disk
   of radius [r0] at [base] where [lo], of [r1] at the top where [hi]; each cap searched
   only below the nearest root so far. With [all], the caps' roots (or infinity) into
   [out] at 2 and 3, and the side's root. *)
let[@inline] with_caps ~all (base : Vec3.t) (axis : Vec3.t) height r0 r1 ~lo ~hi side ox
    oy oz dx dy dz tmin tmax out =
  let tx = base.x +. (height *. axis.x)
  and ty = base.y +. (height *. axis.y)
  and tz = base.z +. (height *. axis.z) in
  if all then (
    Float.Array.unsafe_set out 2
      (if lo then disk_s base axis r0 ox oy oz dx dy dz tmin tmax else Float.infinity);
    Float.Array.unsafe_set out 3
      (if hi then disk_sc tx ty tz axis r1 ox oy oz dx dy dz tmin tmax else Float.infinity);
    side)
  else if not (lo || hi) then side
  else
    let tmax' = Floats.min side tmax in
    let t_lo =
      if lo then disk_s base axis r0 ox oy oz dx dy dz tmin tmax' else Float.infinity
    in
    let tmax' = Floats.min t_lo tmax' in
    let t_hi =
      if hi then disk_sc tx ty tz axis r1 ox oy oz dx dy dz tmin tmax' else Float.infinity
    in
    Floats.min side (Floats.min t_lo t_hi)

(* Cylinder side: the 2-D circle version of the sphere's stable discriminant, in the plane
   perpendicular to the axis (f⊥ and d⊥); kept for 0 ≤ y' ≤ h. Caps are disks. A ray
   parallel to the axis has a = 0 and misses the side (the caps catch it). The vector
   form's operations (f = O − base, f⊥ = f − f_y·axis, …), on scalars. *)
let[@inline] cylinder_gen ~all (base : Vec3.t) (axis : Vec3.t) height radius caps ox oy oz
    dx dy dz tmin tmax out =
  let ex = ox -. base.x and ey = oy -. base.y and ez = oz -. base.z in
  let f_y = (ex *. axis.x) +. (ey *. axis.y) +. (ez *. axis.z)
  and d_y = (dx *. axis.x) +. (dy *. axis.y) +. (dz *. axis.z) in
  let fpx = ex +. (-.f_y *. axis.x)
  and fpy = ey +. (-.f_y *. axis.y)
  and fpz = ez +. (-.f_y *. axis.z) in
  let dpx = dx +. (-.d_y *. axis.x)
  and dpy = dy +. (-.d_y *. axis.y)
  and dpz = dz +. (-.d_y *. axis.z) in
  let a = (dpx *. dpx) +. (dpy *. dpy) +. (dpz *. dpz) in
  let side =
    if a = 0. then Float.infinity
    else
      let b = (fpx *. dpx) +. (fpy *. dpy) +. (fpz *. dpz) in
      let m = -.b /. a in
      let l = Vec3.length3 (fpx +. (m *. dpx)) (fpy +. (m *. dpy)) (fpz +. (m *. dpz)) in
      let disc = a *. (radius -. l) *. (radius +. l) in
      if disc < 0. || Float.is_nan disc then Float.infinity
      else
        let fl = Vec3.length3 fpx fpy fpz in
        let c = (fl -. radius) *. (fl +. radius) in
        let s = Float.sqrt disc in
        let q = if b < 0. then s -. b else -.(b +. s) in
        let t0 = if q = 0. then -.b /. a else Floats.min (q /. a) (c /. q)
        and t1 = if q = 0. then Float.infinity else Floats.max (q /. a) (c /. q) in
        side_roots ~all t0 t1 f_y d_y height tmin tmax out
  in
  with_caps ~all base axis height radius radius ~lo:caps ~hi:caps side ox oy oz dx dy dz
    tmin tmax out

let cylinder_s base axis height radius caps ox oy oz dx dy dz tmin tmax =
  cylinder_gen ~all:false base axis height radius caps ox oy oz dx dy dz tmin tmax no_out

let intersect_cylinder base axis height radius caps r tmin tmax =
  let o = Ray.origin r and d = Ray.dir r in
  cylinder_s base axis height radius caps o.x o.y o.z d.x d.y d.z tmin tmax

(* Cone side: |x⊥| = r(y') with r linear from r0 at y' = 0 to r1 at y' = h, kept for
   0 ≤ y' ≤ h (where r ≥ 0, so the other nappe of the double cone is cut away). With
   k = (r1 − r0)/h and ρ(t) = r0 + k·(f_y + t·d_y): a = |d⊥|² − k²·d_y²,
   b = 2·(f⊥·d⊥ − k·d_y·ρ₀), c = |f⊥|² − ρ₀², solved by the stable formula ([roots],
   written out). Caps are disks (none at a point end). On scalars, as the cylinder. *)
let[@inline] cone_gen ~all (base : Vec3.t) (axis : Vec3.t) height r0 r1 caps ox oy oz dx
    dy dz tmin tmax out =
  let ex = ox -. base.x and ey = oy -. base.y and ez = oz -. base.z in
  let f_y = (ex *. axis.x) +. (ey *. axis.y) +. (ez *. axis.z)
  and d_y = (dx *. axis.x) +. (dy *. axis.y) +. (dz *. axis.z) in
  let fpx = ex +. (-.f_y *. axis.x)
  and fpy = ey +. (-.f_y *. axis.y)
  and fpz = ez +. (-.f_y *. axis.z) in
  let dpx = dx +. (-.d_y *. axis.x)
  and dpy = dy +. (-.d_y *. axis.y)
  and dpz = dz +. (-.d_y *. axis.z) in
  let k = (r1 -. r0) /. height in
  let rho0 = r0 +. (k *. f_y) in
  let a = (dpx *. dpx) +. (dpy *. dpy) +. (dpz *. dpz) -. (k *. k *. d_y *. d_y) in
  let b = 2. *. ((fpx *. dpx) +. (fpy *. dpy) +. (fpz *. dpz) -. (k *. d_y *. rho0)) in
  let c = (fpx *. fpx) +. (fpy *. fpy) +. (fpz *. fpz) -. (rho0 *. rho0) in
  let side =
    if a = 0. then (
      if b = 0. then Float.infinity
      else
        (* One root (the linear case). *)
        let t = -.c /. b in
        let t = if height_root t f_y d_y height tmin tmax then t else Float.infinity in
        if all then Float.Array.unsafe_set out 0 t;
        t)
    else
      let disc = (b *. b) -. (4. *. a *. c) in
      if disc < 0. || Float.is_nan disc then Float.infinity
      else
        let s = Float.sqrt disc in
        let q = if b < 0. then -0.5 *. (b -. s) else -0.5 *. (b +. s) in
        if q = 0. then (
          (* A double root. *)
          let t =
            if height_root 0. f_y d_y height tmin tmax then 0. else Float.infinity
          in
          if all then Float.Array.unsafe_set out 0 t;
          t)
        else
          let t0 = Floats.min (q /. a) (c /. q) and t1 = Floats.max (q /. a) (c /. q) in
          side_roots ~all t0 t1 f_y d_y height tmin tmax out
  in
  with_caps ~all base axis height r0 r1
    ~lo:(caps && r0 > 0.)
    ~hi:(caps && r1 > 0.)
    side ox oy oz dx dy dz tmin tmax out

let cone_s base axis height r0 r1 caps ox oy oz dx dy dz tmin tmax =
  cone_gen ~all:false base axis height r0 r1 caps ox oy oz dx dy dz tmin tmax no_out

let intersect_cone base axis height r0 r1 caps r tmin tmax =
  let o = Ray.origin r and d = Ray.dir r in
  cone_s base axis height r0 r1 caps o.x o.y o.z d.x d.y d.z tmin tmax

(* Torus: with q = P − C, y = q·axis, the surface is (|q|² + R² − r²)² = 4R²(|q|² − y²),
   a quartic along the ray. To keep it well scaled whatever the distance, the ray is
   first restarted at p₀, its point nearest the centre, with a unit direction u, so that
   p(s) = p₀ + s·u with p₀ ⊥ u: every root then lies in |s| ≤ L = √((R + r)² − |p₀|²),
   and the ray misses when |p₀| > R + r. The roots are isolated from the derivatives,
   which are simple in s: g'' = 12s² + 4(|p₀|² + R² − r²) − 8R²(1 − (u·axis)²) has at
   most two roots; they split [−L, L] into pieces where g' is monotonic, whose sign
   changes give g's critical points; between consecutive critical points g is monotonic,
   and each sign change holds one root, found by Newton steps on the original equation
   kept inside the bracket (bisection when a step leaves it). A critical point where g
   is zero within its rounding error is a tangent (double) root: a ray grazing the tube
   is not lost. *)
let torus_roots (center : Vec3.t) (axis : Vec3.t) major minor r tmin tmax =
  let o = Ray.origin r and d = Ray.dir r in
  let dl = Vec3.length d in
  let u = Vec3.smul (1. /. dl) d in
  let f = Vec3.sub o center in
  let sc = -.Vec3.dot f u in
  (* p₀ = f + sc·u, computed as the part of f perpendicular to u (no cancellation). *)
  let p0 = Vec3.madd f sc u in
  let p0 = Vec3.madd p0 (-.Vec3.dot p0 u) u in
  let big = major +. minor in
  let p02 = Vec3.dot p0 p0 in
  let out = ref [] in
  (* A ray touching the outer equator has |p₀| = R + r up to rounding: let it in, with an
     interval that is never empty. *)
  if p02 <= big *. big *. (1. +. 1e-12) then (
    let l =
      (Float.sqrt (Float.max 0. ((big *. big) -. p02)) *. (1. +. 1e-9)) +. (1e-6 *. big)
    in
    let ua = Vec3.dot u axis and pa = Vec3.dot p0 axis in
    let kk = (major *. major) -. (minor *. minor) and r4 = 4. *. major *. major in
    (* g and its first derivative in the original form, at s. *)
    let g s =
      let ss = p02 +. (s *. s) and y = pa +. (s *. ua) in
      let w = ss +. kk in
      (w *. w) -. (r4 *. (ss -. (y *. y)))
    in
    let g1 s =
      let ss = p02 +. (s *. s) and y = pa +. (s *. ua) in
      (4. *. (ss +. kk) *. s) -. (2. *. r4 *. (s -. (y *. ua)))
    in
    let g2 s =
      (12. *. s *. s) +. (4. *. (p02 +. kk)) -. (2. *. r4 *. (1. -. (ua *. ua)))
    in
    (* The rounding error of g at s: a few ulps of its largest term. *)
    let err s =
      let ss = p02 +. (s *. s) in
      let w = Float.abs (ss +. kk) in
      16. *. epsilon_float *. ((w *. w) +. (r4 *. ss) +. (w *. (ss +. Float.abs kk)))
    in
    (* The root of h in [a, b] where h(a), h(b) differ in sign: Newton steps with h',
       bisection when a step leaves the bracket or does not shrink it fast enough. *)
    let solve h h' a b =
      let a = ref a and b = ref b in
      let ha = ref (h !a) in
      let x = ref (0.5 *. (!a +. !b)) in
      let k = ref 0 in
      while
        !k < 200
        && !b -. !a > 2. *. epsilon_float *. Float.max (Float.abs !a) (Float.abs !b)
      do
        incr k;
        let hx = h !x in
        if hx = 0. then (
          a := !x;
          b := !x)
        else (
          if hx < 0. = (!ha < 0.) then (
            a := !x;
            ha := hx)
          else b := !x;
          let dx = h' !x in
          let nx = if dx <> 0. then !x -. (hx /. dx) else Float.nan in
          x := if nx > !a && nx < !b && !k mod 8 <> 0 then nx else 0.5 *. (!a +. !b))
      done;
      if !b -. !a > 2. *. epsilon_float *. Float.max (Float.abs !a) (Float.abs !b) then !x
      else 0.5 *. (!a +. !b)
    in
    (* Critical points of g: roots of g' on each piece where g' is monotonic. *)
    let q = ((2. *. r4 *. (1. -. (ua *. ua))) -. (4. *. (p02 +. kk))) /. 12. in
    let splits =
      if q > 0. then
        let z = Float.sqrt q in
        List.filter (fun s -> s > -.l && s < l) [ -.z; z ]
      else []
    in
    let pts = (-.l :: splits) @ [ l ] in
    let rec crits acc = function
      | a :: (b :: _ as rest) ->
          let fa = g1 a and fb = g1 b in
          let acc =
            if (fa < 0. && fb > 0.) || (fa > 0. && fb < 0.) then solve g1 g2 a b :: acc
            else acc
          in
          crits acc rest
      | _ -> List.rev acc
    in
    let cs = crits [] pts in
    let pts = (-.l :: cs) @ [ l ] in
    let add s = out := ((sc +. s) /. dl) :: !out in
    let rec roots_between = function
      | a :: (b :: _ as rest) ->
          let fa = g a and fb = g b in
          if (fa < 0. && fb > 0.) || (fa > 0. && fb < 0.) then add (solve g g1 a b);
          roots_between rest
      | _ -> ()
    in
    roots_between pts;
    (* Tangent roots: a critical point where g is zero within rounding and no sign change
       beside it. *)
    let rec tangents prev = function
      | c :: rest ->
          let gc = g c in
          let next = match rest with n :: _ -> n | [] -> l in
          if Float.abs gc <= err c && g prev < 0. = (gc < 0.) && g next < 0. = (gc < 0.)
          then add c;
          tangents c rest
      | [] -> ()
    in
    tangents (-.l) cs);
  let best = ref Float.infinity in
  List.iter (fun t -> if in_range t tmin tmax && t < !best then best := t) !out;
  !best

(* Bounds of a disk of radius r around c in the plane of unit normal n: along axis i the
   disk extends r·√(1 − n_i²). *)
let disk_bbox (c : Vec3.t) (n : Vec3.t) r =
  let e x = r *. Float.sqrt (Float.max 0. (1. -. (x *. x))) in
  let h = Vec3.v (e n.x) (e n.y) (e n.z) in
  { Bbox.min = Vec3.sub c h; max = Vec3.add c h }

let bbox_of = function
  | Sphere { center; radius } ->
      let r = Vec3.v radius radius radius in
      Some { Bbox.min = Vec3.sub center r; max = Vec3.add center r }
  | Plane _ -> None
  | Parallelogram { origin; edge1; edge2; _ } ->
      Some
        (Bbox.of_points
           [
             origin;
             Vec3.add origin edge1;
             Vec3.add origin edge2;
             Vec3.add (Vec3.add origin edge1) edge2;
           ])
  | Triangle { a; b; c; _ } ->
      (* Bbox.of_points [a; b; c], without its list and intermediate boxes (the same
         bits: min and max from the empty box keep the first point). *)
      Some { Bbox.min = Vec3.min (Vec3.min a b) c; max = Vec3.max (Vec3.max a b) c }
  | Paraboloid { vertex; axis; radius; height; _ } ->
      let top = disk_bbox (Vec3.madd vertex height axis) axis radius in
      Some (Bbox.union top { Bbox.min = vertex; max = vertex })
  | Box { min; max } -> Some { Bbox.min; max }
  | Cylinder { base; axis; height; radius; _ } ->
      Some
        (Bbox.union (disk_bbox base axis radius)
           (disk_bbox (Vec3.madd base height axis) axis radius))
  | Disk { center; normal; radius; _ } -> Some (disk_bbox center normal radius)
  | Cone { base; axis; height; r0; r1; _ } ->
      Some
        (Bbox.union (disk_bbox base axis r0)
           (disk_bbox (Vec3.madd base height axis) axis r1))
  | Torus { center; axis; major; minor; _ } ->
      (* The ring of radius R in the plane of the axis, grown by r in every direction. *)
      let e x = (major *. Float.sqrt (Float.max 0. (1. -. (x *. x)))) +. minor in
      let h = Vec3.v (e axis.x) (e axis.y) (e axis.z) in
      Some { Bbox.min = Vec3.sub center h; max = Vec3.add center h }
  | Mesh { mesh; _ } -> Some (Trimesh.bounds mesh)
  | Csg { cbounds; _ } -> cbounds

(* --- Solids ------------------------------------------------------------------------- *)

(* Whether (x, y, z) is inside the capped solid of radius [r0] at [base] going linearly
   to [r1] at [height] along [axis]: a cone, or a cylinder ([r0] = [r1], for which the
   radius computed is [r0] itself, exactly). *)
let[@inline] axial_inside (base : Vec3.t) (axis : Vec3.t) height r0 r1 x y z =
  let qx = x -. base.x and qy = y -. base.y and qz = z -. base.z in
  let h = (qx *. axis.x) +. (qy *. axis.y) +. (qz *. axis.z) in
  h >= 0. && h <= height
  &&
  let px = qx +. (-.h *. axis.x)
  and py = qy +. (-.h *. axis.y)
  and pz = qz +. (-.h *. axis.z) in
  let rr = r0 +. ((r1 -. r0) *. h /. height) in
  (px *. px) +. (py *. py) +. (pz *. pz) <= rr *. rr

(* Whether the point (x, y, z) is inside a solid; a point on the boundary counts as
   inside. A plane is the half-space n̂·P ≤ offset. The vector operations of each test,
   on scalars. *)
(* Written once, inlined into the two entry points below: a point given as three floats
   to a function that is not inlined is boxed, a point in a probe is not. *)
let[@inline] inside_xyz s x y z =
  match s with
  | Sphere { center; radius } ->
      let qx = x -. center.x and qy = y -. center.y and qz = z -. center.z in
      (qx *. qx) +. (qy *. qy) +. (qz *. qz) <= radius *. radius
  | Plane { normal; offset } ->
      (normal.x *. x) +. (normal.y *. y) +. (normal.z *. z) <= offset
  | Box { min; max } ->
      x >= min.x && x <= max.x && y >= min.y && y <= max.y && z >= min.z && z <= max.z
  | Cylinder { base; axis; height; radius; caps = true; _ } ->
      axial_inside base axis height radius radius x y z
  | Cone { base; axis; height; r0; r1; caps = true; _ } ->
      axial_inside base axis height r0 r1 x y z
  | Torus { center; axis; major; minor; _ } ->
      let qx = x -. center.x and qy = y -. center.y and qz = z -. center.z in
      let h = (qx *. axis.x) +. (qy *. axis.y) +. (qz *. axis.z) in
      let rho =
        Float.sqrt (Float.max 0. ((qx *. qx) +. (qy *. qy) +. (qz *. qz) -. (h *. h)))
      in
      let dr = rho -. major in
      (dr *. dr) +. (h *. h) <= minor *. minor
  | Mesh { solid = true; _ } | Csg _ ->
      invalid_arg
        "Shape.inside: a solid mesh's or a CSG object's inside follows from its \
         crossings (Walk.inside)"
  | Cylinder { caps = false; _ }
  | Cone { caps = false; _ }
  | Mesh { solid = false; _ }
  | Parallelogram _ | Triangle _ | Paraboloid _ | Disk _ ->
      false

let inside_at s x y z = inside_xyz s x y z
let inside_probe s (p : Probe.t) = inside_xyz s p.ox p.oy p.oz
let inside s (p : Vec3.t) = inside_at s p.x p.y p.z

(* --- Roots ---------------------------------------------------------------------------- *)

let composite what =
  invalid_arg
    (Printf.sprintf
       "Shape.%s: a mesh's or a CSG object's roots come from the walk of its hierarchy \
        or its members (Walk)"
       what)

(* The quadrics with a height range and the torus take the ray in vector form. *)
let intersect s r tmin tmax =
  match s with
  | Sphere { center; radius } -> intersect_sphere center radius r tmin tmax
  | Plane { normal; offset } -> intersect_plane normal offset r tmin tmax
  | Triangle { a; b; c; _ } -> intersect_triangle a b c r tmin tmax
  | Parallelogram { origin; edge1; edge2; pn; w; pd } ->
      intersect_parallelogram origin edge1 edge2 pn w pd r tmin tmax
  | Box { min; max } -> intersect_box min max r tmin tmax
  | Paraboloid { vertex; axis; height; k; _ } ->
      intersect_paraboloid vertex axis height k r tmin tmax
  | Cylinder { base; axis; height; radius; caps; _ } ->
      intersect_cylinder base axis height radius caps r tmin tmax
  | Disk { center; normal; radius; _ } -> disk_hit center normal radius r tmin tmax
  | Cone { base; axis; height; r0; r1; caps; _ } ->
      intersect_cone base axis height r0 r1 caps r tmin tmax
  | Torus { center; axis; major; minor; _ } ->
      torus_roots center axis major minor r tmin tmax
  | Mesh _ | Csg _ -> composite "intersect"

(* The same roots on the probe's scalars; the torus builds the ray its vector form
   needs. *)
let root s (q : Probe.t) =
  let tmin = q.p_tmin and tmax = q.p_tmax in
  match s with
  | Sphere { center; radius } ->
      q.p_t <- sphere_s center radius q.ox q.oy q.oz q.dx q.dy q.dz tmin tmax
  | Plane { normal; offset } ->
      q.p_t <- plane_s normal offset q.ox q.oy q.oz q.dx q.dy q.dz tmin tmax
  | Triangle { a; b; c; _ } ->
      q.p_t <- triangle_s a b c q.ox q.oy q.oz q.dx q.dy q.dz tmin tmax
  | Parallelogram { origin; edge1; edge2; pn; w; pd } ->
      q.p_t <-
        parallelogram_s origin edge1 edge2 pn w pd q.ox q.oy q.oz q.dx q.dy q.dz tmin tmax
  | Box { min; max } -> q.p_t <- box_s min max q.ox q.oy q.oz q.ix q.iy q.iz tmin tmax
  | Disk { center; normal; radius; _ } ->
      q.p_t <- disk_s center normal radius q.ox q.oy q.oz q.dx q.dy q.dz tmin tmax
  | Paraboloid { vertex; axis; height; k; _ } ->
      q.p_t <- paraboloid_s vertex axis height k q.ox q.oy q.oz q.dx q.dy q.dz tmin tmax
  | Cylinder { base; axis; height; radius; caps; _ } ->
      q.p_t <-
        cylinder_s base axis height radius caps q.ox q.oy q.oz q.dx q.dy q.dz tmin tmax
  | Cone { base; axis; height; r0; r1; caps; _ } ->
      q.p_t <- cone_s base axis height r0 r1 caps q.ox q.oy q.oz q.dx q.dy q.dz tmin tmax
  | Torus _ ->
      q.p_t <-
        intersect s
          (Ray.make_raw (Vec3.v q.ox q.oy q.oz) (Vec3.v q.dx q.dy q.dz))
          tmin tmax
  | Mesh _ | Csg _ -> composite "root"

(* The candidates in [out]'s first [n] slots, sorted, each value once, the infinite ones
   dropped: how many are left. The finite ones are gathered first, in order, and only they
   are sorted (stably, as all of them would be): a shape's test leaves most slots
   infinite. *)
let sorted_distinct out n =
  let m = ref 0 in
  for i = 0 to n - 1 do
    let x = Float.Array.unsafe_get out i in
    if x < Float.infinity then (
      Float.Array.unsafe_set out !m x;
      incr m)
  done;
  let m = !m in
  for i = 1 to m - 1 do
    let x = Float.Array.unsafe_get out i in
    let j = ref i in
    while !j > 0 && Float.Array.unsafe_get out (!j - 1) > x do
      Float.Array.unsafe_set out !j (Float.Array.unsafe_get out (!j - 1));
      decr j
    done;
    Float.Array.unsafe_set out !j x
  done;
  let k = ref 0 in
  for i = 0 to m - 1 do
    let x = Float.Array.unsafe_get out i in
    if !k = 0 || x <> Float.Array.unsafe_get out (!k - 1) then (
      Float.Array.unsafe_set out !k x;
      incr k)
  done;
  !k

(* [n] slots of [out] emptied: [n]. *)
let[@inline] put out n =
  for i = 0 to n - 1 do
    Float.Array.unsafe_set out i Float.infinity
  done;
  n

let roots s (q : Probe.t) out =
  let tmin = q.p_tmin and inf = Float.infinity in
  match s with
  | Sphere { center; radius } when Float.Array.length out >= 2 ->
      let n = put out 2 in
      ignore
        (sphere_gen ~all:true center.x center.y center.z radius q.ox q.oy q.oz q.dx q.dy
           q.dz tmin inf out);
      sorted_distinct out n
  | Box { min; max } when Float.Array.length out >= 2 ->
      let n = put out 2 in
      ignore (box_gen ~all:true min max q.ox q.oy q.oz q.ix q.iy q.iz tmin inf out);
      sorted_distinct out n
  | Cylinder { base; axis; height; radius; caps; _ } when Float.Array.length out >= 4 ->
      let n = put out 4 in
      ignore
        (cylinder_gen ~all:true base axis height radius caps q.ox q.oy q.oz q.dx q.dy q.dz
           tmin inf out);
      sorted_distinct out n
  | Cone { base; axis; height; r0; r1; caps; _ } when Float.Array.length out >= 4 ->
      let n = put out 4 in
      ignore
        (cone_gen ~all:true base axis height r0 r1 caps q.ox q.oy q.oz q.dx q.dy q.dz tmin
           inf out);
      sorted_distinct out n
  | Mesh _ | Csg _ -> composite "roots"
  | s ->
      (* Asked again past each root. *)
      let n = ref 0 and go = ref true in
      q.p_tmax <- inf;
      while !go && !n < Float.Array.length out do
        root s q;
        if q.p_t < inf then (
          Float.Array.unsafe_set out !n q.p_t;
          incr n;
          q.p_tmin <- q.p_t)
        else go := false
      done;
      q.p_tmin <- tmin;
      !n

(* --- CSG trees ------------------------------------------------------------------------ *)

(* The simple surfaces of a shape as a CSG member: a CSG object's leaves, or the shape
   itself (a mesh is one leaf, its triangles the faces of that leaf). *)
let leaf_count = function Csg { leaf_count; _ } -> leaf_count | _ -> 1

(* A CSG object counts its leaves but does not list them: each level of a difference
   nested n deep would hold a copy of the ones below, n²/2 records in all. *)
let csg op (ms : (t * Transform.t) list) =
  let n = ref 0 in
  let members =
    List.map
      (fun (shape, transform) ->
        let first_leaf = !n in
        n := !n + leaf_count shape;
        { shape; transform; first_leaf })
      ms
    |> Array.of_list
  in
  if Array.length members = 0 then invalid_arg "Shape.csg: no member";
  let boxes =
    Array.map
      (fun (m : csg_member) -> Option.map (Bbox.transform m.transform) (bbox_of m.shape))
      members
  in
  let known = List.filter_map Fun.id (Array.to_list boxes) in
  let cbounds =
    match op with
    | Union | Merge ->
        if Array.exists Option.is_none boxes then None
        else Some (List.fold_left Bbox.union Bbox.empty known)
    | Difference -> boxes.(0)
    | Intersection -> (
        match known with
        | [] -> None
        | b :: rest ->
            Some
              (List.fold_left
                 (fun (a : Bbox.t) (b : Bbox.t) ->
                   { Bbox.min = Vec3.max a.min b.min; max = Vec3.min a.max b.max })
                 b rest))
  in
  Csg { op; members; leaf_count = !n; cbounds }

(* Each leaf's transform is its member's composed with those of the members above it,
   innermost first, as one level at a time would compose them; it is flipped where an
   odd number of them subtract it. [path] holds those above, innermost first. *)
let csg_leaves s =
  let acc = ref [] in
  let rec up tr flipped = function
    | [] -> (tr, flipped)
    | (t, subtracted) :: rest -> up (Transform.then_ tr t) (flipped <> subtracted) rest
  in
  let add leaf_shape transform subtracted path =
    let leaf_transform, flipped = up transform subtracted path in
    acc := { leaf_shape; leaf_transform; flipped } :: !acc
  in
  let rec walk s path =
    match s with
    | Csg { op; members; _ } ->
        Array.iteri
          (fun i (m : csg_member) ->
            let subtracted = op = Difference && i > 0 in
            match m.shape with
            | Csg _ when Transform.is_identity m.transform && not subtracted ->
                (* A step that changes nothing (then_ keeps its left side as it is): a
                   difference nested n deep walks n levels, not n²/2. *)
                walk m.shape path
            | Csg _ -> walk m.shape ((m.transform, subtracted) :: path)
            | shape -> add shape m.transform subtracted path)
          members
    | _ -> ()
  in
  walk s [];
  Array.of_list (List.rev !acc)

(* Barycentric coordinates (u, v, w) of p (projected onto the triangle's plane), with
   p = u·a + v·b + w·c. *)
let barycentric (a : Vec3.t) b c p =
  let v0 = Vec3.sub b a and v1 = Vec3.sub c a and v2 = Vec3.sub p a in
  let d00 = Vec3.dot v0 v0 and d01 = Vec3.dot v0 v1 and d11 = Vec3.dot v1 v1 in
  let d20 = Vec3.dot v2 v0 and d21 = Vec3.dot v2 v1 in
  let den = (d00 *. d11) -. (d01 *. d01) in
  if den = 0. then (1., 0., 0.)
  else
    let v = ((d11 *. d20) -. (d01 *. d21)) /. den
    and w = ((d00 *. d21) -. (d01 *. d20)) /. den in
    (1. -. v -. w, v, w)

(* Which part of a capped cylinder p lies on: 0 side, 1 base cap, 2 top cap; the nearest
   surface wins, which settles points on the rim. *)
let cylinder_part (base : Vec3.t) axis height radius caps p =
  let q = Vec3.sub p base in
  let y = Vec3.dot q axis in
  if not caps then 0
  else
    let rho = Vec3.length (Vec3.madd q (-.y) axis) in
    let ds = Float.abs (radius -. rho)
    and d0 = Float.abs y
    and d1 = Float.abs (height -. y) in
    if ds <= d0 && ds <= d1 then 0 else if d0 <= d1 then 1 else 2

(* Which part of a cone p lies on, as for the cylinder: 0 side, 1 base cap, 2 top cap. *)
let cone_part (base : Vec3.t) axis height r0 r1 caps p =
  if not caps then 0
  else
    let q = Vec3.sub p base in
    let y = Vec3.dot q axis in
    let rho = Vec3.length (Vec3.madd q (-.y) axis) in
    let rr = r0 +. ((r1 -. r0) *. y /. height) in
    let ds = Float.abs (rr -. rho)
    and d0 = if r0 > 0. then Float.abs y else Float.infinity
    and d1 = if r1 > 0. then Float.abs (height -. y) else Float.infinity in
    if ds <= d0 && ds <= d1 then 0 else if d0 <= d1 then 1 else 2

(* The face of a box nearest to (x, y, z), as 0..5 = −x, +x, −y, +y, −z, +z; the first
   of equals wins. *)
let[@inline] box_face_s (mn : Vec3.t) (mx : Vec3.t) x y z =
  let best = ref 0 and bd = ref (Float.abs (x -. mn.x)) in
  let d = Float.abs (mx.x -. x) in
  if d < !bd then (
    bd := d;
    best := 1);
  let d = Float.abs (y -. mn.y) in
  if d < !bd then (
    bd := d;
    best := 2);
  let d = Float.abs (mx.y -. y) in
  if d < !bd then (
    bd := d;
    best := 3);
  let d = Float.abs (z -. mn.z) in
  if d < !bd then (
    bd := d;
    best := 4);
  let d = Float.abs (mx.z -. z) in
  if d < !bd then best := 5;
  !best

let box_face mn mx (p : Vec3.t) = box_face_s mn mx p.x p.y p.z

let normal s p =
  match s with
  | Sphere { center; _ } -> Vec3.normalize (Vec3.sub p center)
  | Plane { normal; _ } -> normal
  | Parallelogram { pn; _ } -> pn
  | Triangle { tn; normals = None; _ } -> tn
  | Triangle { a; b; c; tn; normals = Some (na, nb, nc); _ } ->
      let u, v, w = barycentric a b c p in
      let n = Vec3.add (Vec3.smul u na) (Vec3.add (Vec3.smul v nb) (Vec3.smul w nc)) in
      let n = Vec3.normalize n in
      if Vec3.dot n n = 0. then tn else n
  | Paraboloid { vertex; axis; k; _ } ->
      (* ∇(|x⊥|² − k·y') = 2·x⊥ − k·axis: away from the cup's inside. *)
      let q = Vec3.sub p vertex in
      let y = Vec3.dot q axis in
      let xp = Vec3.madd q (-.y) axis in
      Vec3.normalize (Vec3.madd (Vec3.smul 2. xp) (-.k) axis)
  | Box { min; max } -> (
      match box_face min max p with
      | 0 -> Vec3.v (-1.) 0. 0.
      | 1 -> Vec3.x_axis
      | 2 -> Vec3.v 0. (-1.) 0.
      | 3 -> Vec3.y_axis
      | 4 -> Vec3.v 0. 0. (-1.)
      | _ -> Vec3.z_axis)
  | Cylinder { base; axis; height; radius; caps; _ } -> (
      match cylinder_part base axis height radius caps p with
      | 1 -> Vec3.neg axis
      | 2 -> axis
      | _ ->
          let q = Vec3.sub p base in
          let n = Vec3.normalize (Vec3.madd q (-.Vec3.dot q axis) axis) in
          if Vec3.dot n n = 0. then axis else n)
  | Disk { normal; _ } -> normal
  | Cone { base; axis; height; r0; r1; caps; _ } -> (
      match cone_part base axis height r0 r1 caps p with
      | 1 -> Vec3.neg axis
      | 2 -> axis
      | _ ->
          (* ∇(|x⊥|² − r(y')²) ∝ x⊥/|x⊥| − k·axis with k = (r1 − r0)/h. *)
          let q = Vec3.sub p base in
          let xp = Vec3.madd q (-.Vec3.dot q axis) axis in
          let l = Vec3.length xp in
          if l = 0. then if r1 < r0 then axis else Vec3.neg axis
          else
            Vec3.normalize
              (Vec3.madd (Vec3.smul (1. /. l) xp) (-.(r1 -. r0) /. height) axis))
  | Torus { center; axis; major; _ } ->
      (* Away from the nearest point of the ring of radius R. *)
      let q = Vec3.sub p center in
      let xp = Vec3.madd q (-.Vec3.dot q axis) axis in
      let l = Vec3.length xp in
      if l = 0. then if Vec3.dot q axis >= 0. then axis else Vec3.neg axis
      else Vec3.normalize (Vec3.madd q (-.major /. l) xp)
  | Mesh _ -> invalid_arg "Shape.normal: a mesh's surface is its triangles (Shape.face)"
  | Csg _ ->
      invalid_arg
        "Shape.normal: a CSG object has no surface of its own; ask its leaf \
         (Shape.csg_leaf)"

(* [normal] in scalars for the shapes most scenes are made of, the same operations;
   the others build the point and the normal. *)
let normal_into s (f : Frag.t) =
  match s with
  | Sphere { center; _ } ->
      let x = f.x -. center.x and y = f.y -. center.y and z = f.z -. center.z in
      let l = Vec3.length3 x y z in
      if l = 0. then (
        f.nx <- 0.;
        f.ny <- 0.;
        f.nz <- 0.)
      else
        let k = 1. /. l in
        f.nx <- k *. x;
        f.ny <- k *. y;
        f.nz <- k *. z
  | Plane { normal; _ } | Disk { normal; _ } -> Frag.set_normal f normal
  | Parallelogram { pn; _ } -> Frag.set_normal f pn
  | Triangle { tn; normals = None; _ } -> Frag.set_normal f tn
  | Box { min; max } -> (
      match box_face_s min max f.x f.y f.z with
      | 0 ->
          f.nx <- -1.;
          f.ny <- 0.;
          f.nz <- 0.
      | 1 -> Frag.set_normal f Vec3.x_axis
      | 2 ->
          f.nx <- 0.;
          f.ny <- -1.;
          f.nz <- 0.
      | 3 -> Frag.set_normal f Vec3.y_axis
      | 4 ->
          f.nx <- 0.;
          f.ny <- 0.;
          f.nz <- -1.
      | _ -> Frag.set_normal f Vec3.z_axis)
  | Triangle _ | Paraboloid _ | Cylinder _ | Cone _ | Torus _ | Mesh _ | Csg _ ->
      Frag.set_normal f (normal s (Frag.point f))

let frac x = x -. Float.floor x
let clamp01 x = if x > 0. then if x < 1. then x else 1. else 0.

(* Angle around [axis] in the frame (e1, e2), as a fraction of a turn in [0, 1). *)
let turn e1 e2 q =
  let u = 0.5 +. (Float.atan2 (Vec3.dot q e2) (Vec3.dot q e1) /. (2. *. Float.pi)) in
  if u >= 1. then 0. else clamp01 u

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
  | Parallelogram { origin; edge1; edge2; w; _ } ->
      let a, b = para_coords origin edge1 edge2 w p in
      (clamp01 a, clamp01 b)
  | Triangle { a; b; c; uvs; _ } -> (
      let l0, l1, l2 = barycentric a b c p in
      match uvs with
      | None -> (clamp01 l1, clamp01 l2)
      | Some ((u0, v0), (u1, v1), (u2, v2)) ->
          ((l0 *. u0) +. (l1 *. u1) +. (l2 *. u2), (l0 *. v0) +. (l1 *. v1) +. (l2 *. v2))
      )
  | Paraboloid { vertex; axis; height; e1; e2; _ } ->
      let q = Vec3.sub p vertex in
      (turn e1 e2 q, clamp01 (Vec3.dot q axis /. height))
  | Cylinder { base; axis; height; radius; caps; e1; e2 } -> (
      let q = Vec3.sub p base in
      match cylinder_part base axis height radius caps p with
      | 0 -> (turn e1 e2 q, clamp01 (Vec3.dot q axis /. height))
      | part ->
          let q = if part = 2 then Vec3.madd q (-.height) axis else q in
          let s = 0.5 /. radius in
          (clamp01 (0.5 +. (s *. Vec3.dot q e1)), clamp01 (0.5 +. (s *. Vec3.dot q e2))))
  | Disk { center; radius; e1; e2; _ } ->
      let q = Vec3.sub p center in
      let s = 0.5 /. radius in
      (clamp01 (0.5 +. (s *. Vec3.dot q e1)), clamp01 (0.5 +. (s *. Vec3.dot q e2)))
  | Box { min; max } -> (
      (* Each face maps its own rectangle onto the unit square. *)
      let f lo hi x = clamp01 ((x -. lo) /. (hi -. lo)) in
      match box_face min max p with
      | 0 | 1 -> (f min.z max.z p.z, f min.y max.y p.y)
      | 2 | 3 -> (f min.x max.x p.x, f min.z max.z p.z)
      | _ -> (f min.x max.x p.x, f min.y max.y p.y))
  | Cone { base; axis; height; r0; r1; caps; e1; e2 } -> (
      let q = Vec3.sub p base in
      match cone_part base axis height r0 r1 caps p with
      | 0 -> (turn e1 e2 q, clamp01 (Vec3.dot q axis /. height))
      | part ->
          let q = if part = 2 then Vec3.madd q (-.height) axis else q in
          let s = 0.5 /. if part = 2 then r1 else r0 in
          (clamp01 (0.5 +. (s *. Vec3.dot q e1)), clamp01 (0.5 +. (s *. Vec3.dot q e2))))
  | Torus { center; axis; major; e1; e2; _ } ->
      (* u the turn around the axis, v the turn around the tube. *)
      let q = Vec3.sub p center in
      let y = Vec3.dot q axis in
      let rho = Vec3.length (Vec3.madd q (-.y) axis) in
      let v = 0.5 +. (Float.atan2 y (rho -. major) /. (2. *. Float.pi)) in
      (turn e1 e2 q, if v >= 1. then 0. else clamp01 v)
  | Mesh _ | Csg _ -> (0., 0.)

let uv_into s (f : Frag.t) =
  let u, v = uv s (Frag.point f) in
  f.u <- u;
  f.v <- v

let bbox = bbox_of

(* Every variant moved by d; precomputed directions, normals and frames stay as they were
   (they do not depend on the position), offsets that do are recomputed. *)
let translate (d : Vec3.t) = function
  | Sphere { center; radius } -> Sphere { center = Vec3.add center d; radius }
  | Plane { normal; offset } -> Plane { normal; offset = offset +. Vec3.dot normal d }
  | Parallelogram { origin; edge1; edge2; pn; w; _ } ->
      let origin = Vec3.add origin d in
      Parallelogram { origin; edge1; edge2; pn; w; pd = Vec3.dot pn origin }
  | Triangle { a; b; c; tn; normals; uvs } ->
      Triangle { a = Vec3.add a d; b = Vec3.add b d; c = Vec3.add c d; tn; normals; uvs }
  | Paraboloid p -> Paraboloid { p with vertex = Vec3.add p.vertex d }
  | Box { min; max } -> Box { min = Vec3.add min d; max = Vec3.add max d }
  | Cylinder c -> Cylinder { c with base = Vec3.add c.base d }
  | Disk k -> Disk { k with center = Vec3.add k.center d }
  | Cone c -> Cone { c with base = Vec3.add c.base d }
  | Torus t -> Torus { t with center = Vec3.add t.center d }
  | Mesh { mesh; solid } -> Mesh { mesh = Trimesh.translate d mesh; solid }
  | Csg { op; members; _ } ->
      csg op
        (Array.to_list
           (Array.map
              (fun (m : csg_member) ->
                (m.shape, Transform.then_ m.transform (Transform.translate d)))
              members))

let name = function
  | Sphere _ -> "sphere"
  | Plane _ -> "plane"
  | Parallelogram _ -> "parallelogram"
  | Triangle { normals = None; uvs = None; _ } -> "triangle"
  | Triangle _ -> "mesh"
  | Paraboloid _ -> "paraboloid"
  | Box _ -> "box"
  | Cylinder _ -> "cylinder"
  | Disk _ -> "disk"
  | Cone _ -> "cone"
  | Mesh _ -> "mesh"
  | Torus _ -> "torus"
  | Csg { op = Union; _ } -> "union"
  | Csg { op = Merge; _ } -> "merge"
  | Csg { op = Intersection; _ } -> "intersection"
  | Csg { op = Difference; _ } -> "difference"

let mesh m = Mesh { mesh = m; solid = false }
let solid_mesh m = Mesh { mesh = m; solid = true }

(* Face [k] of a mesh as the triangle that [mesh_triangle] makes of its corners. *)
let face m k =
  let normals =
    if Trimesh.has_normals m k then
      Some (Trimesh.normal m k 0, Trimesh.normal m k 1, Trimesh.normal m k 2)
    else None
  in
  let uvs =
    if Trimesh.has_uvs m k then Some (Trimesh.uv m k 0, Trimesh.uv m k 1, Trimesh.uv m k 2)
    else None
  in
  triangle_gen ?normals ?uvs (Trimesh.vertex m k 0) (Trimesh.vertex m k 1)
    (Trimesh.vertex m k 2)

let faces m = List.init (Trimesh.count m) (face m)
