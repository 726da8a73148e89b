(* Ray queries: a linear scan for small scenes, a flattened bounding volume hierarchy
   built by the binned surface area heuristic otherwise. Unbounded primitives (planes),
   and any whose bounds are not finite, stay out of the tree in a short list that every
   query scans first.

   Equality with the linear scan. The scan keeps the hit with the smallest t, ties to the
   lower index. Shape intersections compute the same roots whatever tmin and tmax are
   (Shape.mli), so the scan's answer is the lexicographic minimum of (t, index) over the
   primitives' nearest roots in (tmin, tmax). The traversal computes the same minimum:
   each primitive is queried up to just past the best t (at or one float above its
   successor, {!Floats.above}), so an equal t is seen and the index decides, and a root
   beyond it that the bound lets through loses to the best; boxes are padded by a
   relative 1e-9 so that rounding in the slab test never culls a primitive whose hit lies
   on its own bounds; and a box is culled only when its entry is strictly beyond the best
   t. *)

type tree = {
  nodes : Float.Array.t;  (** the hierarchy's nodes, as {!Bvh.t}'s *)
  leaf_prims : Primitive.t array;  (** bounded primitives in leaf order *)
  leaf_idx : int array;  (** their indices in the scene's array *)
  sph : Float.Array.t;
      (** 4 per leaf slot (from the start; it may be longer): the centre and radius of an
          untransformed sphere, tested from here without reading its primitive; radius −1
          for any other primitive *)
  depth : int;  (** the tree's depth: an upper bound on the traversal stack *)
}

type t = {
  prims : Primitive.t array;
  weight : int;  (** the bounded primitives, a mesh counted as its faces *)
  outside : int array;
  planes : Float.Array.t;
      (** 4 per entry of [outside]: the normal and offset of an untransformed plane,
          tested from here without reading its primitive; a NaN normal for any other
          primitive *)
  tree : tree option;
  layers : layers option;
      (** instead of [outside] and [tree]: two structures over parts of [prims] *)
}

(* A scene's primitives in two parts, each with its own structure: [fixed] over those
   whose index [fixed_idx] lists (increasing), [moving] over the others. *)
and layers = {
  fixed : t;
  fixed_idx : int array;
  moving : t;
  moving_idx : int array;
  bvh : bool;  (** whether one structure over them all would be a tree *)
}

let min_bvh = 8
let uses_bvh a = match a.layers with Some l -> l.bvh | None -> a.weight >= min_bvh
let fixed_part a = Option.map (fun l -> l.fixed) a.layers
let fget = Float.Array.unsafe_get
let fset = Float.Array.unsafe_set

(* The most flat spheres a leaf is made of without a split search: a sphere's early miss
   costs less than a box test, and below a node of so few the walk would test about as
   many boxes as there are spheres. A leaf's slots are visited in order and the nearest
   hit is the least (t, index) whatever the order (see above), so the hit does not depend
   on how the spheres of such a leaf would have been split. Measured against 4 (in
   instructions): a million spheres in a grid build with 4.4 % fewer in the whole render
   at 64×48, field_100000 renders at 960×540 with 0.4 % fewer and field_10000 at 480×270
   with 0.4 % more; 6 saves less in the build (0.7 %). *)
let flat_leaf_max = 8

(* Whether [p] is tested from [sph] (a sphere in world space), not through its primitive. *)
let is_flat_sphere (p : Primitive.t) =
  match p.shape with Shape.Sphere _ -> Transform.is_identity p.transform | _ -> false

let plane_data prims outside =
  let planes = Float.Array.make (4 * Array.length outside) Float.nan in
  Array.iteri
    (fun k i ->
      let p : Primitive.t = prims.(i) in
      match p.shape with
      | Shape.Plane { normal; offset } when Transform.is_identity p.transform ->
          fset planes (4 * k) normal.x;
          fset planes ((4 * k) + 1) normal.y;
          fset planes ((4 * k) + 2) normal.z;
          fset planes ((4 * k) + 3) offset
      | _ -> ())
    outside;
  planes

let build prims =
  let n = Array.length prims in
  (* Every primitive's bounds in one pass, then the bounded ones' (all six finite) moved
     down in place and padded: one box per primitive, none allocated for a sphere. *)
  let pbox = Float.Array.create (6 * n) in
  Array.iteri (fun i p -> Primitive.bounds_into p pbox (6 * i)) prims;
  let bounded_at i =
    let q = 6 * i and ok = ref true in
    for k = 0 to 5 do
      if not (Float.is_finite (fget pbox (q + k))) then ok := false
    done;
    !ok
  in
  let flags = Bytes.init n (fun i -> if bounded_at i then '\001' else '\000') in
  let is_b i = Bytes.unsafe_get flags i = '\001' in
  let pick want =
    let k = ref 0 in
    for i = 0 to n - 1 do
      if is_b i = want then incr k
    done;
    let r = Array.make !k 0 and j = ref 0 in
    for i = 0 to n - 1 do
      if is_b i = want then (
        r.(!j) <- i;
        incr j)
    done;
    r
  in
  let m =
    let k = ref 0 in
    for i = 0 to n - 1 do
      if is_b i then incr k
    done;
    !k
  in
  (* The bounded primitives' indices; when all are, the k-th is k, with no array. *)
  let bounded = if m = n then [||] else pick true in
  let[@inline] at k = if m = n then k else Array.unsafe_get bounded k in
  (* A mesh counts as its faces, which one object each would have been. *)
  let weight =
    let w = ref 0 in
    for k = 0 to m - 1 do
      w := !w + Primitive.faces prims.(at k)
    done;
    !w
  in
  if weight < min_bvh then
    let outside = Array.init n Fun.id in
    {
      prims;
      weight;
      outside;
      planes = plane_data prims outside;
      tree = None;
      layers = None;
    }
  else
    let outside = pick false in
    for k = 0 to m - 1 do
      let q = 6 * at k in
      Bvh.pad_into pbox k (fget pbox q)
        (fget pbox (q + 1))
        (fget pbox (q + 2))
        (fget pbox (q + 3))
        (fget pbox (q + 4))
        (fget pbox (q + 5))
    done;
    let pbox = if m = n then pbox else Float.Array.sub pbox 0 (6 * m) in
    let flat =
      Bytes.init m (fun k -> if is_flat_sphere prims.(at k) then '\001' else '\000')
    in
    let { Bvh.nodes; order; depth } = Bvh.build ~cheap:(flat, flat_leaf_max) pbox in
    (* The leaf order as indices into [prims], in place. *)
    let leaf_idx = order in
    if m < n then Array.iteri (fun j k -> leaf_idx.(j) <- at k) leaf_idx;
    let leaf_prims = Array.map (fun i -> prims.(i)) leaf_idx in
    (* The tree does not keep the boxes: their array holds the spheres from here (its
       first 4m floats), rather than a new one beside it at the peak of memory. *)
    let sph = pbox in
    Float.Array.fill sph 0 (4 * m) (-1.);
    Array.iteri
      (fun j (p : Primitive.t) ->
        match p.shape with
        | Shape.Sphere { center; radius } when Transform.is_identity p.transform ->
            fset sph (4 * j) center.x;
            fset sph ((4 * j) + 1) center.y;
            fset sph ((4 * j) + 2) center.z;
            fset sph ((4 * j) + 3) radius
        | _ -> ())
      leaf_prims;
    {
      prims;
      weight;
      outside;
      planes = plane_data prims outside;
      tree = Some { nodes; leaf_prims; leaf_idx; sph; depth };
      layers = None;
    }

(* What [build] would decide, from each primitive's bounds as it reads them, without the
   tree: the weight of the bounded primitives (all six bounds finite). *)
let unindexed prims =
  let b = Float.Array.create 6 and weight = ref 0 in
  Array.iter
    (fun p ->
      Primitive.bounds_into p b 0;
      let ok = ref true in
      for k = 0 to 5 do
        if not (Float.is_finite (fget b k)) then ok := false
      done;
      if !ok then weight := !weight + Primitive.faces p)
    prims;
  let outside = Array.init (Array.length prims) Fun.id in
  {
    prims;
    weight = !weight;
    outside;
    planes = plane_data prims outside;
    tree = None;
    layers = None;
  }

(* --- Traversal -------------------------------------------------------------------- *)

(* What a domain's queries reuse, found by one look-up per query. The shadow query's: a
   probe that the caller fills, and for each light slot the scene index of the primitive
   that last blocked it (-1: none), tested before the walk. Shadow rays of neighbouring
   pixels tend to be blocked by the same object; since the answer is a boolean (is there
   any opaque crossing?), trying one first changes only how soon it is found, never what
   is found. Every query's: a scratch probe for transformed objects ([obj]), and the
   traversal stacks. *)
type scratch = {
  q : Shape.probe;
  obj : Shape.probe;
  mutable last : int array;
  stack : Bvh.walk;  (** the domain's traversal stack *)
  watched : Float.Array.t;  (** the watched box (min x y z, max x y z) *)
  mutable watching : bool;
  mutable touched : bool;
      (** whether a query since {!untouch} may have met the watched box *)
}

let scratch_key =
  Domain.DLS.new_key (fun () ->
      {
        q = Shape.probe ();
        obj = Shape.probe ();
        last = [||];
        stack = Bvh.new_walk ();
        watched = Float.Array.make 6 0.;
        watching = false;
        touched = false;
      })

let watch sc box =
  match box with
  | None -> sc.watching <- false
  | Some b ->
      if Float.Array.length b <> 6 then invalid_arg "Accel.watch: a box is 6 floats";
      Float.Array.blit b 0 sc.watched 0 6;
      sc.watching <- true

let untouch sc = sc.touched <- false

(* A query that an exception leaves (Sys.Break from a poll inside a CSG object's test)
   leaves its stack marked busy; every later query of the domain would make a new one. *)
let release sc = sc.stack.busy <- false
let touched sc = sc.touched

(* Whether the segment (t0, t1) of the probe's ray may meet the watched box: false only
   where every axis's slab is missed for certain (a NaN, from an origin on a slab plane
   with a direction along it, or an infinite t1, leaves it met). Divisions, not the
   probe's reciprocal, which a query may not have set yet. *)
let meets sc (q : Shape.probe) t0 t1 =
  let b = sc.watched in
  let lo = ref t0 and hi = ref t1 and miss = ref false in
  let axis o d k =
    let a = fget b k and c = fget b (k + 3) in
    if a > c || (d = 0. && (o < a || o > c)) then miss := true
    else if d = 0. then ()
    else
      let u = (a -. o) /. d and v = (c -. o) /. d in
      let near = if u < v then u else v and far = if u < v then v else u in
      if near > !lo then lo := near;
      if far < !hi then hi := far
  in
  axis q.ox q.dx 0;
  axis q.oy q.dy 1;
  axis q.oz q.dz 2;
  not (!miss || !lo > !hi)

(* A query over (t0, t1) seen by a watch: marks it touched where it may meet the box. *)
let[@inline] seen sc q t0 t1 =
  if sc.watching && (not sc.touched) && meets sc q t0 t1 then sc.touched <- true

(* One primitive over (h.tmin, tmax): the root, unboxed. *)
let[@inline] test p r tmax (h : Shape.hit) =
  h.tmax <- tmax;
  Primitive.intersect_into p r h;
  h.t

(* The nearest hit: every query with a ray goes through a probe, [Primitive.probe_into]
   computing the roots [Primitive.intersect_into] does, bit for bit. The traversal keeps
   the lexicographic minimum of (t, index): each primitive is queried up to just past the
   best t (p_tmax moves with the best hit), so that an equal t is seen and the index
   decides; the scratch probe for transformed objects is the domain's. *)
let[@inline] probe_test (p : Primitive.t) (q : Shape.probe) obj tmax =
  q.p_tmax <- tmax;
  (* An untransformed sphere or plane, tested here without the two dispatches of
     {!Primitive.probe_into}: the same root, left in [q.p_t] as it leaves it (the linear
     scans of small scenes and an animation's moving part are mostly these). *)
  (match p.shape with
  | Shape.Sphere { center; radius } when Transform.is_identity p.transform ->
      q.p_t <-
        Shape.sphere_sc center.x center.y center.z radius q.ox q.oy q.oz q.dx q.dy q.dz
          q.p_tmin tmax
  | Shape.Plane { normal; offset } when Transform.is_identity p.transform ->
      q.p_t <-
        Shape.plane_sc normal.x normal.y normal.z offset q.ox q.oy q.oz q.dx q.dy q.dz
          q.p_tmin tmax
  | _ -> Primitive.probe_into p q obj);
  q.p_t

(* [probe_test] of leaf slot [j]: a flat sphere's test on its scalars, the same roots. *)
let[@inline] slot_test tr j (q : Shape.probe) obj tmax =
  let sph = tr.sph in
  let r = fget sph ((4 * j) + 3) in
  if r >= 0. then (
    q.p_tmax <- tmax;
    Shape.sphere_sc
      (fget sph (4 * j))
      (fget sph ((4 * j) + 1))
      (fget sph ((4 * j) + 2))
      r q.ox q.oy q.oz q.dx q.dy q.dz q.p_tmin tmax)
  else probe_test (Array.unsafe_get tr.leaf_prims j) q obj tmax

let linear_nearest_probe prims (q : Shape.probe) obj =
  let best_t = ref q.p_tmax and best_i = ref (-1) in
  for i = 0 to Array.length prims - 1 do
    let t = probe_test (Array.unsafe_get prims i) q obj !best_t in
    if t < !best_t then (
      best_t := t;
      best_i := i)
  done;
  q.p_t <- (if !best_i < 0 then Float.infinity else !best_t);
  !best_i

let tree_nearest_probe a tr (q : Shape.probe) obj stack =
  let tmin = q.p_tmin in
  let best_t = ref q.p_tmax and best_i = ref (-1) and query = ref q.p_tmax in
  let outside = a.outside and prims = a.prims and planes = a.planes in
  for k = 0 to Array.length outside - 1 do
    let i = outside.(k) in
    let nx = fget planes (4 * k) in
    let t =
      if Float.is_nan nx then probe_test prims.(i) q obj !query
      else (
        q.p_tmax <- !query;
        Shape.plane_sc nx
          (fget planes ((4 * k) + 1))
          (fget planes ((4 * k) + 2))
          (fget planes ((4 * k) + 3))
          q.ox q.oy q.oz q.dx q.dy q.dz q.p_tmin !query)
    in
    if t < !best_t || (t = !best_t && i < !best_i) then (
      best_t := t;
      best_i := i;
      query := Floats.above t)
  done;
  let nodes = tr.nodes in
  let st = Bvh.take stack tr.depth in
  (if Bvh.start nodes q st tmin !best_t then
     let leaf = ref (Bvh.next_leaf nodes q st) in
     while !leaf >= 0 do
       let first = Bvh.link nodes !leaf in
       for j = first to first + Bvh.count nodes !leaf - 1 do
         let t = slot_test tr j q obj !query in
         if t <= !best_t then
           let i = Array.unsafe_get tr.leaf_idx j in
           if t < !best_t || i < !best_i then (
             best_t := t;
             best_i := i;
             query := Floats.above t)
       done;
       fset st.span 1 !best_t;
       leaf := Bvh.next_leaf nodes q st
     done);
  st.busy <- false;
  q.p_t <- (if !best_i < 0 then Float.infinity else !best_t);
  !best_i

let is_black (c : Color.t) = c.r = 0. && c.g = 0. && c.b = 0.

(* Every crossing of one primitive: advance tmin to the last root found; roots are
   recomputed identically each time, so the strict test t > tmin never returns the same
   root twice. *)
let crossings p r tmin tmax (h : Shape.hit) f acc =
  let acc = ref acc in
  h.tmin <- tmin;
  let t = ref (test p r tmax h) in
  while !t < tmax && not (is_black !acc) do
    acc := f p !t !acc;
    h.tmin <- !t;
    t := test p r tmax h
  done;
  !acc

(* With [only_transparent], opaque primitives are skipped: the caller knows that none
   crosses the segment, so they would leave [acc] as it is. *)
let[@inline] skipped only_transparent (p : Primitive.t) =
  only_transparent && p.material.transparency = 0.

let linear_fold ~only_transparent prims r tmin tmax f acc =
  let acc = ref acc and i = ref 0 in
  let h = { Shape.tmin; tmax; t = Float.infinity } in
  while !i < Array.length prims && not (is_black !acc) do
    let p = prims.(!i) in
    if not (skipped only_transparent p) then acc := crossings p r tmin tmax h f !acc;
    incr i
  done;
  !acc

(* Each bounded primitive sits in exactly one leaf, so the depth-first walk over the boxes
   the ray meets visits each primitive's crossings once. *)
(* Every primitive that the ray may cross in [tmin, tmax], unordered: the unbounded ones
   first, then depth-first over the boxes it meets, until [visit] answers true (stop).
   Each bounded primitive sits in exactly one leaf, so each is visited once. Whether a
   visit stopped the walk. *)
let tree_visit a tr r tmin tmax visit =
  let stack = (Domain.DLS.get scratch_key).stack in
  let stop = ref false in
  let outside = a.outside in
  let k = ref 0 in
  while (not !stop) && !k < Array.length outside do
    stop := visit a.prims.(outside.(!k));
    incr k
  done;
  if not !stop then (
    let q = Shape.probe () in
    Probe.of_ray q r;
    let nodes = tr.nodes in
    let st = Bvh.take stack tr.depth in
    (try
       let node =
         ref (if Bvh.start nodes q st tmin tmax then Bvh.next_leaf nodes q st else -1)
       in
       while !node >= 0 do
         let first = Bvh.link nodes !node in
         let j = ref first in
         while (not !stop) && !j < first + Bvh.count nodes !node do
           stop := visit (Array.unsafe_get tr.leaf_prims !j);
           incr j
         done;
         node := if !stop then -1 else Bvh.next_leaf nodes q st
       done
     with e ->
       st.busy <- false;
       raise e);
    st.busy <- false);
  !stop

let tree_fold ~only_transparent a tr r tmin tmax f acc =
  let acc = ref acc in
  let h = { Shape.tmin; tmax; t = Float.infinity } in
  if not (is_black !acc) then
    ignore
      (tree_visit a tr r tmin tmax (fun p ->
           if not (skipped only_transparent p) then
             acc := crossings p r tmin tmax h f !acc;
           is_black !acc));
  !acc

let rec fold ~only_transparent a r tmin tmax f acc =
  match a.layers with
  | Some l ->
      let acc = fold ~only_transparent l.fixed r tmin tmax f acc in
      if is_black acc then acc else fold ~only_transparent l.moving r tmin tmax f acc
  | None -> (
      match a.tree with
      | None -> linear_fold ~only_transparent a.prims r tmin tmax f acc
      | Some tr -> tree_fold ~only_transparent a tr r tmin tmax f acc)

let fold_hits a r tmin tmax f acc = fold ~only_transparent:false a r tmin tmax f acc

let fold_transparent_hits a r tmin tmax f acc =
  fold ~only_transparent:true a r tmin tmax f acc

(* --- Occlusion ---------------------------------------------------------------------- *)

(* The shadow query proper: no ray, no hit record, no closure (see {!scratch}). *)
let shadow_probe () = (Domain.DLS.get scratch_key).q

let[@inline] blocks ~any (p : Primitive.t) (q : Shape.probe) obj =
  if (not any) && p.material.transparency <> 0. then false
  else
    match p.shape with
    | Shape.Sphere { center; radius } when Transform.is_identity p.transform ->
        (* {!Primitive.probe_first_into}'s test of it, without the dispatch. *)
        Shape.sphere_sc center.x center.y center.z radius q.ox q.oy q.oz q.dx q.dy q.dz
          q.p_tmin q.p_tmax
        < q.p_tmax
    | _ ->
        Primitive.probe_first_into p q obj;
        q.p_t < q.p_tmax

(* [blocks] of leaf slot [j]. *)
let[@inline] slot_blocks ~any tr j (q : Shape.probe) obj =
  let sph = tr.sph in
  let r = fget sph ((4 * j) + 3) in
  if r >= 0. then
    Shape.sphere_sc
      (fget sph (4 * j))
      (fget sph ((4 * j) + 1))
      (fget sph ((4 * j) + 2))
      r q.ox q.oy q.oz q.dx q.dy q.dz q.p_tmin q.p_tmax
    < q.p_tmax
    && (any || (Array.unsafe_get tr.leaf_prims j).material.transparency = 0.)
  else blocks ~any (Array.unsafe_get tr.leaf_prims j) q obj

let linear_occluder ~any prims q obj =
  let found = ref (-1) and i = ref 0 in
  while !found < 0 && !i < Array.length prims do
    if blocks ~any (Array.unsafe_get prims !i) q obj then found := !i;
    incr i
  done;
  !found

(* The first primitive found crossing the probe's segment: an opaque one, or with [any]
   any one. *)
let rec occluder ~any a q obj stack =
  match a.layers with
  | Some l ->
      let i = occluder ~any l.fixed q obj stack in
      if i >= 0 then l.fixed_idx.(i)
      else
        let j = occluder ~any l.moving q obj stack in
        if j >= 0 then l.moving_idx.(j) else -1
  | None -> (
      match a.tree with
      | None -> linear_occluder ~any a.prims q obj
      | Some tr -> tree_occluder ~any a tr q obj stack)

and tree_occluder ~any a tr (q : Shape.probe) obj stack =
  let found = ref (-1) in
  let outside = a.outside and prims = a.prims and planes = a.planes in
  let k = ref 0 in
  while !found < 0 && !k < Array.length outside do
    let i = Array.unsafe_get outside !k in
    let p = Array.unsafe_get prims i and nx = fget planes (4 * !k) in
    if
      if Float.is_nan nx then blocks ~any p q obj
      else
        (any || p.material.transparency = 0.)
        && Shape.plane_sc nx
             (fget planes ((4 * !k) + 1))
             (fget planes ((4 * !k) + 2))
             (fget planes ((4 * !k) + 3))
             q.ox q.oy q.oz q.dx q.dy q.dz q.p_tmin q.p_tmax
           < q.p_tmax
    then found := i;
    incr k
  done;
  if !found < 0 then (
    let tmin = q.p_tmin and tmax = q.p_tmax in
    let nodes = tr.nodes in
    let st = Bvh.take stack tr.depth in
    let node =
      ref (if Bvh.start nodes q st tmin tmax then Bvh.next_leaf nodes q st else -1)
    in
    while !node >= 0 do
      let count = Bvh.count nodes !node in
      let first = Bvh.link nodes !node in
      let j = ref first in
      while !found < 0 && !j < first + count do
        if slot_blocks ~any tr !j q obj then found := Array.unsafe_get tr.leaf_idx !j;
        incr j
      done;
      node := if !found < 0 then Bvh.next_leaf nodes q st else -1
    done;
    st.busy <- false);
  !found

let rec nearest_probe_in a (q : Shape.probe) obj stack =
  match a.layers with
  | Some l ->
      (* As [nearest_into]'s two parts: the moving part up to just past the fixed part's
         hit t, the lexicographic minimum of (t, index). *)
      let tmin = q.p_tmin and tmax = q.p_tmax in
      let i = nearest_probe_in l.fixed q obj stack in
      let t = q.p_t in
      q.p_tmin <- tmin;
      q.p_tmax <- (if i >= 0 then Floats.above t else tmax);
      let j = nearest_probe_in l.moving q obj stack in
      if
        j >= 0 && (i < 0 || q.p_t < t || (q.p_t = t && l.moving_idx.(j) < l.fixed_idx.(i)))
      then l.moving_idx.(j)
      else (
        q.p_t <- (if i >= 0 then t else Float.infinity);
        if i >= 0 then l.fixed_idx.(i) else -1)
  | None -> (
      match a.tree with
      | None -> linear_nearest_probe a.prims q obj
      | Some tr -> tree_nearest_probe a tr q obj stack)

let domain_scratch () = Domain.DLS.get scratch_key

let nearest_probe_with sc a (q : Shape.probe) =
  Probe.set_inv_dir q;
  if sc.watching then (
    (* The segment up to the answer: no moving surface nearer than it means none of the
       watched box's crosses the ray before the answer. *)
    let t0 = q.p_tmin
    and t1 = q.p_tmax in
    let i = nearest_probe_in a q sc.obj sc.stack in
    seen sc q t0 (if i >= 0 && q.p_t < t1 then q.p_t else t1);
    i)
  else nearest_probe_in a q sc.obj sc.stack

let nearest_probe a q = nearest_probe_with (domain_scratch ()) a q

(* A ray's query through a probe of its own, and a scratch probe of its own, since such
   a query may run inside a fold's callback. *)
let ray_probe r tmin tmax =
  let q = Shape.probe () in
  Probe.of_ray q r;
  q.p_tmin <- tmin;
  q.p_tmax <- tmax;
  q

let nearest_into a r tmin tmax (h : Shape.hit) =
  let q = ray_probe r tmin tmax in
  let i = nearest_probe_in a q (Shape.probe ()) (Domain.DLS.get scratch_key).stack in
  h.t <- q.p_t;
  i

let nearest a r tmin tmax =
  let h = { Shape.tmin; tmax; t = Float.infinity } in
  let i = nearest_into a r tmin tmax h in
  (h.t, i)

(* Any crossing at all, opaque or not: where the first surface met settles the answer.
   The shadow query's walk, every primitive counting. *)
let any_hit a r tmin tmax =
  occluder ~any:true a (ray_probe r tmin tmax) (Shape.probe ())
    (Domain.DLS.get scratch_key).stack
  >= 0

(* [fold_transparent_hits] for a ray held in a probe: the same transparent primitives in
   the same order (the unbounded ones first, then depth first over the boxes the ray
   meets), each one's crossings in increasing t, [visit p] called at each with the
   crossing's t in [q.p_t], until it answers true. The interval is read once, before the
   probe's moves with the crossings found. *)
let[@inline] crossings_probe p (q : Shape.probe) obj tmin tmax visit =
  q.p_tmin <- tmin;
  let t = ref (probe_test p q obj tmax) and stop = ref false in
  while (not !stop) && !t < tmax do
    stop := visit p;
    if not !stop then (
      q.p_tmin <- !t;
      t := probe_test p q obj tmax)
  done;
  !stop

let[@inline] visit_transparent p q obj tmin tmax visit =
  if p.Primitive.material.transparency = 0. then false
  else crossings_probe p q obj tmin tmax visit

let linear_transparent prims (q : Shape.probe) obj visit =
  let tmin = q.p_tmin and tmax = q.p_tmax in
  let stop = ref false and i = ref 0 in
  while (not !stop) && !i < Array.length prims do
    stop := visit_transparent (Array.unsafe_get prims !i) q obj tmin tmax visit;
    incr i
  done

let tree_transparent a tr (q : Shape.probe) obj stack visit =
  let tmin = q.p_tmin and tmax = q.p_tmax in
  let stop = ref false in
  let outside = a.outside in
  let k = ref 0 in
  while (not !stop) && !k < Array.length outside do
    stop := visit_transparent a.prims.(outside.(!k)) q obj tmin tmax visit;
    incr k
  done;
  if not !stop then (
    let nodes = tr.nodes in
    let st = Bvh.take stack tr.depth in
    (* The interval as it was: the visits move the probe's with the crossings found. *)
    (try
       let node =
         ref (if Bvh.start nodes q st tmin tmax then Bvh.next_leaf nodes q st else -1)
       in
       while !node >= 0 do
         let first = Bvh.link nodes !node in
         let j = ref first in
         while (not !stop) && !j < first + Bvh.count nodes !node do
           stop :=
             visit_transparent (Array.unsafe_get tr.leaf_prims !j) q obj tmin tmax visit;
           incr j
         done;
         node := if !stop then -1 else Bvh.next_leaf nodes q st
       done
     with e ->
       st.busy <- false;
       raise e);
    st.busy <- false)

let rec transparent_in a (q : Shape.probe) obj stack visit =
  match a.layers with
  | Some l ->
      (* The fixed part's crossings, then the moving part's (see {!layered}). *)
      let tmin = q.p_tmin and tmax = q.p_tmax in
      let stopped = ref false in
      let visit p =
        let stop = visit p in
        if stop then stopped := true;
        stop
      in
      transparent_in l.fixed q obj stack visit;
      if not !stopped then (
        q.p_tmin <- tmin;
        q.p_tmax <- tmax;
        transparent_in l.moving q obj stack visit)
  | None -> (
      match a.tree with
      | None -> linear_transparent a.prims q obj visit
      | Some tr -> tree_transparent a tr q obj stack visit)

let transparent_crossings_with sc a (q : Shape.probe) visit =
  Probe.set_inv_dir q;
  seen sc q q.p_tmin q.p_tmax;
  transparent_in a q sc.obj sc.stack visit

let transparent_crossings a q visit =
  transparent_crossings_with (domain_scratch ()) a q visit

let occluded_with sc a (q : Shape.probe) ~slot =
  seen sc q q.p_tmin q.p_tmax;
  let obj = sc.obj in
  q.ix <- 1. /. q.dx;
  q.iy <- 1. /. q.dy;
  q.iz <- 1. /. q.dz;
  if slot >= Array.length sc.last then (
    let last = Array.make (slot + 1) (-1) in
    Array.blit sc.last 0 last 0 (Array.length sc.last);
    sc.last <- last);
  let prims = a.prims in
  let c = Array.unsafe_get sc.last slot in
  if
    c >= 0 && c < Array.length prims && blocks ~any:false (Array.unsafe_get prims c) q obj
  then true
  else
    let found = occluder ~any:false a q obj sc.stack in
    if found >= 0 then Array.unsafe_set sc.last slot found;
    found >= 0

let occluded a q ~slot = occluded_with (domain_scratch ()) a q ~slot

(* --- Two parts ------------------------------------------------------------------------ *)

let layered prims ~fixed ~fixed_idx ~moving ~moving_idx =
  let n = Array.length prims in
  if Array.length fixed_idx + Array.length moving_idx <> n then
    invalid_arg "Accel.layered: the parts do not cover the primitives";
  (* The parts counted their bounded primitives when they were built: nothing here is
     proportional to the fixed part, which a frame of an animation does not change. *)
  let weight = fixed.weight + moving.weight in
  {
    prims;
    weight;
    outside = [||];
    planes = Float.Array.create 0;
    tree = None;
    layers = Some { fixed; fixed_idx; moving; moving_idx; bvh = weight >= min_bvh };
  }

let moving_bounds accels =
  let u =
    Float.Array.of_list
      [ infinity; infinity; infinity; neg_infinity; neg_infinity; neg_infinity ]
  in
  let b = Float.Array.create 6 in
  let exception Unbounded in
  let add p =
    Primitive.bounds_into p b 0;
    for k = 0 to 5 do
      if not (Float.is_finite (fget b k)) then raise Unbounded
    done;
    for k = 0 to 2 do
      fset u k (Float.min (fget u k) (fget b k));
      fset u (k + 3) (Float.max (fget u (k + 3)) (fget b (k + 3)))
    done
  in
  match
    List.iter
      (fun a ->
        match a.layers with
        | None -> raise Unbounded
        | Some l -> Array.iter add l.moving.prims)
      accels
  with
  | exception Unbounded -> None
  | () ->
      (* Padded by a millionth of its magnitude: {!meets} then errs towards met. *)
      let m = ref 0. in
      Float.Array.iter
        (fun v -> if Float.is_finite v then m := Float.max !m (Float.abs v))
        u;
      let e = (1e-6 *. !m) +. 1e-9 in
      for k = 0 to 2 do
        fset u k (fget u k -. e);
        fset u (k + 3) (fget u (k + 3) +. e)
      done;
      Some u
