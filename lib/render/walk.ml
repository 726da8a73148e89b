(* The one walk of a bounding volume hierarchy, and the tests of what its leaves hold.

   A hierarchy here is a Bvh tree (possibly none) over slots, with a count [first] of slots
   tested in order before the tree (a scene's unbounded objects, or every slot when there
   is no tree), and [ids] giving each slot's item: a scene index, or a triangle. Its
   leaves are of one of two kinds: the triangles of a mesh, or a scene's placed objects
   ([items]: spheres read from a float array in a tree's slots, planes and spheres read
   from their shape, other simple shapes through their primitive, meshes and CSG objects
   asked in turn). Each of the three queries (the nearest root, any root, every crossing)
   is written once, over the slots before the tree and then each leaf that Bvh's one
   descent reaches, and tests a slot by its kind; the item tests are shared with the
   scans of a small scene's slots, which has no tree. A leaf of a scene's objects is
   first sifted by {!sphere_candidates} (in C, two spheres at a time): the nearest and
   the any-hit queries test only the slots it leaves, the others' spheres being missed
   by the ray's line, for certain, by the sphere test's own early miss.

   The leaf kind is a constant that the compiler specialises each query by where it is
   inlined, not a functor's argument: lancer is compiled without flambda, where a
   functor's or a first-class module's functions are called through [caml_applyN], their
   float arguments boxed; a test per slot so called cost the 100 000-sphere field 0.7 %
   more instructions in the nearest walk alone (cachegrind), and a glass scene 1 %.

   A query runs on a [level] of the domain's scratch (its stack, probes and buffers); the
   queries of a mesh item or a CSG object that it makes run on the next level, and so on.
   A query that an exception leaves (a cancellation polled in a CSG object's test,
   Task.spend) leaves nothing to undo. Floats go from one function to the next in the
   levels' probes, a float argument of a call that is not inlined being boxed. *)

let fget = Float.Array.unsafe_get
let fset = Float.Array.unsafe_set

(* --- Crossings ------------------------------------------------------------------------ *)

(* A merge sort's other half. *)
type sorter = { mutable tmp_ts : Float.Array.t; mutable tmp_parts : int array }

type crossings = {
  mutable ts : Float.Array.t;
  mutable parts : int array;  (** 3 per crossing: item, leaf, face *)
  mutable n : int;
  sorter : sorter;
}

let crossings () =
  {
    ts = Float.Array.create 16;
    parts = Array.make 48 0;
    n = 0;
    sorter = { tmp_ts = Float.Array.create 0; tmp_parts = [||] };
  }

let[@inline never] grow (c : crossings) =
  let m = 2 * Float.Array.length c.ts in
  let ts = Float.Array.create m and parts = Array.make (3 * m) 0 in
  Float.Array.blit c.ts 0 ts 0 c.n;
  Array.blit c.parts 0 parts 0 (3 * c.n);
  c.ts <- ts;
  c.parts <- parts

let[@inline] push (c : crossings) t item leaf face =
  let n = c.n in
  if n >= Float.Array.length c.ts then grow c;
  fset c.ts n t;
  let k = 3 * n in
  Array.unsafe_set c.parts k item;
  Array.unsafe_set c.parts (k + 1) leaf;
  Array.unsafe_set c.parts (k + 2) face;
  c.n <- n + 1

let clear (c : crossings) = c.n <- 0

let remap (c : crossings) from (idx : int array) =
  for k = from to c.n - 1 do
    c.parts.(3 * k) <- idx.(c.parts.(3 * k))
  done

(* Entry [i] of ([ts], [ps]) before entry [j] of ([us], [qs]): by t, then item, leaf and
   face. Roots are never NaN. *)
let[@inline] before ts ps i us qs j =
  let a = fget ts i and b = fget us j in
  a < b
  || a = b
     &&
     let k = 3 * i and l = 3 * j in
     let x = Array.unsafe_get ps k and y = Array.unsafe_get qs l in
     x < y
     || x = y
        &&
        let x = Array.unsafe_get ps (k + 1) and y = Array.unsafe_get qs (l + 1) in
        x < y || (x = y && Array.unsafe_get ps (k + 2) < Array.unsafe_get qs (l + 2))

let[@inline] move ts ps i us qs j =
  fset us j (fget ts i);
  let k = 3 * i and l = 3 * j in
  Array.unsafe_set qs l (Array.unsafe_get ps k);
  Array.unsafe_set qs (l + 1) (Array.unsafe_get ps (k + 1));
  Array.unsafe_set qs (l + 2) (Array.unsafe_get ps (k + 2))

(* Entries [from, n) by insertion: few crossings, nearly in order. Each entry moves down
   past the entries after it in the order. *)
let insertion (c : crossings) from =
  let ts = c.ts and ps = c.parts in
  for i = from + 1 to c.n - 1 do
    let j = ref i in
    while !j > from && before ts ps !j ts ps (!j - 1) do
      let a = !j - 1 and b = !j in
      let t = fget ts a in
      fset ts a (fget ts b);
      fset ts b t;
      for d = 0 to 2 do
        let x = Array.unsafe_get ps ((3 * a) + d) in
        Array.unsafe_set ps ((3 * a) + d) (Array.unsafe_get ps ((3 * b) + d));
        Array.unsafe_set ps ((3 * b) + d) x
      done;
      decr j
    done
  done

(* Entries [from, n) by a bottom-up merge sort through the buffer's other half. *)
let merge_sort (c : crossings) from =
  let n = c.n - from in
  let o = c.sorter in
  if Float.Array.length o.tmp_ts < c.n then (
    o.tmp_ts <- Float.Array.create (Float.Array.length c.ts);
    o.tmp_parts <- Array.make (Array.length c.parts) 0);
  let src_ts = ref c.ts and src_ps = ref c.parts in
  let dst_ts = ref o.tmp_ts and dst_ps = ref o.tmp_parts in
  let w = ref 1 in
  while !w < n do
    let lo = ref 0 in
    while !lo < n do
      let mid = min n (!lo + !w) and hi = min n (!lo + (2 * !w)) in
      let i = ref !lo and j = ref mid and k = ref !lo in
      while !k < hi do
        if
          !j >= hi
          || !i < mid
             && not (before !src_ts !src_ps (from + !j) !src_ts !src_ps (from + !i))
        then (
          move !src_ts !src_ps (from + !i) !dst_ts !dst_ps (from + !k);
          incr i)
        else (
          move !src_ts !src_ps (from + !j) !dst_ts !dst_ps (from + !k);
          incr j);
        incr k
      done;
      lo := hi
    done;
    let t = !src_ts and p = !src_ps in
    src_ts := !dst_ts;
    src_ps := !dst_ps;
    dst_ts := t;
    dst_ps := p;
    w := 2 * !w
  done;
  if !src_ts != c.ts then (
    Float.Array.blit !src_ts from c.ts from n;
    Array.blit !src_ps (3 * from) c.parts (3 * from) (3 * n))

let sort_from (c : crossings) from =
  let n = c.n - from in
  if n >= 2 then if n <= 32 then insertion c from else merge_sort c from

let sort c = sort_from c 0

(* A simple member's roots are at most this many (Shape.roots); a shape has few, and this
   bound only guards against a surface that would never stop. *)
let max_roots = 64

(* --- Levels ---------------------------------------------------------------------------- *)

(* What one query holds while it runs: its stack, the object-space probe of the items it
   tests, a CSG object's member probe, the point where its inside is tested and that
   point in a member's space, a solid mesh's parity probe, two buffers, the CSG member
   states, the part of the last mesh or CSG object it tested, and the level of the
   queries it makes in turn (made when first needed). Floats go from one function to the
   next in these probes: a float argument of a call that is not inlined is boxed. *)
type level = {
  stack : Bvh.walk;
  obj : Probe.t;
  mq : Probe.t;
  pt : Probe.t;
  mp : Probe.t;
  pq : Probe.t;
  buf : crossings;
  aux : crossings;
  mutable states : int array;
  rs : Float.Array.t;  (** a simple member's roots *)
  box : Float.Array.t;  (** an object's box *)
  mutable leaf : int;
  mutable face : int;  (** the part of the nearest item's root, once a query returns *)
  mutable cand_leaf : int;
  mutable cand_face : int;  (** the part of the last mesh or CSG object tested *)
  mutable deeper : level option;
}

type scratch = level
type hit = { mutable item : int; mutable leaf : int; mutable face : int }

let hit () = { item = -1; leaf = -1; face = -1 }

let new_level () =
  {
    stack = Bvh.new_walk ();
    obj = Probe.create ();
    mq = Probe.create ();
    pt = Probe.create ();
    mp = Probe.create ();
    pq = Probe.create ();
    buf = crossings ();
    aux = crossings ();
    states = [||];
    rs = Float.Array.create max_roots;
    box = Float.Array.create 6;
    leaf = -1;
    face = -1;
    cand_leaf = -1;
    cand_face = -1;
    deeper = None;
  }

let scratch = new_level
let scratch_key = Domain.DLS.new_key new_level
let domain_scratch () = Domain.DLS.get scratch_key

let[@inline never] new_deeper lv =
  let d = new_level () in
  lv.deeper <- Some d;
  d

(* The level of a query made inside one of [lv]'s. *)
let[@inline] deeper lv = match lv.deeper with Some d -> d | None -> new_deeper lv

(* A query tests the slots before the tree, [0, first), in order, then each leaf's as the
   descent reaches them. [next_leaf] gives the next leaf: −1 when none is left; [at] is
   the leaf the query last tested, −2 for the slots before the tree, after which the
   walk of the tree begins, within [tmin, bound] where there is one; [bound] is a nearest
   walk's best t. [range_first] and [range_count] say which slots [at] holds. *)
let[@inline] next_leaf lv at nodes depth (q : Probe.t) tmin bound =
  let st = lv.stack in
  if at >= 0 then (
    fset st.span 1 bound;
    Bvh.next_leaf nodes q st)
  else if Float.Array.length nodes > 0 then (
    Bvh.ready st depth;
    Bvh.start nodes q st tmin bound)
  else -1

(* The slots of [at]: leaf [at]'s from its first, or the slots before the tree for −2. *)
let[@inline] range_first nodes first at = if at < 0 then 0 else first + Bvh.link nodes at
let[@inline] range_count nodes first at = if at < 0 then first else Bvh.count nodes at

(* --- Items --------------------------------------------------------------------------- *)

type items = {
  prims : Primitive.t array;
  flat : Float.Array.t;
  kind : Bytes.t;
  parts : bool;  (** whether a slot holds a mesh or a CSG object *)
  spheres : bool;  (** whether a slot holds a sphere read from [flat] *)
  boxes : Float.Array.t;
      (** where [parts]: 6 per slot, a mesh's or a CSG object's world box (min x y z, max
          x y z), padded as the tree's are (Bvh.pad_into); infinite for an unbounded one
      *)
  cull : Float.Array.t;
      (** for at most [mask_slots] slots: each one's world bounds, 6 per slot (NaN for an
          unbounded one), what {!shadow_mask} reads; empty otherwise *)
}

(* The most slots a mask of shadow_mask has a bit for: one per bit of an int but its
   sign. *)
let mask_slots = Sys.int_size - 1

(* A slot's kind: how it is tested, plus [see_through] for a transparent material, which
   the shadow queries read without the primitive, and [moved] for a transformed one. *)
let simple = 0
let sphere = 1
let plane = 2
let composite = 3
let see_through = 4
let moved = 8

let kind_of (p : Primitive.t) =
  let fixed = Transform.is_identity p.transform in
  (if p.material.transparency <> 0. then see_through else 0)
  + (if fixed then 0 else moved)
  +
  match p.shape with
  | Shape.Sphere _ when fixed -> sphere
  | Shape.Plane _ when fixed -> plane
  | Shape.Mesh _ | Shape.Csg _ -> composite
  | _ -> simple

let items ?flat prims =
  let n = Array.length prims in
  let flat =
    match flat with
    | Some f when Float.Array.length f >= 4 * n -> f
    | _ -> Float.Array.create (4 * n)
  in
  let kind = Bytes.create n and parts = ref false and spheres = ref false in
  for j = 0 to n - 1 do
    let p = Array.unsafe_get prims j in
    let k = kind_of p in
    Bytes.unsafe_set kind j (Char.unsafe_chr k);
    if k land 3 = composite then parts := true;
    let o = 4 * j in
    match p.shape with
    | Shape.Sphere { center; radius } when k land 3 = sphere ->
        spheres := true;
        fset flat o center.x;
        fset flat (o + 1) center.y;
        fset flat (o + 2) center.z;
        fset flat (o + 3) radius
    | _ -> Float.Array.fill flat o 4 Float.nan
  done;
  let cull = Float.Array.make (if n <= mask_slots then 6 * n else 0) Float.nan in
  if n <= mask_slots then
    Array.iteri (fun j p -> Primitive.bounds_into p cull (6 * j)) prims;
  let boxes = Float.Array.make (if !parts then 6 * n else 0) Float.nan in
  if !parts then
    Array.iteri
      (fun j (p : Primitive.t) ->
        if Char.code (Bytes.get kind j) land 3 = composite then (
          Primitive.bounds_into p boxes (6 * j);
          let g k = Float.Array.get boxes ((6 * j) + k) in
          if Float.is_nan (g 0) then
            for k = 0 to 5 do
              Float.Array.set boxes
                ((6 * j) + k)
                (if k < 3 then Float.neg_infinity else Float.infinity)
            done
          else Bvh.pad_into boxes j (g 0) (g 1) (g 2) (g 3) (g 4) (g 5)))
      prims;
  { prims; flat; kind; parts = !parts; spheres = !spheres; boxes; cull }

let no_items =
  {
    prims = [||];
    flat = Float.Array.create 0;
    kind = Bytes.empty;
    parts = false;
    spheres = false;
    boxes = Float.Array.create 0;
    cull = Float.Array.create 0;
  }

(* Whether [q]'s ray meets, within [tmin, tmax], the box at [6 * j] of [b]: each slab's
   near and far planes chosen by the sign of the reciprocal direction, as the hierarchy's
   descent does (a NaN from 0·∞, an origin on a slab plane with the ray along it, leaves the
   interval open). *)
let[@inline] box_met b j (q : Probe.t) tmin tmax =
  let o = 6 * j in
  let ix = q.ix and iy = q.iy and iz = q.iz in
  let n = if ix < 0. then o + 3 else o in
  let t0 = (fget b n -. q.ox) *. ix and t1 = (fget b ((2 * o) + 3 - n) -. q.ox) *. ix in
  let t0 = if t0 > tmin then t0 else tmin and t1 = if t1 < tmax then t1 else tmax in
  let n = if iy < 0. then o + 4 else o + 1 in
  let a = (fget b n -. q.oy) *. iy and c = (fget b ((2 * o) + 5 - n) -. q.oy) *. iy in
  let t0 = if a > t0 then a else t0 and t1 = if c < t1 then c else t1 in
  let n = if iz < 0. then o + 5 else o + 2 in
  let a = (fget b n -. q.oz) *. iz and c = (fget b ((2 * o) + 7 - n) -. q.oz) *. iz in
  let t0 = if a > t0 then a else t0 and t1 = if c < t1 then c else t1 in
  t0 <= t1

let no_mesh =
  Trimesh.make ~pos:(Float.Array.create 0) ~nrm:(Float.Array.create 0)
    ~tex:(Float.Array.create 0) ~tv:Trimesh.no_ints ~tn:Trimesh.no_ints
    ~tt:Trimesh.no_ints ()

type index = {
  nodes : Float.Array.t;
  depth : int;
  ids : int array;
  first : int;
  items : items;
}

(* [q]'s ray in [p]'s object space: [q] itself where [p] is not transformed. *)
let[@inline] object_of lv (p : Primitive.t) (q : Probe.t) =
  if Transform.is_identity p.transform then q
  else (
    Primitive.object_probe p q lv.obj;
    lv.obj)

(* Slot [j]'s root on its sphere, in (tmin, tmax): read from the flat floats in a tree's
   slots (visited by the thousand, close together), from its shape otherwise (a few
   objects, their records at hand). *)
let[@inline] sphere_root ~tree flat prims j (q : Probe.t) tmin tmax =
  if tree then
    let o = 4 * j in
    Shape.sphere_sc (fget flat o)
      (fget flat (o + 1))
      (fget flat (o + 2))
      (fget flat (o + 3))
      q.ox q.oy q.oz q.dx q.dy q.dz tmin tmax
  else
    match (Array.unsafe_get prims j : Primitive.t).shape with
    | Shape.Sphere { center; radius } ->
        Shape.sphere_sc center.x center.y center.z radius q.ox q.oy q.oz q.dx q.dy q.dz
          tmin tmax
    | _ -> Float.infinity

(* Slot [j]'s root on its plane, in (tmin, tmax). *)
let[@inline] plane_root prims j (q : Probe.t) tmin tmax =
  match (Array.unsafe_get prims j : Primitive.t).shape with
  | Shape.Plane { normal; offset } ->
      Shape.plane_sc normal.x normal.y normal.z offset q.ox q.oy q.oz q.dx q.dy q.dz tmin
        tmax
  | _ -> Float.infinity

(* Slot [j]'s nearest root in (tmin, tmax) among [it]'s objects, [nested] testing a mesh
   or a CSG object (whose part it leaves in [lv.cand_leaf] and [lv.cand_face]). *)
let[@inline] item_root ~tree ~nested (lv : level) (it : items) j (q : Probe.t) tmin tmax =
  let c = Char.code (Bytes.unsafe_get it.kind j) in
  let k = c land 3 in
  if k = sphere then sphere_root ~tree it.flat it.prims j q tmin tmax
  else if k = plane then plane_root it.prims j q tmin tmax
  else (
    q.p_tmax <- tmax;
    let p = Array.unsafe_get it.prims j in
    if k = composite then
      if box_met it.boxes j q tmin tmax then nested lv p q else q.p_t <- Float.infinity
    else if c land moved = 0 then Shape.root p.shape q
    else Primitive.root p q lv.obj;
    q.p_t)

(* The slots [lo, lo + n) of a leaf whose sphere the probe's ray may meet, as a mask (bit
   k for slot lo + k, n ≤ {!filtered}): in C ([spheres_stubs.c], which says why), each
   slot's sphere tested as far as {!Shape.sphere_gen}'s early miss, by the same
   operations, two at a time. A slot without a sphere (NaN in [flat]) is always in it. *)
external sphere_candidates :
  Float.Array.t -> (int[@untagged]) -> (int[@untagged]) -> Probe.t -> (int[@untagged])
  = "lancer_sphere_candidates_byte" "lancer_sphere_candidates"
[@@noalloc]

(* The most slots {!sphere_candidates} takes: a bit each in an int but its sign. *)
let filtered = Sys.int_size - 1

(* Which of the slots [lo, lo + n) of leaf [at] may hold a root: [sphere_candidates]'s
   mask for a leaf of items of more than one slot where some slot holds a sphere; −1
   (all) for the slots before the tree, a mesh's triangles, a leaf of one slot (whose
   test takes the same early miss itself) or one too large. *)
let[@inline] candidates ~tris (it : items) at lo n (q : Probe.t) =
  if tris then -1
  else if at >= 0 && n > 1 && n <= filtered && it.spheres then
    sphere_candidates it.flat lo n q
  else -1

(* Whether slot [lo + k] is in mask [m]. *)
let[@inline] candidate m k = m = -1 || (m lsr k) land 1 = 1

(* The part of slot [j]'s root, the nearest found so far, into [lv.leaf] and [lv.face]. *)
let[@inline] keep_part (lv : level) (it : items) j =
  if Char.code (Bytes.unsafe_get it.kind j) land 3 = composite then (
    lv.leaf <- lv.cand_leaf;
    lv.face <- lv.cand_face)
  else (
    lv.leaf <- -1;
    lv.face <- -1)

(* Whether slot [j]'s object crosses (tmin, tmax), but for one of kind [skip]. *)
let[@inline] item_hits ~tree ~nested (lv : level) (it : items) j (q : Probe.t) tmin tmax
    skip =
  let c = Char.code (Bytes.unsafe_get it.kind j) in
  c land skip = 0
  &&
  let k = c land 3 in
  if k = sphere then sphere_root ~tree it.flat it.prims j q tmin tmax < tmax
  else if k = plane then plane_root it.prims j q tmin tmax < tmax
  else
    let p = Array.unsafe_get it.prims j in
    q.p_tmin <- tmin;
    q.p_tmax <- tmax;
    if k = composite then box_met it.boxes j q tmin tmax && nested lv p q
    else (
      if c land moved = 0 then Shape.root p.shape q else Primitive.root p q lv.obj;
      q.p_t < tmax)

(* Every crossing of slot [j]'s object (scene index [id]) in (tmin, tmax) into [out], where
   its kind has [want]. *)
let[@inline] item_crossings ~tree ~nested (lv : level) (it : items) j id (q : Probe.t)
    tmin tmax want out =
  let c = Char.code (Bytes.unsafe_get it.kind j) in
  if c land want = want then
    let k = c land 3 and p = Array.unsafe_get it.prims j in
    if k = composite then (
      if box_met it.boxes j q tmin tmax then (
        q.p_tmin <- tmin;
        q.p_tmax <- tmax;
        nested lv p q out id))
    else
      (* Each root in turn, from the last one: roots are computed the same whatever the
         interval, so the strict bound never returns one twice. *)
      let from = ref tmin and more = ref true in
      while !more do
        let t =
          if k = sphere then sphere_root ~tree it.flat it.prims j q !from tmax
          else if k = plane then plane_root it.prims j q !from tmax
          else (
            q.p_tmin <- !from;
            q.p_tmax <- tmax;
            if c land moved = 0 then Shape.root p.shape q else Primitive.root p q lv.obj;
            q.p_t)
        in
        if t < tmax then (
          push out t id (-1) (-1);
          from := t)
        else more := false
      done

(* --- The three queries ------------------------------------------------------------------ *)

(* Each query is written once, as a body that [~tris] specialises where it is inlined (the
   compiler drops the branches it rules out): with [~tris:true] the slots are the
   triangles of mesh [m] (slot j holding triangle ids.(j)); with [~tris:false] they are
   [it]'s objects, and [nested] tests a mesh or a CSG object among them (a call through
   the closure: those are rare and cost far more than the call). The hierarchy is
   [nodes], [depth], [ids] and [first] as in {!index}; [lv] is the query's level. Each
   reads its interval from the probe at its start. *)

(* The nearest root in (q.p_tmin, q.p_tmax): the slot's id (−1: none), its t into
   [q.p_t], its part into [lv.leaf] and [lv.face] for items (both −1 but for a mesh's or
   a CSG object's, which [nested] leaves in [lv.cand_leaf] and [lv.cand_face]). The
   lexicographic minimum of (t, id): each slot is queried up to just past the best t
   (Floats.above), so that an equal t is seen and the id decides; a root beyond it that
   the bound lets through loses to the best; and a box is culled only when its entry is
   beyond the best t (Bvh.next_leaf). It moves [q.p_tmax]. *)
let[@inline] nearest ~tris ~nested (lv : level) (it : items) m nodes depth
    (ids : int array) first (q : Probe.t) =
  let tmin = q.p_tmin in
  let best_t = ref q.p_tmax and best_i = ref (-1) and query = ref q.p_tmax in
  if not tris then (
    lv.leaf <- -1;
    lv.face <- -1);
  let at = ref (-2) in
  while !at <> -1 do
    let lo = range_first nodes first !at and n = range_count nodes first !at in
    let c = candidates ~tris it !at lo n q in
    for j = lo to lo + n - 1 do
      if tris || candidate c (j - lo) then
        let t =
          if tris then Trimesh.root m (Array.unsafe_get ids j) q !query
          else item_root ~tree:true ~nested lv it j q tmin !query
        in
        if t <= !best_t then
          let i = Array.unsafe_get ids j in
          if t < !best_t || i < !best_i then (
            best_t := t;
            best_i := i;
            query := Floats.above t;
            if (not tris) && it.parts then keep_part lv it j)
    done;
    at := next_leaf lv !at nodes depth q tmin !best_t
  done;
  q.p_t <- (if !best_i < 0 then Float.infinity else !best_t);
  !best_i

(* A slot whose item crosses (q.p_tmin, q.p_tmax), the first the walk meets (−1: none);
   with [opaque], items of a transparent material do not count. *)
let[@inline] any ~tris ~nested (lv : level) (it : items) m nodes depth (ids : int array)
    first (q : Probe.t) ~opaque =
  let tmin = q.p_tmin and tmax = q.p_tmax in
  let skip = if opaque then see_through else 0 in
  let found = ref (-1) and at = ref (-2) in
  while !at <> -1 do
    let lo = range_first nodes first !at and n = range_count nodes first !at in
    let c = candidates ~tris it !at lo n q in
    let j = ref lo and hi = ref (lo + n) in
    while !j < !hi do
      let s = !j in
      if
        (tris || candidate c (s - lo))
        &&
        if tris then Trimesh.root m (Array.unsafe_get ids s) q tmax < tmax
        else item_hits ~tree:true ~nested lv it s q tmin tmax skip
      then (
        found := s;
        hi := 0);
      incr j
    done;
    at := if !found < 0 then next_leaf lv !at nodes depth q tmin tmax else -1
  done;
  q.p_tmin <- tmin;
  q.p_tmax <- tmax;
  !found

(* Every crossing in (q.p_tmin, q.p_tmax), unordered (each item's in increasing t),
   pushed into [out]: an item's as (t, id, its leaf, its face), a triangle's as
   (t, [item], [leaf], the triangle). With [transparent], items of an opaque material are
   left out. How many slots were tested. *)
let[@inline] every ~tris ~nested (lv : level) (it : items) m nodes depth (ids : int array)
    first (q : Probe.t) ~transparent out item leaf =
  let tmin = q.p_tmin and tmax = q.p_tmax in
  let want = if transparent then see_through else 0 in
  let tested = ref 0 and at = ref (-2) in
  while !at <> -1 do
    let lo = range_first nodes first !at and n = range_count nodes first !at in
    tested := !tested + n;
    for j = lo to lo + n - 1 do
      if tris then (
        let k = Array.unsafe_get ids j in
        let t = Trimesh.root m k q tmax in
        if t < tmax then push out t item leaf k)
      else
        item_crossings ~tree:true ~nested lv it j (Array.unsafe_get ids j) q tmin tmax
          want out
    done;
    at := next_leaf lv !at nodes depth q tmin tmax
  done;
  q.p_tmin <- tmin;
  q.p_tmax <- tmax;
  !tested

(* The same three queries over the slots [0, n) of a scene's index without a tree, in
   order: the first of equal roots wins the nearest with the strict bound (the next slot
   is queried up to the best t itself), and the slots are the ids. *)
let[@inline] scan_nearest ~parts ~nested (lv : level) (it : items) n (q : Probe.t) =
  let tmin = q.p_tmin in
  let best_t = ref q.p_tmax and best_i = ref (-1) in
  if parts then (
    lv.leaf <- -1;
    lv.face <- -1);
  for j = 0 to n - 1 do
    let t = item_root ~tree:false ~nested lv it j q tmin !best_t in
    if t < !best_t then (
      best_t := t;
      best_i := j;
      if parts then keep_part lv it j)
  done;
  q.p_t <- (if !best_i < 0 then Float.infinity else !best_t);
  !best_i

let[@inline] scan_any ~nested (lv : level) (it : items) n (q : Probe.t) ~opaque ~mask =
  let tmin = q.p_tmin and tmax = q.p_tmax in
  let skip = if opaque then see_through else 0 in
  let found = ref (-1) and j = ref 0 in
  (if mask = -1 then
     while !found < 0 && !j < n do
       if item_hits ~tree:false ~nested lv it !j q tmin tmax skip then found := !j;
       incr j
     done
   else
     (* The mask's bits, lowest first, up to its highest: a slot above it costs nothing. *)
     let m = ref mask in
     while !found < 0 && !m <> 0 do
       if !m land 1 = 1 && item_hits ~tree:false ~nested lv it !j q tmin tmax skip then
         found := !j;
       m := !m lsr 1;
       incr j
     done);
  q.p_tmin <- tmin;
  q.p_tmax <- tmax;
  !found

let[@inline] scan_every ~nested (lv : level) (it : items) n (q : Probe.t) ~transparent out
    =
  let tmin = q.p_tmin and tmax = q.p_tmax in
  let want = if transparent then see_through else 0 in
  for j = 0 to n - 1 do
    item_crossings ~tree:false ~nested lv it j j q tmin tmax want out
  done;
  q.p_tmin <- tmin;
  q.p_tmax <- tmax

(* --- A mesh's hierarchy ---------------------------------------------------------------- *)

let mesh_nearest lv mesh (q : Probe.t) =
  nearest ~tris:true
    ~nested:(fun _ _ _ -> ())
    lv no_items mesh (Trimesh.nodes mesh) (Trimesh.depth mesh) (Trimesh.order mesh)
    (Trimesh.first mesh) q

let mesh_any lv mesh (q : Probe.t) =
  any ~tris:true
    ~nested:(fun _ _ _ -> false)
    lv no_items mesh (Trimesh.nodes mesh) (Trimesh.depth mesh) (Trimesh.order mesh)
    (Trimesh.first mesh) q ~opaque:false

let mesh_crossings lv mesh (q : Probe.t) out item leaf =
  every ~tris:true
    ~nested:(fun _ _ _ _ _ -> ())
    lv no_items mesh (Trimesh.nodes mesh) (Trimesh.depth mesh) (Trimesh.order mesh)
    (Trimesh.first mesh) q ~transparent:false out item leaf

(* Each distinct t of a mesh's crossings in [b] (sorted), with the lowest face crossed
   there: the crossings a nearest query asked again past each one would find. *)
let push_distinct (b : crossings) out item =
  for k = 0 to b.n - 1 do
    let t = fget b.ts k in
    if k = 0 || t <> fget b.ts (k - 1) then push out t item (-1) b.parts.((3 * k) + 2)
  done

(* --- CSG objects ------------------------------------------------------------------------ *)

(* A CSG member's state along a ray: tested at each gap, or followed from its own
   crossings, out or in. *)
let tested = -1
let followed_out = 0
let followed_in = 1

(* The member whose leaves include [leaf]: the last one whose first leaf is at most it. *)
let member_of (members : Shape.csg_member array) leaf =
  let lo = ref 0 and hi = ref (Array.length members) in
  while !hi - !lo > 1 do
    let mid = (!lo + !hi) / 2 in
    if members.(mid).first_leaf <= leaf then lo := mid else hi := mid
  done;
  !lo

(* A crossing of a followed member flips its state. *)
let pass (members : Shape.csg_member array) states leaf =
  let i = member_of members leaf in
  let st = states.(i) in
  if st <> tested then states.(i) <- followed_in - st

(* The tests of simple surfaces that a tested member's inside costs at one gap (a solid
   mesh's parity walk counts its own). *)
let inside_cost = function Shape.Csg { leaf_count; _ } -> max 1 leaf_count | _ -> 1

(* [q]'s ray in member [m]'s space, into [mq] (a copy where [m] is not transformed): as
   {!Ray.make_raw} would make it of the origin and direction {!Transform.inv_point} and
   {!Transform.inv_vector} give. *)
let member_probe (m : Shape.csg_member) (q : Probe.t) (mq : Probe.t) =
  if Transform.is_identity m.transform then (
    mq.ox <- q.ox;
    mq.oy <- q.oy;
    mq.oz <- q.oz;
    mq.dx <- q.dx;
    mq.dy <- q.dy;
    mq.dz <- q.dz;
    mq.ix <- q.ix;
    mq.iy <- q.iy;
    mq.iz <- q.iz)
  else Probe.inverse_into m.transform q mq

(* The point [pt] holds in member [m]'s space, into [mp] ([pt] itself where [m] is not
   transformed): {!Transform.inv_point}'s operations. *)
let[@inline] member_point (m : Shape.csg_member) (pt : Probe.t) (mp : Probe.t) =
  let tr = m.transform in
  if Transform.is_identity tr then pt
  else
    let x = pt.ox and y = pt.oy and z = pt.oz in
    mp.ox <- Transform.inv_px tr x y z;
    mp.oy <- Transform.inv_py tr x y z;
    mp.oz <- Transform.inv_pz tr x y z;
    mp

(* [q]'s ray at [t], {!Ray.at}'s operations, into [pt]'s origin. *)
let[@inline] set_point (pt : Probe.t) (q : Probe.t) t =
  pt.ox <- q.ox +. (t *. q.dx);
  pt.oy <- q.oy +. (t *. q.dy);
  pt.oz <- q.oz +. (t *. q.dz)

(* The parity ray of a solid mesh: from the point [pt] holds along a fixed direction that
   no axis-aligned feature lies along, over (0, ∞). *)
let parity_direction = Vec3.v 0.5773502691896258 0.5773502691896257 0.5773502691896259

let parity_probe (pq : Probe.t) (pt : Probe.t) =
  Probe.set_origin pq pt.ox pt.oy pt.oz;
  pq.dx <- parity_direction.x;
  pq.dy <- parity_direction.y;
  pq.dz <- parity_direction.z;
  Probe.set_inv_dir pq;
  pq.p_tmin <- 0.;
  pq.p_tmax <- Float.infinity

(* Whether member [i]'s inside costs little: followed, or a simple surface's test. *)
let[@inline] cheap (members : Shape.csg_member array) states i =
  Array.unsafe_get states i <> tested
  ||
  match (Array.unsafe_get members i).shape with
  | Shape.Mesh _ | Shape.Csg _ -> false
  | _ -> true

(* The crossings of CSG object [s]'s boundary along the ray [q] holds in (q.p_tmin,
   q.p_tmax), nearest first, pushed into [out] as (t, [item], [leaf0] + the leaf, the
   face); with [first], only the first. [lv] is the query's level. Every member's roots
   are merged in order; between two consecutive roots (and after the last) nothing
   changes, so the inside of the combined set is tested once per gap, at its middle, and a
   root where it changes is a crossing. The answer does not depend on tmin (only which
   roots are kept): the first gap's state is sampled within the same gap whatever tmin
   is. Roots are computed up to infinity; tmax only ends the list.

   A member that is itself a CSG object (but a union, whose list keeps every surface) is
   not tested again at each gap: its crossings are where its own state changes, so its
   state is followed along the ray from the one it had just after tmin, flipped at each
   of its crossings. Testing it would walk its whole tree at every gap of every level, and
   a difference nested n deep would cost n² tests per ray; followed, each level costs its
   gaps. The other members (surfaces, meshes, unions) are tested as the object's inside
   tests them; a mesh's roots and its parity come from the walk of its hierarchy. With
   [state], the result is the object's inside just after tmin (for the object it is a
   member of); otherwise [false]. Each surface's root sought and each gap count as the
   tests they make, for [w]. *)
let rec csg_crossings ?(rooted = false) lv w s (q : Probe.t) ~first ~state out item leaf0
    =
  match s with
  | Shape.Csg { op; members; _ } ->
      let tmin = q.p_tmin and tmax = q.p_tmax in
      let n = Array.length members in
      if Array.length lv.states < n then lv.states <- Array.make n tested;
      let states = lv.states in
      for i = 0 to n - 1 do
        Array.unsafe_set states i tested
      done;
      let ev = lv.buf in
      if not rooted then (
        ev.n <- 0;
        member_roots lv w members.(0) 0 q ev);
      if (not rooted) && outside_first lv w op members q ev tmax then false
      else (
        for i = 1 to n - 1 do
          member_roots lv w members.(i) i q ev
        done;
        let gap_cost = ref 1 and followed = ref false and costly = ref 0 in
        for i = 0 to n - 1 do
          if states.(i) = tested then (
            gap_cost := !gap_cost + inside_cost members.(i).shape;
            match members.(i).shape with
            | Shape.Mesh _ | Shape.Csg _ -> incr costly
            | _ -> ())
          else followed := true
        done;
        let gap_cost = !gap_cost and followed = !followed in
        let reorder = !costly > 0 && !costly < n in
        sort ev;
        let ne = ev.n and ts = ev.ts and ps = ev.parts and pt = lv.pt in
        if ne = 0 then
          state
          &&
          (Task.spend w gap_cost;
           set_point pt q (tmin +. Float.max 1. (Float.abs tmin));
           combined lv w op members states ~reorder)
        else if op = Shape.Union then (
          (* every member's surface, as a group *)
          let k = ref 0 in
          while !k < ne && fget ts !k < tmax && not (first && !k > 0) do
            push out (fget ts !k) item (leaf0 + ps.((3 * !k) + 1)) ps.((3 * !k) + 2);
            incr k
          done;
          false)
        else (
          Task.spend w gap_cost;
          set_point pt q (0.5 *. (tmin +. fget ts 0));
          let first_state = combined lv w op members states ~reorder in
          let before = ref first_state and k = ref 0 and stop = ref false in
          while (not !stop) && !k < ne do
            let t = fget ts !k in
            if t >= tmax then stop := true
            else
              let leaf = ps.((3 * !k) + 1) and face = ps.((3 * !k) + 2) in
              if followed then pass members states leaf;
              incr k;
              while !k < ne && fget ts !k = t do
                if followed then pass members states ps.((3 * !k) + 1);
                incr k
              done;
              Task.spend w gap_cost;
              set_point pt q
                (if !k < ne then 0.5 *. (t +. fget ts !k)
                 else t +. Float.max 1. (Float.abs t));
              let after = combined lv w op members states ~reorder in
              if after <> !before then (
                push out t item (leaf0 + leaf) face;
                before := after;
                if first then stop := true)
          done;
          first_state))
  | _ -> invalid_arg "Walk.csg_crossings: not a CSG object"

(* Whether an intersection or a difference, which lies inside its first member, has no
   crossing in (q.p_tmin, tmax) and is outside just after q.p_tmin, because that member,
   a simple surface whose roots [ev] holds in increasing order (and nothing else yet),
   has no root there and is outside: then the other members' roots are not sought. Its
   inside is tested between q.p_tmin and its first root, or beyond q.p_tmin when it has
   none; where its inside test agrees with its roots (its state does not change between
   two roots), that is the state the whole list's gaps before that root would see. *)
and outside_first lv w op (members : Shape.csg_member array) (q : Probe.t) ev tmax =
  match op with
  | Shape.Union | Shape.Merge -> false
  | Shape.Intersection | Shape.Difference -> (
      match (Array.unsafe_get members 0).shape with
      | Shape.Mesh _ | Shape.Csg _ -> false
      | _ ->
          let tmin = q.p_tmin in
          (ev.n = 0 || fget ev.ts 0 >= tmax)
          &&
          let pt = lv.pt in
          set_point pt q
            (if ev.n = 0 then tmin +. Float.max 1. (Float.abs tmin)
             else 0.5 *. (tmin +. fget ev.ts 0));
          Task.spend w 1;
          not (member_at lv w members 0 pt))

(* Every root of member [m] (number [i]) after q.p_tmin into [ev], as (t, 0, its leaf,
   its face); each surface's root sought is one unit of work for [w]. For a CSG member
   followed along the ray, its state just after q.p_tmin goes into [lv.states.(i)]. *)
and member_roots lv w (m : Shape.csg_member) i (q : Probe.t) ev =
  let mq = lv.mq in
  member_probe m q mq;
  mq.p_tmin <- q.p_tmin;
  mq.p_tmax <- Float.infinity;
  match m.shape with
  | Shape.Mesh { mesh; _ } ->
      Task.spend w (1 + mesh_crossings (deeper lv) mesh mq ev 0 m.first_leaf)
  | Shape.Csg { op; _ } ->
      let followed = op <> Shape.Union in
      let st =
        csg_crossings (deeper lv) w m.shape mq ~first:false ~state:followed ev 0
          m.first_leaf
      in
      if followed then lv.states.(i) <- (if st then followed_in else followed_out)
  | s ->
      let rs = lv.rs in
      let n = Shape.roots s mq rs in
      Task.spend w (n + 1);
      for k = 0 to n - 1 do
        push ev (Float.Array.unsafe_get rs k) 0 m.first_leaf (-1)
      done

(* The inside of a CSG object at the point [lv.pt] holds (in its space), each member's
   inside its followed state or its own test. The members that decide the answer alone (in
   a union, one inside; in an intersection, one outside; in a difference, the first
   outside or another inside) are sought among the cheap ones first (followed, or simple
   surfaces), and only then, with [reorder], among the meshes and CSG objects that must be
   tested: the answer is the same whatever the order. *)
and combined lv w op (members : Shape.csg_member array) states ~reorder =
  let n = Array.length members in
  if reorder then (
    let union = match op with Shape.Union | Shape.Merge -> true | _ -> false
    and diff = match op with Shape.Difference -> true | _ -> false in
    let decided = ref false and i = ref 0 in
    for pass = 0 to 1 do
      i := 0;
      while (not !decided) && !i < n do
        let k = !i in
        if cheap members states k = (pass = 0) then
          decided := member_inside lv w members states k = (union || (diff && k > 0));
        incr i
      done
    done;
    if !decided then union else not union)
  else
    match op with
    | Shape.Union | Shape.Merge ->
        let r = ref false and i = ref 0 in
        while (not !r) && !i < n do
          r := member_inside lv w members states !i;
          incr i
        done;
        !r
    | Shape.Intersection ->
        let r = ref true and i = ref 0 in
        while !r && !i < n do
          r := member_inside lv w members states !i;
          incr i
        done;
        !r
    | Shape.Difference ->
        member_inside lv w members states 0
        &&
        let r = ref true and i = ref 1 in
        while !r && !i < n do
          r := not (member_inside lv w members states !i);
          incr i
        done;
        !r

and member_inside lv w (members : Shape.csg_member array) states i =
  let st = Array.unsafe_get states i in
  if st <> tested then st = followed_in
  else
    let m = Array.unsafe_get members i in
    inside_at (deeper lv) w m.shape (member_point m lv.pt lv.mp)

(* Whether the point [pt] holds is inside solid [s]: a solid mesh by the parity of its
   crossings along a fixed direction, through the walk of its hierarchy; a CSG object by
   its members' (each tested). [lv] is free for it. *)
and inside_at lv w s (pt : Probe.t) =
  match s with
  | Shape.Mesh { mesh; solid = true } ->
      parity_probe lv.pq pt;
      let b = lv.aux in
      b.n <- 0;
      Task.spend w (mesh_crossings (deeper lv) mesh lv.pq b 0 0);
      b.n land 1 = 1
  | Shape.Csg { op; members; _ } -> (
      let n = Array.length members in
      match op with
      | Shape.Union | Shape.Merge ->
          let r = ref false and i = ref 0 in
          while (not !r) && !i < n do
            r := member_at lv w members !i pt;
            incr i
          done;
          !r
      | Shape.Intersection ->
          let r = ref true and i = ref 0 in
          while !r && !i < n do
            r := member_at lv w members !i pt;
            incr i
          done;
          !r
      | Shape.Difference ->
          member_at lv w members 0 pt
          &&
          let r = ref true and i = ref 1 in
          while !r && !i < n do
            r := not (member_at lv w members !i pt);
            incr i
          done;
          !r)
  | s -> Shape.inside_probe s pt

(* Whether the point [pt] holds (in the CSG object's space) is inside member [i]. *)
and member_at lv w (members : Shape.csg_member array) i pt =
  let m = Array.unsafe_get members i in
  inside_at (deeper lv) w m.shape (member_point m pt lv.mp)

(* The first crossing of CSG object [s] in (q.p_tmin, q.p_tmax): its t into [q.p_t]
   (infinity for none), its part into [lv.cand_leaf] and [lv.cand_face]. With [rooted],
   the next level's buffer already holds its first member's roots along [q], and
   [outside_first] did not decide ([csg_any]). *)
let csg_first ?rooted lv s (q : Probe.t) =
  let b = lv.buf in
  b.n <- 0;
  ignore
    (csg_crossings ?rooted (deeper lv) (Task.current ()) s q ~first:true ~state:false b 0
       0);
  if b.n > 0 then (
    q.p_t <- fget b.ts 0;
    lv.cand_leaf <- b.parts.(1);
    lv.cand_face <- b.parts.(2))
  else q.p_t <- Float.infinity

(* Whether point [pt] (in the CSG object's space) is inside member [m], a simple surface:
   {!member_at}'s answer, without its dispatch. *)
let[@inline] simple_at lv (m : Shape.csg_member) pt =
  Shape.inside_probe m.shape (member_point m pt lv.mp)

(* Whether CSG object [s] crosses (q.p_tmin, q.p_tmax), as [csg_first] answers it. A
   difference of simple surfaces is first tried from its first member's roots alone.
   Where that member has no root in the interval and the ray is outside it, so is the
   difference (as [outside_first] finds it). Where the ray enters it at its first root
   r0 < tmax, outside it before, and just past r0 (before its next root and tmax) is
   inside it and outside every other member, the difference is outside before r0 and
   inside there, so it is crossed at r0 or at another member's root just past it. Either
   way the other members' roots are not sought; any other case is [csg_first]'s. *)
let csg_any lv s (q : Probe.t) =
  let tmin = q.p_tmin and tmax = q.p_tmax in
  (* 0: not crossed, 1: crossed, 2: not known from the first member (whose roots the
     next level's buffer holds), 3: not tried. The first member's roots and each inside
     are those [member_roots] and [member_at] find; the work is bounded, the shadow ray
     counts for it. *)
  let known =
    match s with
    | Shape.Csg { op = Shape.Difference; members; _ } when Array.length members >= 2 ->
        let simple = ref true in
        for i = 0 to Array.length members - 1 do
          match (Array.unsafe_get members i).shape with
          | Shape.Mesh _ | Shape.Csg _ -> simple := false
          | _ -> ()
        done;
        if not !simple then 3
        else
          let l = deeper lv in
          let m0 = Array.unsafe_get members 0 and mq = l.mq and rs = l.rs in
          member_probe m0 q mq;
          mq.p_tmin <- tmin;
          mq.p_tmax <- Float.infinity;
          (* One member's roots come in increasing order. *)
          let n = Shape.roots m0.shape mq rs in
          let pt = l.pt in
          let known =
            if n = 0 || fget rs 0 >= tmax then (
              set_point pt q
                (if n = 0 then tmin +. Float.max 1. (Float.abs tmin)
                 else 0.5 *. (tmin +. fget rs 0));
              if simple_at l m0 pt then 2 else 0)
            else
              let r0 = fget rs 0 in
              set_point pt q (0.5 *. (tmin +. r0));
              if simple_at l m0 pt then 2
              else
                let stop = if n > 1 && fget rs 1 < tmax then fget rs 1 else tmax in
                (* Near r0: the other members are met further in, if at all. *)
                let p =
                  if Float.is_finite stop then r0 +. ((stop -. r0) /. 64.)
                  else r0 +. ((if Float.abs r0 > 1. then Float.abs r0 else 1.) /. 64.)
                in
                set_point pt q p;
                if not (simple_at l m0 pt) then 2
                else
                  let out = ref true and i = ref 1 in
                  while !out && !i < Array.length members do
                    if simple_at l (Array.unsafe_get members !i) pt then out := false;
                    incr i
                  done;
                  if !out then 1 else 2
          in
          if known = 2 then (
            (* [csg_first ~rooted] reads them from the next level's buffer. *)
            let ev = l.buf in
            ev.n <- 0;
            for k = 0 to n - 1 do
              push ev (fget rs k) 0 m0.first_leaf (-1)
            done);
          known
    | _ -> 3
  in
  if known < 2 then known = 1
  else (
    q.p_tmin <- tmin;
    q.p_tmax <- tmax;
    (* The first member's roots are not sought again. *)
    if known = 2 then csg_first ~rooted:true lv s q else csg_first lv s q;
    q.p_t < q.p_tmax)

(* --- Meshes and CSG objects among a scene's objects -------------------------------------- *)

(* The nearest root of mesh or CSG object [p] in (q.p_tmin, q.p_tmax) into [q.p_t], its
   part into [lv.cand_leaf] and [lv.cand_face]. *)
let composite_root lv (p : Primitive.t) (q : Probe.t) =
  let o = object_of lv p q in
  (match p.shape with
  | Shape.Mesh { mesh; _ } ->
      let k = mesh_nearest (deeper lv) mesh o in
      lv.cand_leaf <- -1;
      lv.cand_face <- k
  | s -> csg_first lv s o);
  q.p_t <- o.p_t

(* Whether mesh or CSG object [p] crosses (q.p_tmin, q.p_tmax). *)
let composite_any lv (p : Primitive.t) (q : Probe.t) =
  let o = object_of lv p q in
  match p.shape with
  | Shape.Mesh { mesh; _ } -> mesh_any (deeper lv) mesh o >= 0
  | s -> csg_any lv s o

(* Every crossing of mesh or CSG object [p] (scene index [id]) in (q.p_tmin, q.p_tmax)
   into [out]: a mesh's each t once, with the lowest face crossed there. *)
let composite_crossings lv (p : Primitive.t) (q : Probe.t) out id =
  let o = object_of lv p q in
  match p.shape with
  | Shape.Mesh { mesh; _ } ->
      let b = lv.buf in
      b.n <- 0;
      ignore (mesh_crossings (deeper lv) mesh o b 0 (-1));
      sort b;
      push_distinct b out id
  | s ->
      ignore
        (csg_crossings (deeper lv) (Task.current ()) s o ~first:false ~state:false out id
           0)

(* --- A scene's index ---------------------------------------------------------------------- *)

(* Each query over a tree, or in a scan of the slots of an index that has none. *)
let nearest_in lv (x : index) q (h : hit) =
  h.item <-
    (if Float.Array.length x.nodes > 0 then
       nearest ~tris:false ~nested:composite_root lv x.items no_mesh x.nodes x.depth x.ids
         x.first q
     else if x.items.parts then
       scan_nearest ~parts:true ~nested:composite_root lv x.items x.first q
     else (
       lv.leaf <- -1;
       lv.face <- -1;
       scan_nearest ~parts:false ~nested:composite_root lv x.items x.first q));
  h.leaf <- lv.leaf;
  h.face <- lv.face

let any_in lv (x : index) q ~opaque ~mask =
  let s =
    if Float.Array.length x.nodes > 0 then
      any ~tris:false ~nested:composite_any lv x.items no_mesh x.nodes x.depth x.ids
        x.first q ~opaque
    else scan_any ~nested:composite_any lv x.items x.first q ~opaque ~mask
  in
  if s < 0 then -1 else Array.unsafe_get x.ids s

(* Whether the part s0 ≤ s ≤ s1 of the segment o + s·(c − o), at most [r] away, can meet
   the bounds at [k] of [b]: whether it meets them grown by r on every side (slabs over s
   in [s0, s1]). Any bound that is not finite keeps the answer yes. The three slabs are
   written out: a loop over the axes choosing each one's values costs 2.7 % more
   instructions in a soft-shadowed still life. *)
let[@inline] segment_near b k ox oy oz cx cy cz r s0 s1 =
  let x0 = fget b k and y0 = fget b (k + 1) and z0 = fget b (k + 2) in
  let x1 = fget b (k + 3) and y1 = fget b (k + 4) and z1 = fget b (k + 5) in
  if
    not
      (Float.is_finite x0 && Float.is_finite y0 && Float.is_finite z0
     && Float.is_finite x1 && Float.is_finite y1 && Float.is_finite z1)
  then true
  else
    let lo = ref s0 and hi = ref s1 and near = ref true in
    let d = cx -. ox in
    (if d = 0. then (if ox < x0 -. r || ox > x1 +. r then near := false)
     else
       let a = (x0 -. r -. ox) /. d and c = (x1 +. r -. ox) /. d in
       let tn = if a <= c then a else c and tf = if a <= c then c else a in
       if tn > !lo then lo := tn;
       if tf < !hi then hi := tf);
    let d = cy -. oy in
    (if d = 0. then (if oy < y0 -. r || oy > y1 +. r then near := false)
     else
       let a = (y0 -. r -. oy) /. d and c = (y1 +. r -. oy) /. d in
       let tn = if a <= c then a else c and tf = if a <= c then c else a in
       if tn > !lo then lo := tn;
       if tf < !hi then hi := tf);
    let d = cz -. oz in
    (if d = 0. then (if oz < z0 -. r || oz > z1 +. r then near := false)
     else
       let a = (z0 -. r -. oz) /. d and c = (z1 +. r -. oz) /. d in
       let tn = if a <= c then a else c and tf = if a <= c then c else a in
       if tn > !lo then lo := tn;
       if tf < !hi then hi := tf);
    !near && !lo <= !hi

(* Whether a ray from o toward a point at most [r] from c may cross the plane of slot
   [j] (an untransformed one): not when o is strictly on one side (as the plane's test
   computes it) and every such point further on that side by more than [e], so that every
   ray leaves the plane behind. *)
let[@inline] plane_near prims j ox oy oz cx cy cz r e =
  match (Array.unsafe_get prims j : Primitive.t).shape with
  | Shape.Plane { normal; offset } ->
      let nx = normal.x and ny = normal.y and nz = normal.z in
      let num = offset -. ((ox *. nx) +. (oy *. ny) +. (oz *. nz)) in
      let nl = Float.sqrt ((nx *. nx) +. (ny *. ny) +. (nz *. nz)) in
      (* How far c lies beyond o, away from the plane, less the disk's reach. *)
      let away = (cx *. nx) +. (cy *. ny) +. (cz *. nz) -. offset +. num in
      not ((num < 0. && away -. (nl *. r) > e) || (num > 0. && away +. (nl *. r) < -.e))
  | _ -> true

let[@inline] abs_max a x y z =
  Floats.max a (Floats.max (Float.abs x) (Floats.max (Float.abs y) (Float.abs z)))

(* [csg_clear] for the member [m] and points in its space: the planes tried are a face's
   (a box's or a cylinder's cap) whose outside o is in, a cylinder's side tangent across
   o's way from the axis, and a sphere's tangent plane nearest o. For each, the member
   has n·x ≤ d, and the test is n·o > d + eo and n·c ≥ d + r + e: o outside by a margin
   [eo] (a millionth of the light's [e], far below the lift of a shaded point off its
   surface) that the member's own roots, computed otherwise, agree with, and c beyond by
   r and [e]; o inside the member has none. Coordinates that are not finite have none. *)
let[@inline] member_clear (m : Shape.t) ox oy oz cx cy cz r =
  Float.is_finite ox && Float.is_finite oy && Float.is_finite oz && Float.is_finite cx
  && Float.is_finite cy && Float.is_finite cz
  &&
  let scale = abs_max (abs_max 1. ox oy oz) cx cy cz in
  let e = 1e-6 *. scale and eo = 1e-12 *. scale in
  match m with
  | Shape.Sphere { center; radius } ->
      let vx = ox -. center.x and vy = oy -. center.y and vz = oz -. center.z in
      let l = Float.sqrt ((vx *. vx) +. (vy *. vy) +. (vz *. vz)) in
      l > radius +. eo
      && l < Float.infinity
      && ((vx *. (cx -. center.x)) +. (vy *. (cy -. center.y)) +. (vz *. (cz -. center.z)))
         /. l
         >= radius +. r +. e
  | Shape.Box { min; max } ->
      (ox > max.x +. eo && cx -. max.x >= r +. e)
      || (ox < min.x -. eo && min.x -. cx >= r +. e)
      || (oy > max.y +. eo && cy -. max.y >= r +. e)
      || (oy < min.y -. eo && min.y -. cy >= r +. e)
      || (oz > max.z +. eo && cz -. max.z >= r +. e)
      || (oz < min.z -. eo && min.z -. cz >= r +. e)
  | Shape.Cylinder { base; axis; height; radius; caps = true; _ } ->
      let ex = ox -. base.x and ey = oy -. base.y and ez = oz -. base.z in
      let fx = cx -. base.x and fy = cy -. base.y and fz = cz -. base.z in
      let h = (ex *. axis.x) +. (ey *. axis.y) +. (ez *. axis.z)
      and hc = (fx *. axis.x) +. (fy *. axis.y) +. (fz *. axis.z) in
      (h > height +. eo && hc -. height >= r +. e)
      || (h < -.eo && -.hc >= r +. e)
      ||
      let rx = ex -. (h *. axis.x)
      and ry = ey -. (h *. axis.y)
      and rz = ez -. (h *. axis.z) in
      let rl = Float.sqrt ((rx *. rx) +. (ry *. ry) +. (rz *. rz)) in
      rl > radius +. eo
      && rl < Float.infinity
      && ((rx *. fx) +. (ry *. fy) +. (rz *. fz)) /. rl >= radius +. r +. e
  | _ -> false

(* Whether no segment from o to a point at most [r] from c can meet CSG object [p], a
   difference or an intersection (so inside its first member), because a plane has that
   member on one side and o and the whole ball of radius r around c on the other: the
   member is a sphere, a box or a capped cylinder placed as its object is, and the plane
   one that touches it where o is outside it. That settles the rays from a point of the
   object's own surface toward a light above it, each of which would otherwise seek the
   member's roots to learn that it leaves it. Worked in the object's space: o
   and c through the inverse transform, r grown by a bound on how far that stretches
   (√(‖A‖₁‖A‖∞) of its linear part A, 1 for a translation); the light's side must clear
   the plane by a margin on the scale of the coordinates. *)
let csg_clear (p : Primitive.t) ox oy oz cx cy cz r =
  match p.shape with
  | Shape.Csg { op = Shape.Difference | Shape.Intersection; members; _ }
    when Transform.is_identity (Array.unsafe_get members 0).transform ->
      let m = (Array.unsafe_get members 0).shape and tr = p.transform in
      if Transform.is_identity tr then member_clear m ox oy oz cx cy cz r
      else
        let a00 = Transform.inv_vx tr 1. 0. 0.
        and a10 = Transform.inv_vy tr 1. 0. 0.
        and a20 = Transform.inv_vz tr 1. 0. 0.
        and a01 = Transform.inv_vx tr 0. 1. 0.
        and a11 = Transform.inv_vy tr 0. 1. 0.
        and a21 = Transform.inv_vz tr 0. 1. 0.
        and a02 = Transform.inv_vx tr 0. 0. 1.
        and a12 = Transform.inv_vy tr 0. 0. 1.
        and a22 = Transform.inv_vz tr 0. 0. 1. in
        let[@inline] sum x y z = Float.abs x +. Float.abs y +. Float.abs z in
        let n1 =
          Floats.max (sum a00 a10 a20) (Floats.max (sum a01 a11 a21) (sum a02 a12 a22))
        and ninf =
          Floats.max (sum a00 a01 a02) (Floats.max (sum a10 a11 a12) (sum a20 a21 a22))
        in
        member_clear m
          (Transform.inv_px tr ox oy oz)
          (Transform.inv_py tr ox oy oz)
          (Transform.inv_pz tr ox oy oz)
          (Transform.inv_px tr cx cy cz)
          (Transform.inv_py tr cx cy cz)
          (Transform.inv_pz tr cx cy cz)
          (r *. Float.sqrt (n1 *. ninf))
  | _ -> false

let shadow_mask (x : index) (o : Probe.t) (c : Vec3.t) r =
  let ox = o.ox and oy = o.oy and oz = o.oz and cx = c.x and cy = c.y and cz = c.z in
  let n = x.first in
  if Float.Array.length x.nodes > 0 || Float.Array.length x.items.cull <> 6 * n then -1
  else
    (* A margin for rounding, far above it, on the scale of the coordinates. *)
    let scale = ref 1. in
    if Float.abs ox > !scale then scale := Float.abs ox;
    if Float.abs oy > !scale then scale := Float.abs oy;
    if Float.abs oz > !scale then scale := Float.abs oz;
    if Float.abs cx > !scale then scale := Float.abs cx;
    if Float.abs cy > !scale then scale := Float.abs cy;
    if Float.abs cz > !scale then scale := Float.abs cz;
    let scale = !scale in
    let e = 1e-6 *. scale and r = r *. (1. +. 1e-6) in
    let b = x.items.cull in
    (* The box of the whole segment grown by r: a slot's bounds apart from it are far
       from every ray (comparisons that a bound that is not finite fails keep it). *)
    let g = r +. e in
    let lx = Floats.min ox cx -. g and hx = Floats.max ox cx +. g in
    let ly = Floats.min oy cy -. g and hy = Floats.max oy cy +. g in
    let lz = Floats.min oz cz -. g and hz = Floats.max oz cz +. g in
    let m = ref 0 in
    for j = 0 to n - 1 do
      let k = 6 * j in
      (* A ray's point at s (its sample at most r from c) is at most s·r from the
         segment's point at s: the whole segment within r first, then its parts
         within s1·r, nearer the origin where the rays are close together. *)
      let c = Char.code (Bytes.unsafe_get x.items.kind j) in
      if
        if c land 3 = plane then plane_near x.items.prims j ox oy oz cx cy cz r e
        else
          (not
             (fget b (k + 3) < lx
             || fget b k > hx
             || fget b (k + 4) < ly
             || fget b (k + 1) > hy
             || fget b (k + 5) < lz
             || fget b (k + 2) > hz))
          && segment_near b k ox oy oz cx cy cz (r +. e) 0. 1.
          && (segment_near b k ox oy oz cx cy cz ((0.125 *. r) +. e) 0. 0.125
             || segment_near b k ox oy oz cx cy cz ((0.25 *. r) +. e) 0.125 0.25
             || segment_near b k ox oy oz cx cy cz ((0.5 *. r) +. e) 0.25 0.5
             || segment_near b k ox oy oz cx cy cz (r +. e) 0.5 1.)
          && not
               (c land 3 = composite
               && csg_clear (Array.unsafe_get x.items.prims j) ox oy oz cx cy cz r)
      then m := !m lor (1 lsl j)
    done;
    !m

let crossings_in lv (x : index) q ~transparent out =
  if Float.Array.length x.nodes > 0 then
    ignore
      (every ~tris:false ~nested:composite_crossings lv x.items no_mesh x.nodes x.depth
         x.ids x.first q ~transparent out 0 0)
  else scan_every ~nested:composite_crossings lv x.items x.first q ~transparent out

(* A mesh is tried first only where the ray meets its box (its bounds, padded as the
   tree's are). A CSG object is not tried first: where its crossings let the ray through,
   the walk would gather them a second time, which costs more than the walk it spares. *)
let other_blocks lv (p : Primitive.t) (q : Probe.t) =
  match p.shape with
  | Shape.Csg _ -> false
  | Shape.Mesh _ ->
      let b = lv.box in
      Primitive.bounds_into p b 0;
      Bvh.pad_into b 0 (fget b 0) (fget b 1) (fget b 2) (fget b 3) (fget b 4) (fget b 5);
      box_met b 0 q q.p_tmin q.p_tmax
      &&
      let tmin = q.p_tmin and tmax = q.p_tmax in
      let r = composite_any lv p q in
      q.p_tmin <- tmin;
      q.p_tmax <- tmax;
      r
  | _ ->
      let tmax = q.p_tmax in
      Primitive.root p q lv.obj;
      q.p_t < tmax

let[@inline] blocks lv (p : Primitive.t) (q : Probe.t) ~opaque =
  (not (opaque && p.material.transparency <> 0.))
  &&
  match p.shape with
  | Shape.Sphere { center; radius } when Transform.is_identity p.transform ->
      Shape.sphere_sc center.x center.y center.z radius q.ox q.oy q.oz q.dx q.dy q.dz
        q.p_tmin q.p_tmax
      < q.p_tmax
  | _ -> other_blocks lv p q

(* --- One shape, for a ray --------------------------------------------------------------- *)

let probe_of r tmin tmax =
  let q = Probe.create () in
  Probe.of_ray q r;
  q.p_tmin <- tmin;
  q.p_tmax <- tmax;
  q

let intersect s r tmin tmax =
  let lv = new_level () and q = probe_of r tmin tmax in
  (match s with
  | Shape.Mesh { mesh; _ } -> ignore (mesh_nearest lv mesh q)
  | Shape.Csg _ -> csg_first lv s q
  | s -> Shape.root s q);
  q.p_t

let inside s (p : Vec3.t) =
  let pt = Probe.create () in
  Probe.set_origin pt p.x p.y p.z;
  inside_at (new_level ()) (Task.current ()) s pt

let shape_crossings s r tmin =
  let q = probe_of r tmin Float.infinity in
  let out = crossings () in
  (match s with
  | Shape.Csg _ ->
      ignore
        (csg_crossings (new_level ()) (Task.current ()) s q ~first:false ~state:false out
           0 0)
  | Shape.Mesh { mesh; _ } ->
      let b = crossings () in
      ignore (mesh_crossings (new_level ()) mesh q b 0 (-1));
      sort b;
      push_distinct b out 0
  | s ->
      let go = ref true in
      while !go do
        Shape.root s q;
        if q.p_t < Float.infinity then (
          push out q.p_t 0 0 (-1);
          q.p_tmin <- q.p_t)
        else go := false
      done);
  let csg = match s with Shape.Csg _ -> true | _ -> false in
  List.init out.n (fun k ->
      ( fget out.ts k,
        (if csg then out.parts.((3 * k) + 1) else 0),
        out.parts.((3 * k) + 2) ))
