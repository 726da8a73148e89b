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
  | Closed_mesh of { tris : t array; mbounds : Bbox.t option }
  | Mesh of Trimesh.t
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
let[@inline] sphere_sc cx cy cz radius ox oy oz dx dy dz tmin tmax =
  (* The same operations as the vector form (f = O − C, perp = f − (b/a)·d, the lengths
     of perp and f), in scalars so that nothing is allocated, and with an early miss
     when |perp|² is clearly beyond r²: most rays miss most spheres, and the exact
     test would say the same. *)
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
      if q = 0. then
        let t = -.b /. a in
        if in_range t tmin tmax then t else Float.infinity
      else
        let t0 = q /. a and t1 = c /. q in
        (* Typed comparisons (no NaN here: disc ≥ 0 and q ≠ 0); Float.min costs a C call. *)
        let lo = if t0 < t1 then t0 else t1 and hi = if t0 < t1 then t1 else t0 in
        if in_range lo tmin tmax then lo
        else if in_range hi tmin tmax then hi
        else Float.infinity

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

(* Both roots of a·t² + b·t + c in increasing order, by the stable formula; the linear and
   the rootless cases give infinities. Used by the quadrics with a height range, where the
   nearer root may be cut away and the farther one kept. *)
let roots a b c =
  if a = 0. then
    if b = 0. then (Float.infinity, Float.infinity)
    else
      let t = -.c /. b in
      (t, Float.infinity)
  else
    let disc = (b *. b) -. (4. *. a *. c) in
    if disc < 0. || Float.is_nan disc then (Float.infinity, Float.infinity)
    else
      let s = Float.sqrt disc in
      let q = if b < 0. then -0.5 *. (b -. s) else -0.5 *. (b +. s) in
      if q = 0. then (0., 0.)
      else
        let t0 = q /. a and t1 = c /. q in
        (Floats.min t0 t1, Floats.max t0 t1)

(* Paraboloid in its frame: y' = (P − V)·axis, x⊥ = (P − V) − y'·axis, surface
   |x⊥|² = k·y' with k = r²/h, kept for 0 ≤ y' ≤ h (open cup, seen from both sides).
   Along the ray, with f = O − V: a = |d⊥|², b = 2·f⊥·d⊥ − k·d_y, c = |f⊥|² − k·f_y. A ray
   parallel to the axis has a = 0 and one root; nearly parallel (a = 1e-18) the stable
   formula keeps the finite root (9.4999999905 in doc/reference/numerics.md) where the naive one gives 0. *)
let[@inline] paraboloid_root t fy dy height tmin tmax =
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
      if paraboloid_root t f_y d_y height tmin tmax then t else Float.infinity
  else
    let disc = (b *. b) -. (4. *. a *. c) in
    if disc < 0. || Float.is_nan disc then Float.infinity
    else
      let s = Float.sqrt disc in
      let q = if b < 0. then -0.5 *. (b -. s) else -0.5 *. (b +. s) in
      if q = 0. then
        if paraboloid_root 0. f_y d_y height tmin tmax then 0. else Float.infinity
      else
        let u = q /. a and v = c /. q in
        let t0 = Floats.min u v and t1 = Floats.max u v in
        if paraboloid_root t0 f_y d_y height tmin tmax then t0
        else if paraboloid_root t1 f_y d_y height tmin tmax then t1
        else Float.infinity

let intersect_paraboloid vertex axis height k r tmin tmax =
  let o = Ray.origin r and d = Ray.dir r in
  paraboloid_s vertex axis height k o.x o.y o.z d.x d.y d.z tmin tmax

(* Slab test for an axis-aligned box: the entry t if it lies in (tmin, tmax), else the
   exit t (origin inside). Zero direction components give ±inf bounds; 0·inf (origin on
   a face plane) gives NaN, which the comparisons ignore. *)
let[@inline] box_s (mn : Vec3.t) (mx : Vec3.t) ox oy oz ix iy iz tmin tmax =
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
  else if in_range t0 tmin tmax then t0
  else if in_range t1 tmin tmax then t1
  else Float.infinity

let intersect_box mn mx r tmin tmax =
  let o = Ray.origin r and inv = Ray.inv_dir r in
  box_s mn mx o.x o.y o.z inv.x inv.y inv.z tmin tmax

(* A disk of radius r at [center] in the plane of [normal], t from the plane test. *)
let[@inline] disk_s (center : Vec3.t) (normal : Vec3.t) radius ox oy oz dx dy dz tmin tmax
    =
  let denom = (dx *. normal.x) +. (dy *. normal.y) +. (dz *. normal.z) in
  if denom = 0. then Float.infinity
  else
    let t =
      (((center.x -. ox) *. normal.x)
      +. ((center.y -. oy) *. normal.y)
      +. ((center.z -. oz) *. normal.z))
      /. denom
    in
    if in_range t tmin tmax then
      let qx = ox +. (t *. dx) -. center.x
      and qy = oy +. (t *. dy) -. center.y
      and qz = oz +. (t *. dz) -. center.z in
      if (qx *. qx) +. (qy *. qy) +. (qz *. qz) <= radius *. radius then t
      else Float.infinity
    else Float.infinity

let disk_hit center normal radius r tmin tmax =
  let o = Ray.origin r and d = Ray.dir r in
  disk_s center normal radius o.x o.y o.z d.x d.y d.z tmin tmax

(* Cylinder side: the 2-D circle version of the sphere's stable discriminant, in the plane
   perpendicular to the axis (f⊥ and d⊥); kept for 0 ≤ y' ≤ h. Caps are disks. A ray
   parallel to the axis has a = 0 and misses the side (the caps catch it). *)
let intersect_cylinder base axis height radius caps r tmin tmax =
  let o = Ray.origin r and d = Ray.dir r in
  let f = Vec3.sub o base in
  let fy = Vec3.dot f axis and dy = Vec3.dot d axis in
  let fp = Vec3.madd f (-.fy) axis and dp = Vec3.madd d (-.dy) axis in
  let a = Vec3.dot dp dp in
  let side =
    if a = 0. then Float.infinity
    else
      let b = Vec3.dot fp dp in
      let l = Vec3.length (Vec3.madd fp (-.b /. a) dp) in
      let disc = a *. (radius -. l) *. (radius +. l) in
      if disc < 0. || Float.is_nan disc then Float.infinity
      else
        let fl = Vec3.length fp in
        let c = (fl -. radius) *. (fl +. radius) in
        let s = Float.sqrt disc in
        let q = if b < 0. then s -. b else -.(b +. s) in
        let t0, t1 =
          if q = 0. then (-.b /. a, Float.infinity)
          else (Floats.min (q /. a) (c /. q), Floats.max (q /. a) (c /. q))
        in
        let ok t =
          in_range t tmin tmax
          &&
          let y = fy +. (t *. dy) in
          y >= 0. && y <= height
        in
        if ok t0 then t0 else if ok t1 then t1 else Float.infinity
  in
  if not caps then side
  else
    let tmax' = Floats.min side tmax in
    let t_lo = disk_hit base axis radius r tmin tmax' in
    let tmax' = Floats.min t_lo tmax' in
    let t_hi = disk_hit (Vec3.madd base height axis) axis radius r tmin tmax' in
    Floats.min side (Floats.min t_lo t_hi)

(* Cone side: |x⊥| = r(y') with r linear from r0 at y' = 0 to r1 at y' = h, kept for
   0 ≤ y' ≤ h (where r ≥ 0, so the other nappe of the double cone is cut away). With
   k = (r1 − r0)/h and ρ(t) = r0 + k·(f_y + t·d_y): a = |d⊥|² − k²·d_y²,
   b = 2·(f⊥·d⊥ − k·d_y·ρ₀), c = |f⊥|² − ρ₀², solved by the stable formula. Caps are
   disks (none at a point end). *)
let intersect_cone base axis height r0 r1 caps r tmin tmax =
  let o = Ray.origin r and d = Ray.dir r in
  let f = Vec3.sub o base in
  let fy = Vec3.dot f axis and dy = Vec3.dot d axis in
  let fp = Vec3.madd f (-.fy) axis and dp = Vec3.madd d (-.dy) axis in
  let k = (r1 -. r0) /. height in
  let rho0 = r0 +. (k *. fy) in
  let a = Vec3.dot dp dp -. (k *. k *. dy *. dy) in
  let b = 2. *. (Vec3.dot fp dp -. (k *. dy *. rho0)) in
  let c = Vec3.dot fp fp -. (rho0 *. rho0) in
  let t0, t1 = roots a b c in
  let ok t =
    in_range t tmin tmax
    &&
    let y = fy +. (t *. dy) in
    y >= 0. && y <= height
  in
  let side = if ok t0 then t0 else if ok t1 then t1 else Float.infinity in
  if not caps then side
  else
    let tmax' = Floats.min side tmax in
    let t_lo = if r0 > 0. then disk_hit base axis r0 r tmin tmax' else Float.infinity in
    let tmax' = Floats.min t_lo tmax' in
    let t_hi =
      if r1 > 0. then disk_hit (Vec3.madd base height axis) axis r1 r tmin tmax'
      else Float.infinity
    in
    Floats.min side (Floats.min t_lo t_hi)

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

type hit = { mutable tmin : float; mutable tmax : float; mutable t : float }

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
  | Closed_mesh { mbounds; _ } -> mbounds
  | Mesh m -> Some (Trimesh.bounds m)
  | Csg { cbounds; _ } -> cbounds

(* --- Solids and CSG ------------------------------------------------------------------ *)

(* Whether a point is inside a solid; a point on the boundary counts as inside. A plane
   is the half-space n̂·P ≤ offset. *)
let rec inside s (p : Vec3.t) =
  match s with
  | Sphere { center; radius } ->
      let q = Vec3.sub p center in
      Vec3.dot q q <= radius *. radius
  | Plane { normal; offset } -> Vec3.dot normal p <= offset
  | Box { min; max } ->
      p.x >= min.x && p.x <= max.x && p.y >= min.y && p.y <= max.y && p.z >= min.z
      && p.z <= max.z
  | Cylinder { base; axis; height; radius; caps = true; _ } ->
      let q = Vec3.sub p base in
      let y = Vec3.dot q axis in
      y >= 0. && y <= height
      &&
      let xp = Vec3.madd q (-.y) axis in
      Vec3.dot xp xp <= radius *. radius
  | Cone { base; axis; height; r0; r1; caps = true; _ } ->
      let q = Vec3.sub p base in
      let y = Vec3.dot q axis in
      y >= 0. && y <= height
      &&
      let xp = Vec3.madd q (-.y) axis in
      let rr = r0 +. ((r1 -. r0) *. y /. height) in
      Vec3.dot xp xp <= rr *. rr
  | Torus { center; axis; major; minor; _ } ->
      let q = Vec3.sub p center in
      let y = Vec3.dot q axis in
      let rho = Float.sqrt (Float.max 0. (Vec3.dot q q -. (y *. y))) in
      let dr = rho -. major in
      (dr *. dr) +. (y *. y) <= minor *. minor
  | Closed_mesh { tris; _ } ->
      (* Parity of the crossings of a ray from p in a fixed direction that no axis-aligned
         feature lies along. *)
      let r =
        Ray.make_raw p (Vec3.v 0.5773502691896258 0.5773502691896257 0.5773502691896259)
      in
      let n = ref 0 in
      Array.iter
        (function
          | Triangle { a; b; c; _ } ->
              if intersect_triangle a b c r 0. Float.infinity < Float.infinity then incr n
          | _ -> ())
        tris;
      !n land 1 = 1
  | Csg { op; members; _ } -> (
      let ins (m : csg_member) = inside m.shape (Transform.inv_point m.transform p) in
      match op with
      | Union | Merge -> Array.exists ins members
      | Intersection -> Array.for_all ins members
      | Difference ->
          ins members.(0)
          &&
          let rec none i =
            i >= Array.length members || ((not (ins members.(i))) && none (i + 1))
          in
          none 1)
  | Cylinder { caps = false; _ }
  | Cone { caps = false; _ }
  | Parallelogram _ | Triangle _ | Paraboloid _ | Disk _ | Mesh _ ->
      false

let rec is_solid = function
  | Sphere _ | Plane _ | Box _ | Torus _ | Closed_mesh _ -> true
  | Cone { caps; _ } -> caps
  | Csg { members; _ } -> Array.for_all (fun (m : csg_member) -> is_solid m.shape) members
  | Cylinder { caps; _ } -> caps
  | Parallelogram _ | Triangle _ | Paraboloid _ | Disk _ | Mesh _ -> false

(* A member's crossings are found by asking again past the last root; a shape has few
   roots, and this bound only guards against a surface that would never stop. *)
let max_roots = 64

let[@inline] member_ray (m : csg_member) r =
  if Transform.is_identity m.transform then r
  else
    Ray.make_raw
      (Transform.inv_point m.transform (Ray.origin r))
      (Transform.inv_vector m.transform (Ray.dir r))

(* How a CSG object knows a member's inside at one of its gaps (see [crossings_in]): a
   [tested] member is tested there; a followed one is [followed_out] or [followed_in],
   its state along the ray, known from its own crossings. *)
let tested = -1
let followed_out = 0
let followed_in = 1

(* The tests of simple surfaces that [inside] makes on a member, at most: what a tested
   member's test at one gap counts as (Stats.spend). *)
let inside_cost = function
  | Closed_mesh { tris; _ } -> max 1 (Array.length tris)
  | Csg { leaf_count; _ } -> max 1 leaf_count
  | _ -> 1

(* The member whose leaves include [leaf]: the last one whose first leaf is at most it
   (members list their leaves in order, and one without any is never the answer). *)
let member_of (members : csg_member array) leaf =
  let rec go lo hi =
    if hi - lo <= 1 then lo
    else
      let mid = (lo + hi) / 2 in
      if members.(mid).first_leaf <= leaf then go mid hi else go lo mid
  in
  go 0 (Array.length members)

(* The inside of member [i] at [p] (a point of the CSG object's space): its followed state,
   or its own test. *)
let[@inline] member_inside (members : csg_member array) states i p =
  let st = Array.unsafe_get states i in
  if st <> tested then st = followed_in
  else
    let m = Array.unsafe_get members i in
    inside m.shape (Transform.inv_point m.transform p)

(* [inside] of a CSG object at [p], each member's inside as [member_inside] has it. *)
let combined op (members : csg_member array) states p =
  let n = Array.length members in
  match op with
  | Union | Merge ->
      let rec any i = i < n && (member_inside members states i p || any (i + 1)) in
      any 0
  | Intersection ->
      let rec all i = i >= n || (member_inside members states i p && all (i + 1)) in
      all 0
  | Difference ->
      let rec none i =
        i >= n || ((not (member_inside members states i p)) && none (i + 1))
      in
      member_inside members states 0 p && none 1

(* The common shapes' tests are inlined here, reading the interval from and storing the
   root into the caller's record (a float record is flat): no float is boxed. *)
let rec intersect_into s r (h : hit) =
  let tmin = h.tmin and tmax = h.tmax in
  match s with
  | Sphere { center; radius } -> h.t <- intersect_sphere center radius r tmin tmax
  | Plane { normal; offset } -> h.t <- intersect_plane normal offset r tmin tmax
  | Triangle { a; b; c; _ } -> h.t <- intersect_triangle a b c r tmin tmax
  | Parallelogram { origin; edge1; edge2; pn; w; pd } ->
      h.t <- intersect_parallelogram origin edge1 edge2 pn w pd r tmin tmax
  | Box { min; max } -> h.t <- intersect_box min max r tmin tmax
  | Paraboloid { vertex; axis; height; k; _ } ->
      h.t <- intersect_paraboloid vertex axis height k r tmin tmax
  | Cylinder { base; axis; height; radius; caps; _ } ->
      h.t <- intersect_cylinder base axis height radius caps r tmin tmax
  | Disk { center; normal; radius; _ } -> h.t <- disk_hit center normal radius r tmin tmax
  | Cone { base; axis; height; r0; r1; caps; _ } ->
      h.t <- intersect_cone base axis height r0 r1 caps r tmin tmax
  | Torus { center; axis; major; minor; _ } ->
      h.t <- torus_roots center axis major minor r tmin tmax
  | Closed_mesh { tris; _ } ->
      let best = ref tmax in
      Array.iter
        (fun tr ->
          let t = intersect tr r tmin !best in
          if t < !best then best := t)
        tris;
      h.t <- (if !best < tmax then !best else Float.infinity)
  | Mesh m ->
      let q = Probe.create () in
      Probe.of_ray q r;
      q.p_tmin <- tmin;
      q.p_tmax <- tmax;
      ignore (Trimesh.nearest m q);
      h.t <- q.p_t
  | Csg _ ->
      h.t <-
        (match crossings_in (Stats.current ()) s r tmin false with
        | (t, _) :: _, _ when t < tmax -> t
        | _ -> Float.infinity)

and intersect s r tmin tmax =
  let h = { tmin; tmax; t = Float.infinity } in
  intersect_into s r h;
  h.t

(* Every root of member [m] (number [i]) after [tmin], each paired with the leaf whose
   surface it lies on, prepended to [acc]; each surface's root sought is one unit of
   work for [w]. For a CSG member followed along the ray (see [crossings_in]), its state
   just after [tmin] goes into [states.(i)]. *)
and member_crossings w (m : csg_member) r tmin acc states i =
  let r' = member_ray m r in
  match m.shape with
  | Closed_mesh { tris; _ } ->
      Stats.spend w (Array.length tris);
      let acc = ref acc in
      Array.iteri
        (fun k tr ->
          let t = intersect tr r' tmin Float.infinity in
          if t < Float.infinity then acc := (t, m.first_leaf + k) :: !acc)
        tris;
      !acc
  | Csg { op; _ } ->
      let followed = op <> Union in
      let crossings, state = crossings_in w m.shape r' tmin followed in
      if followed then states.(i) <- (if state then followed_in else followed_out);
      List.fold_left (fun acc (t, l) -> (t, m.first_leaf + l) :: acc) acc crossings
  | s ->
      let rec go acc tmin k =
        Stats.spend w 1;
        let t = intersect s r' tmin Float.infinity in
        if t < Float.infinity && k < max_roots then go ((t, m.first_leaf) :: acc) t (k + 1)
        else acc
      in
      go acc tmin 0

(* The crossings of the combined set's boundary after [tmin], nearest first, each with its
   leaf. Every member's roots are merged in order; between two consecutive roots (and
   after the last) nothing changes, so the inside of the combined set is tested once per
   gap, at its middle, and a root where it changes is a crossing. The answer does not
   depend on tmin (only which roots are kept): the first gap's state is sampled within
   the same gap whatever tmin is. Roots are computed up to infinity, so tmax plays no
   part at all.

   A member that is itself a CSG object (but a union, whose list keeps every surface) is
   not tested again at each gap: its crossings are where its own state changes, so its
   state is followed along the ray from the one it had just after [tmin], flipped at each
   of its crossings. Testing it would walk its whole tree at every gap of every level, and
   a difference nested n deep would cost n² tests per ray; followed, each level costs its
   gaps. The other members (surfaces, meshes, unions) are tested as the object's inside
   tests them. With [state], the second result is the object's inside just after [tmin]
   (for the object it is a member of); otherwise [false]. Each gap counts as the tests
   it makes, for [w]. *)
and crossings_in w s r tmin state =
  match s with
  | Csg { op; members; _ } -> (
      let n = Array.length members in
      let states = Array.make n tested in
      let ev = ref [] in
      for i = 0 to n - 1 do
        ev := member_crossings w members.(i) r tmin !ev states i
      done;
      let gap_cost = ref 1 and followed = ref false in
      for i = 0 to n - 1 do
        if states.(i) = tested then gap_cost := !gap_cost + inside_cost members.(i).shape
        else followed := true
      done;
      let gap_cost = !gap_cost and followed = !followed in
      let ev =
        List.stable_sort
          (fun ((a : float), (i : int)) (b, j) ->
            if a < b then -1 else if a > b then 1 else Int.compare i j)
          !ev
      in
      let state_at t =
        Stats.spend w gap_cost;
        combined op members states (Ray.at r t)
      in
      (* A crossing of a followed member flips its state. *)
      let pass leaf =
        if followed then
          let i = member_of members leaf in
          let st = states.(i) in
          if st <> tested then states.(i) <- followed_in - st
      in
      let rec skip t = function
        | (t', l) :: rest when t' = t ->
            pass l;
            skip t rest
        | l -> l
      in
      let rec walk before = function
        | [] -> []
        | (t, leaf) :: rest ->
            pass leaf;
            let rest = skip t rest in
            let probe =
              match rest with
              | (t', _) :: _ -> 0.5 *. (t +. t')
              | [] -> t +. Float.max 1. (Float.abs t)
            in
            let after = state_at probe in
            if after <> before then (t, leaf) :: walk after rest else walk before rest
      in
      match ev with
      | [] -> ([], state && state_at (tmin +. Float.max 1. (Float.abs tmin)))
      | _ when op = Union -> (ev, false) (* every member's surface, as a group *)
      | (t0, _) :: _ ->
          let first = state_at (0.5 *. (tmin +. t0)) in
          (walk first ev, first))
  | _ ->
      ( List.map
          (fun t -> (t, 0))
          (let t = intersect s r tmin Float.infinity in
           if t < Float.infinity then [ t ] else []),
        false )

let csg_crossings s r tmin = fst (crossings_in (Stats.current ()) s r tmin false)

type probe = Probe.t

let probe = Probe.create

(* The same tests as [intersect_into], on the probe's scalars; the quadrics with a height
   range (cylinder, paraboloid) build the ray their vector form needs. *)
let probe_into s (q : probe) =
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
  | Mesh m -> ignore (Trimesh.nearest m q)
  | Paraboloid { vertex; axis; height; k; _ } ->
      q.p_t <- paraboloid_s vertex axis height k q.ox q.oy q.oz q.dx q.dy q.dz tmin tmax
  | Cylinder _ | Cone _ | Torus _ | Closed_mesh _ | Csg _ ->
      let h = { tmin; tmax; t = Float.infinity } in
      intersect_into s (Ray.make_raw (Vec3.v q.ox q.oy q.oz) (Vec3.v q.dx q.dy q.dz)) h;
      q.p_t <- h.t

let probe_first_into s (q : probe) =
  match s with Mesh m -> ignore (Trimesh.first m q) | s -> probe_into s q

(* The simple surfaces of a shape as a CSG member: a closed mesh's triangles, a CSG
   object's leaves, or the shape itself. *)
let leaf_count = function
  | Csg { leaf_count; _ } -> leaf_count
  | Closed_mesh { tris; _ } -> Array.length tris
  | _ -> 1

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
            | Closed_mesh { tris; _ } ->
                Array.iter (fun tr -> add tr m.transform subtracted path) tris
            | shape -> add shape m.transform subtracted path)
          members
    | _ -> ()
  in
  walk s [];
  Array.of_list (List.rev !acc)

let closed_mesh tris =
  let tris = Array.of_list tris in
  let b =
    Array.fold_left
      (fun acc tr -> match bbox_of tr with Some b -> Bbox.union acc b | None -> acc)
      Bbox.empty tris
  in
  Closed_mesh { tris; mbounds = (if Array.length tris = 0 then None else Some b) }

let csg_leaf s r t =
  match s with
  | Csg _ ->
      (* The crossings from 0 (where every shading ray starts) or from before t: the same
         roots as the query that found t, so t is among them. *)
      let tmin = if t > 0. then 0. else t -. Float.max 1. (Float.abs t) in
      let best = ref 0 and bd = ref Float.infinity in
      List.iter
        (fun (t', l) ->
          let d = Float.abs (t' -. t) in
          if d < !bd then (
            bd := d;
            best := l))
        (csg_crossings s r tmin);
      !best
  | _ -> 0

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
  | Closed_mesh _ | Mesh _ ->
      invalid_arg "Shape.normal: a mesh's surface is its triangles (Shape.mesh_face)"
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
  | Triangle _ | Paraboloid _ | Cylinder _ | Cone _ | Torus _ | Closed_mesh _ | Mesh _
  | Csg _ ->
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
  | Closed_mesh _ | Mesh _ | Csg _ -> (0., 0.)

let uv_into s (f : Frag.t) =
  let u, v = uv s (Frag.point f) in
  f.u <- u;
  f.v <- v

let bbox = bbox_of

(* Every variant moved by d; precomputed directions, normals and frames stay as they were
   (they do not depend on the position), offsets that do are recomputed. *)
let rec translate (d : Vec3.t) = function
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
  | Closed_mesh { tris; _ } -> closed_mesh (Array.to_list (Array.map (translate d) tris))
  | Mesh m -> Mesh (Trimesh.translate d m)
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
  | Closed_mesh _ | Mesh _ -> "mesh"
  | Torus _ -> "torus"
  | Csg { op = Union; _ } -> "union"
  | Csg { op = Merge; _ } -> "merge"
  | Csg { op = Intersection; _ } -> "intersection"
  | Csg { op = Difference; _ } -> "difference"

let mesh m = Mesh m

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

let mesh_face s r t =
  match s with
  | Mesh m ->
      (* The triangles whose root is t are those hit in (pred t, succ t): roots do not
         depend on the interval, and the lowest index among them is the one the query
         that found t kept. *)
      let q = Probe.create () in
      Probe.of_ray q r;
      q.p_tmin <- Float.pred t;
      q.p_tmax <- Float.succ t;
      let k = Trimesh.nearest m q in
      face m (if k < 0 then 0 else k)
  | s -> s
