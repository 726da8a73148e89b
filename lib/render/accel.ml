(* Ray queries over a scene's objects: the hierarchy over them (Walk.index), built by the
   binned surface area heuristic when they weigh enough, a linear scan otherwise, and the
   three queries of Walk over it. Unbounded primitives (planes), and any whose bounds are
   not finite, stay out of the tree in the slots tested before it.

   Equality with the linear scan. The scan keeps the hit with the smallest t, ties to the
   lower index. Shape intersections compute the same roots whatever tmin and tmax are
   (Shape.mli), so the scan's answer is the lexicographic minimum of (t, index) over the
   primitives' nearest roots in (tmin, tmax). The walk computes the same minimum
   (Walk.nearest_in). *)

type t = {
  prims : Primitive.t array;
  weight : int;  (** the bounded primitives, a mesh counted as its faces *)
  index : Walk.index;
  layers : layers option;  (** instead of [index]: two structures over parts of [prims] *)
}

(* A scene's primitives in two parts, each with its own structure: [fixed] over those
   whose index [fixed_idx] lists (increasing), [moving] over the others. *)
and layers = {
  key : int array;  (** what the fixed part is, as its maker named it *)
  fixed : t;
  fixed_idx : int array;
  moving : t;
  moving_idx : int array;
  bvh : bool;  (** whether one structure over them all would be a tree *)
}

let min_bvh = 8
let uses_bvh a = match a.layers with Some l -> l.bvh | None -> a.weight >= min_bvh
let fixed_key a = Option.map (fun l -> l.key) a.layers
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

(* Whether [p] is tested from the flat floats (a sphere in world space). *)
let is_flat_sphere (p : Primitive.t) =
  match p.shape with Shape.Sphere _ -> Transform.is_identity p.transform | _ -> false

(* Every slot tested in order: no tree. *)
let linear prims =
  {
    Walk.nodes = Float.Array.create 0;
    depth = 0;
    ids = Array.init (Array.length prims) Fun.id;
    first = Array.length prims;
    items = Walk.items prims;
  }

let build_tree prims =
  let n = Array.length prims in
  (* One pass over the primitives: each one's bounds, whether they are bounded (all six
     finite: each [x -. x] is then +0, a NaN otherwise), the bounded ones' weight (a mesh
     counts as its faces, which one object each would have been), each bounded box padded
     where it lies, and whether it is a flat sphere. One pass and no closure: over the
     million coloured spheres of [make bench-limit], a pass and a closure per question
     were 0.25 G more instructions (5.36 G against 5.11 G to the first pixel). *)
  let pbox = Float.Array.create (6 * n) in
  (* By primitive: '\001' a flat sphere, '\000' another bounded one, '\002' unbounded;
     once the bounded ones are moved down, the first bytes are the build's flags of flat
     spheres. *)
  let flags = Bytes.create n in
  let m = ref 0 and weight = ref 0 in
  for i = 0 to n - 1 do
    let p = Array.unsafe_get prims i and q = 6 * i in
    Primitive.bounds_into p pbox q;
    let x0 = fget pbox q
    and y0 = fget pbox (q + 1)
    and z0 = fget pbox (q + 2)
    and x1 = fget pbox (q + 3)
    and y1 = fget pbox (q + 4)
    and z1 = fget pbox (q + 5) in
    if x0 -. x0 +. (y0 -. y0) +. (z0 -. z0) +. (x1 -. x1) +. (y1 -. y1) +. (z1 -. z1) = 0.
    then (
      Bvh.pad_into pbox i x0 y0 z0 x1 y1 z1;
      Bytes.unsafe_set flags i (if is_flat_sphere p then '\001' else '\000');
      incr m;
      weight := !weight + Primitive.faces p)
    else Bytes.unsafe_set flags i '\002'
  done;
  let m = !m and weight = !weight in
  if weight < min_bvh then { prims; weight; index = linear prims; layers = None }
  else
    (* The unbounded primitives' indices in order; the bounded ones' (when all are, the
       k-th is k, with no array), their boxes and flags moved down in place. *)
    let outside = Array.make (n - m) 0
    and bounded = Array.make (if m = n then 0 else m) 0 in
    (if m < n then
       let k = ref 0 and o = ref 0 in
       for i = 0 to n - 1 do
         let f = Bytes.unsafe_get flags i in
         if f = '\002' then (
           Array.unsafe_set outside !o i;
           incr o)
         else (
           Array.unsafe_set bounded !k i;
           Float.Array.blit pbox (6 * i) pbox (6 * !k) 6;
           Bytes.unsafe_set flags !k f;
           incr k)
       done);
    let pbox = if m = n then pbox else Float.Array.sub pbox 0 (6 * m) in
    let flat = if m = n then flags else Bytes.sub flags 0 m in
    let { Bvh.nodes; order; depth } = Bvh.build ~cheap:(flat, flat_leaf_max) pbox in
    (* The slots: the unbounded primitives, then the tree's in leaf order; the
       primitives in slot order beside them. *)
    let first = n - m in
    let ids = Array.make (first + m) 0 in
    Array.blit outside 0 ids 0 first;
    if m = n then Array.blit order 0 ids first m
    else
      for j = 0 to m - 1 do
        Array.unsafe_set ids (first + j)
          (Array.unsafe_get bounded (Array.unsafe_get order j))
      done;
    let slots =
      if first + m = 0 then [||]
      else
        let a =
          Array.make (first + m) (Array.unsafe_get prims (Array.unsafe_get ids 0))
        in
        for j = 1 to first + m - 1 do
          Array.unsafe_set a j (Array.unsafe_get prims (Array.unsafe_get ids j))
        done;
        a
    in
    (* The tree does not keep the boxes: their array holds the flat floats from here,
       rather than a new one beside it at the peak of memory. *)
    let items = Walk.items ~flat:pbox slots in
    { prims; weight; index = { Walk.nodes; depth; ids; first; items }; layers = None }

(* The structure is built at {!Pace.all_live}: what it allocates lives on with the
   primitives it indexes, but for the build's scratch. At the default pace the collector
   marked the primitives again for every few megabytes of boxes and nodes: over the
   million coloured spheres of [make bench-limit] (first pixel at 64×48) 5.77 G
   instructions rather than 5.36 G, over field_100000 (at 1×1) 0.87 G rather than 0.78 G,
   at the same peak of memory (295 MiB, 99.5 MiB at 1920×1080). *)
let build prims = Pace.within Pace.all_live (fun () -> build_tree prims)

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
  { prims; weight = !weight; index = linear prims; layers = None }

(* --- Scratch -------------------------------------------------------------------------- *)

(* What a domain's queries reuse, found by one look-up: the walks' levels, a hit record
   for the answers of a layered structure's first part, and for each light slot the scene
   index of the primitive that blocked its last shadow ray (-1: that ray was not
   blocked), tested before the walk. Shadow rays of neighbouring pixels tend to be
   blocked by the same object, and to pass where the last one passed: a ray that passes
   forgets the occluder, whose test (a mesh's whole walk) the next ray would most likely
   spend for nothing. Since the answer is a boolean (is there any opaque crossing?),
   trying one first changes only how soon it is found, never what is found. *)
type scratch = {
  w : Walk.scratch;
  mutable last : int array;
  watched : Float.Array.t;  (** the watched box (min x y z, max x y z) *)
  mutable watching : bool;
  mutable touched : bool;
      (** whether a query since {!untouch} may have met the watched box *)
}

let scratch_key =
  Domain.DLS.new_key (fun () ->
      {
        w = Walk.domain_scratch ();
        last = [||];
        watched = Float.Array.make 6 0.;
        watching = false;
        touched = false;
      })

let domain_scratch () = Domain.DLS.get scratch_key

let watch sc box =
  match box with
  | None -> sc.watching <- false
  | Some b ->
      if Float.Array.length b <> 6 then invalid_arg "Accel.watch: a box is 6 floats";
      Float.Array.blit b 0 sc.watched 0 6;
      sc.watching <- true

let untouch sc = sc.touched <- false
let touched sc = sc.touched

(* Whether the segment (t0, t1) of the probe's ray may meet the watched box: false only
   where every axis's slab is missed for certain (a NaN, from an origin on a slab plane
   with a direction along it, or an infinite t1, leaves it met). Divisions, not the
   probe's reciprocal, which a query may not have set yet. *)
let meets sc (q : Probe.t) t0 t1 =
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

(* --- The three queries ------------------------------------------------------------------ *)

let rec nearest_in sc a (q : Probe.t) (h : Walk.hit) =
  match a.layers with
  | None -> Walk.nearest_in sc.w a.index q h
  | Some l ->
      (* The moving part up to just past the fixed part's hit t, the lexicographic
         minimum of (t, index). *)
      let tmin = q.p_tmin and tmax = q.p_tmax in
      nearest_in sc l.fixed q h;
      let i = h.item and leaf = h.leaf and face = h.face and t = q.p_t in
      q.p_tmin <- tmin;
      q.p_tmax <- (if i >= 0 then Floats.above t else tmax);
      nearest_in sc l.moving q h;
      let j = h.item in
      if
        j >= 0 && (i < 0 || q.p_t < t || (q.p_t = t && l.moving_idx.(j) < l.fixed_idx.(i)))
      then h.item <- l.moving_idx.(j)
      else (
        q.p_t <- (if i >= 0 then t else Float.infinity);
        h.item <- (if i >= 0 then l.fixed_idx.(i) else -1);
        h.leaf <- leaf;
        h.face <- face)

let nearest sc a (q : Probe.t) h =
  Probe.set_inv_dir q;
  if sc.watching then (
    (* The segment up to the answer: no moving surface nearer than it means none of the
       watched box's crosses the ray before the answer. *)
    let t0 = q.p_tmin
    and t1 = q.p_tmax in
    nearest_in sc a q h;
    seen sc q t0 (if h.Walk.item >= 0 && q.p_t < t1 then q.p_t else t1))
  else
    match a.layers with
    | None -> Walk.nearest_in sc.w a.index q h
    | Some _ -> nearest_in sc a q h

let rec any_in sc a q ~opaque =
  match a.layers with
  | None -> Walk.any_in sc.w a.index q ~opaque ~mask:(-1)
  | Some l ->
      let i = any_in sc l.fixed q ~opaque in
      if i >= 0 then l.fixed_idx.(i)
      else
        let j = any_in sc l.moving q ~opaque in
        if j >= 0 then l.moving_idx.(j) else -1

(* [any_in] with the index of a structure without parts asked directly; only such a
   structure's mask is other than −1. *)
let[@inline] any_top sc a q ~opaque ~mask =
  match a.layers with
  | None -> Walk.any_in sc.w a.index q ~opaque ~mask
  | Some _ -> any_in sc a q ~opaque

let shadow_mask a o c r =
  match a.layers with None -> Walk.shadow_mask a.index o c r | Some _ -> -1

(* Whether scene index [c] may be tested under [mask]: a structure without a tree has
   its objects in scene order, one slot each. *)
let[@inline] allowed mask c = mask = -1 || (mask lsr c) land 1 = 1

let any sc a (q : Probe.t) ~opaque ~slot ~mask =
  seen sc q q.p_tmin q.p_tmax;
  Probe.set_inv_dir q;
  if slot < 0 then any_top sc a q ~opaque ~mask >= 0
  else (
    if slot >= Array.length sc.last then (
      let last = Array.make (slot + 1) (-1) in
      Array.blit sc.last 0 last 0 (Array.length sc.last);
      sc.last <- last);
    let prims = a.prims in
    let c = Array.unsafe_get sc.last slot in
    c >= 0
    && c < Array.length prims
    && allowed mask c
    && Walk.blocks sc.w (Array.unsafe_get prims c) q ~opaque
    ||
    let found = any_top sc a q ~opaque ~mask in
    Array.unsafe_set sc.last slot found;
    found >= 0)

let rec crossings_in sc a q ~transparent out =
  match a.layers with
  | None -> Walk.crossings_in sc.w a.index q ~transparent out
  | Some l ->
      let from = out.Walk.n in
      crossings_in sc l.fixed q ~transparent out;
      Walk.remap out from l.fixed_idx;
      let from = out.Walk.n in
      crossings_in sc l.moving q ~transparent out;
      Walk.remap out from l.moving_idx

let crossings sc a (q : Probe.t) ~transparent out =
  seen sc q q.p_tmin q.p_tmax;
  Probe.set_inv_dir q;
  Walk.clear out;
  (match a.layers with
  | None -> Walk.crossings_in sc.w a.index q ~transparent out
  | Some _ -> crossings_in sc a q ~transparent out);
  Walk.sort out

(* --- Two parts ------------------------------------------------------------------------ *)

let layered prims ~key ~fixed ~fixed_idx ~moving ~moving_idx =
  let n = Array.length prims in
  if Array.length fixed_idx + Array.length moving_idx <> n then
    invalid_arg "Accel.layered: the parts do not cover the primitives";
  (* The parts counted their bounded primitives when they were built: nothing here is
     proportional to the fixed part, which a frame of an animation does not change. *)
  let weight = fixed.weight + moving.weight in
  {
    prims;
    weight;
    index = linear [||];
    layers = Some { key; fixed; fixed_idx; moving; moving_idx; bvh = weight >= min_bvh };
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
