(* A bounding volume hierarchy over boxes, built by the binned surface area heuristic
   (over [large] items, in Morton order above small subtrees: see Large builds): what
   the scene's structure and a mesh's own are made of. *)

let fget = Float.Array.unsafe_get
let fset = Float.Array.unsafe_set
let max_leaf = 8
let bins = 16

(* Nodes of at most [small] items are split by the sorted search of Small subtrees below,
   along the widest axis of their centroids' bounds; larger ones by binning, along the
   widest axis of their box over its extent, or of their centroids' bounds where an item
   is wide ([over_box], [best_split]). [small] was
   chosen when the search looked along all three axes (at about three times the
   binning's cost per item and level): over a million spheres in a grid, 16 rather than
   32 built with 1.5 % fewer instructions in the whole render, and the 100 000-sphere
   field's render took the same (within 0.2 %). Searching small nodes along their widest
   axis rather than all three loads a million-triangle mesh in about 10 % fewer
   instructions (a 90 000-triangle torus: 582 M against 646 M under cachegrind) and
   renders it in 0.6 % more. *)
let small = 16

(* --- Construction ----------------------------------------------------------------- *)

(* The build allocates nothing per primitive or per node beyond its arrays: per-primitive
   data is one Float.Array of padded bounds (centroids are their midpoints), moved with
   the primitives' order as nodes are partitioned, nodes are written into arrays grown by
   half, and the binning scratch is reused at every node. Floats stay in local mutable
   variables, inlined functions and float arrays, so that none is boxed.

   A large node is read once: its partition also bins its children (their boxes are
   unions of its bins, known before it starts), and a primitive's bin waits in a byte by
   its position for the partition of the node it is in. Min and max being exact on finite
   floats, bounds gathered bin by bin are those a pass in any order computes, so the tree
   is the one a bin pass and a partition pass per node make.

   The tree changes what a query costs, never what it answers: the walks answer the least
   (t, index) of the items, in whatever order they meet them ({!Walk}). *)
(* A bin's box, a flat record of floats. *)
type bin = {
  mutable x0 : float;
  mutable y0 : float;
  mutable z0 : float;
  mutable x1 : float;
  mutable y1 : float;
  mutable z1 : float;
}

let new_bin () = { x0 = 0.; y0 = 0.; z0 = 0.; x1 = 0.; y1 = 0.; z1 = 0. }
let new_slot () = Array.init bins (fun _ -> new_bin ())

type work = {
  mutable pbox : Float.Array.t;
      (** 6 per primitive: padded min x y z, max x y z, in the order of [ids] (but within
          a small subtree: see Small subtrees below), so that every pass over a large node
          reads memory in sequence; from position [p_lo] on (a large build's small subtree
          reads a copy of its own boxes: see Large builds below) *)
  mutable p_lo : int;
  ids : int array;  (** a permutation of 0..m−1, partitioned in place *)
  tag : Bytes.t;
      (** by position: the primitive's bin in the binning of the node it is in, written by
          that binning and read by the node's partition *)
  mutable nodes_b : Float.Array.t;  (** 8 per node (see [t]) *)
  mutable count : int;
  mutable max_depth : int;
  cheap : Bytes.t;
      (** by item: whether a leaf of at most [cheap_max] such items is made without a
          split search (empty: none is) *)
  cheap_max : int;
  (* Bin scratch, reused at every node: the areas and counts of the bins from b to the
     last, and the bounds the node is searched over (a large node's box, a small node's
     centroid bounds). *)
  right_area : Float.Array.t;
  right_n : int array;
  cbox : Float.Array.t;
  cen12 : Float.Array.t;
      (** a large node's box and centroids' bounds, when it is binned over the latter *)
  mutable ext : Float.Array.t;
      (** the largest extent of an item along each axis, 3 floats (found where a node is
          binned: a build in Morton order with no wide item bins none) *)
  cost : Float.Array.t;  (** the split cost the last split search found (not boxed) *)
  mutable pend : Float.Array.t;
  mutable pend_right : Float.Array.t;
  (* The bins of large nodes, a slot of [bins] bins and [slot_i] integers per depth, like
     [pend] and [pend_right]: at d those of the node being built there and those of its
     right child. The integers are the binning axis (−1: not binned yet), then the
     counts. *)
  mutable pbins : bin array array;
  mutable pbins_right : bin array array;
  mutable pcount : int array;
  mutable pcount_right : int array;
  (* A subtree of at most [small] primitives, all of its nodes small (see Small
     subtrees below): its primitives are named by their position in it when it starts,
     their identity; positions below are relative to its first, [s_lo]. *)
  mutable s_lo : int;
  s_cen : Float.Array.t;  (** by identity: its centroid, 3 floats *)
  s_pos : int array;  (** by position: the identity there, moved as [ids] would be *)
  s_sorted : int array;
      (** [small] per axis, by position: identities, those of a node's range sorted by
          their centroid along the axis *)
  s_tmp : int array;
  s_key : Float.Array.t;  (** the centroids of a list being sorted, in its order *)
  s_left : Bytes.t;  (** by identity: whether it goes left in the partition under way *)
  s_bin : int array;  (** by rank along the axis searched: the primitive's bin *)
  s_area : Float.Array.t;
      (** by rank, where a bin starts: the area of the boxes of that rank and above *)
  s_rbox : Float.Array.t;  (** by rank likewise, their box, 6 floats *)
  s_best : Float.Array.t;
      (** the boxes of the two sides of the best split found, 6 floats each *)
}

let new_node w =
  let k = w.count in
  if 8 * (k + 1) > Float.Array.length w.nodes_b then (
    let cap = k + (k / 2) + 16 in
    let nodes = Float.Array.create (8 * cap) in
    Float.Array.blit w.nodes_b 0 nodes 0 (8 * k);
    w.nodes_b <- nodes);
  w.count <- k + 1;
  k

(* Running bounds in registers are updated as [if not (!x0 < v) then x0 := v], which is
   [x0 := fmin !x0 v] for any floats with one branch and no jump on the common path.
   Typed comparisons rather than Float.min/max: the bounds are finite (checked at
   entry), and Float.min's NaN and signed-zero handling costs a C call per use. *)
let[@inline] fmin (a : float) b = if a < b then a else b
let[@inline] fmax (a : float) b = if a > b then a else b

(* Surface area of the box min (x0, y0, z0), max (x1, y1, z1), 0 when empty. *)
let[@inline] area6 x0 y0 z0 x1 y1 z1 =
  let dx = x1 -. x0 and dy = y1 -. y0 and dz = z1 -. z0 in
  if dx < 0. || dy < 0. || dz < 0. then 0.
  else 2. *. ((dx *. dy) +. (dy *. dz) +. (dz *. dx))

(* Surface area of the box stored at [off] in [a] (6 floats), 0 when empty. *)
let[@inline] area a off =
  area6 (fget a off)
    (fget a (off + 1))
    (fget a (off + 2))
    (fget a (off + 3))
    (fget a (off + 4))
    (fget a (off + 5))

let[@inline] box_empty a off =
  fset a off Float.infinity;
  fset a (off + 1) Float.infinity;
  fset a (off + 2) Float.infinity;
  fset a (off + 3) Float.neg_infinity;
  fset a (off + 4) Float.neg_infinity;
  fset a (off + 5) Float.neg_infinity

(* The box min (x0, y0, z0), max (x1, y1, z1) into [a] at [off]. *)
let[@inline] box_set a off x0 y0 z0 x1 y1 z1 =
  fset a off x0;
  fset a (off + 1) y0;
  fset a (off + 2) z0;
  fset a (off + 3) x1;
  fset a (off + 4) y1;
  fset a (off + 5) z1

(* The centroid's coordinate [k] of the padded box at [q] in [pb]. *)
let[@inline] cen pb q k = 0.5 *. (fget pb (q + k) +. fget pb (q + 3 + k))

let[@inline] bin_of cmin scale c =
  let b = int_of_float ((c -. cmin) *. scale) in
  if b < 0 then 0 else if b >= bins then bins - 1 else b

(* The box of ids[lo, hi) and its centroids' bounds, 12 floats into [dst] at [doff]. *)
let bound_range w lo hi dst doff =
  let pb = w.pbox in
  let x0 = ref Float.infinity and y0 = ref Float.infinity and z0 = ref Float.infinity in
  let x1 = ref Float.neg_infinity
  and y1 = ref Float.neg_infinity
  and z1 = ref Float.neg_infinity in
  let cx0 = ref Float.infinity
  and cy0 = ref Float.infinity
  and cz0 = ref Float.infinity in
  let cx1 = ref Float.neg_infinity
  and cy1 = ref Float.neg_infinity
  and cz1 = ref Float.neg_infinity in
  for i = lo to hi - 1 do
    let q = 6 * i in
    let v0 = fget pb q and v1 = fget pb (q + 1) and v2 = fget pb (q + 2) in
    let v3 = fget pb (q + 3) and v4 = fget pb (q + 4) and v5 = fget pb (q + 5) in
    if not (!x0 < v0) then x0 := v0;
    if not (!y0 < v1) then y0 := v1;
    if not (!z0 < v2) then z0 := v2;
    if not (!x1 > v3) then x1 := v3;
    if not (!y1 > v4) then y1 := v4;
    if not (!z1 > v5) then z1 := v5;
    let cx = cen pb q 0 and cy = cen pb q 1 and cz = cen pb q 2 in
    if not (!cx0 < cx) then cx0 := cx;
    if not (!cy0 < cy) then cy0 := cy;
    if not (!cz0 < cz) then cz0 := cz;
    if not (!cx1 > cx) then cx1 := cx;
    if not (!cy1 > cy) then cy1 := cy;
    if not (!cz1 > cz) then cz1 := cz
  done;
  fset dst doff !x0;
  fset dst (doff + 1) !y0;
  fset dst (doff + 2) !z0;
  fset dst (doff + 3) !x1;
  fset dst (doff + 4) !y1;
  fset dst (doff + 5) !z1;
  fset dst (doff + 6) !cx0;
  fset dst (doff + 7) !cy0;
  fset dst (doff + 8) !cz0;
  fset dst (doff + 9) !cx1;
  fset dst (doff + 10) !cy1;
  fset dst (doff + 11) !cz1

let bound_empty dst doff =
  box_empty dst doff;
  box_empty dst (doff + 6)

let slot_i = bins + 1

(* The widest axis of the bounds at [coff] in [c] (ties to x, then y), and whether its
   extent is positive: the one axis each search looks along (a large node's box, a small
   node's centroid bounds, −1 where every centroid coincides). *)
let[@inline] widest c coff =
  let ex = fget c (coff + 3) -. fget c coff
  and ey = fget c (coff + 4) -. fget c (coff + 1)
  and ez = fget c (coff + 5) -. fget c (coff + 2) in
  if ex >= ey && ex >= ez then if ex > 0. then 0 else -1
  else if ey >= ez then if ey > 0. then 1 else -1
  else if ez > 0. then 2
  else -1

(* The axis [best_split] bins a node of [n] primitives along, whose box is at [coff] in
   [c]: its widest, or −1 when the node is small. *)
let bin_axis_of c coff n = if n <= small then -1 else widest c coff

(* Whether a large node whose box is at [coff] in [c] is binned over its box along
   [axis]: when no item of the whole build is wider there than half the box, so that its
   centroids spread over at least half its bins. Over a box that some item makes much
   wider than its centroids' spread (a floor among small objects), the centroids would
   fall in a few bins, and the split found would be poor at every level down to that
   item (the SAH cost of 100 000 small boxes among 100 large ones five times the
   other's); such a node is binned over its centroids' bounds, found by a pass over it,
   along their widest axis. *)
let[@inline] over_box w c coff axis =
  2. *. fget w.ext axis <= fget c (coff + 3 + axis) -. fget c (coff + axis)

(* Empty the bins of [slot], counts at [io] in [c], for binning along [axis]. *)
let bins_clear (slot : bin array) c io axis =
  Array.unsafe_set c io axis;
  for b = 0 to bins - 1 do
    Array.unsafe_set c (io + 1 + b) 0;
    let r = Array.unsafe_get slot b in
    r.x0 <- Float.infinity;
    r.y0 <- Float.infinity;
    r.z0 <- Float.infinity;
    r.x1 <- Float.neg_infinity;
    r.y1 <- Float.neg_infinity;
    r.z1 <- Float.neg_infinity
  done

(* Put the primitive at position [i], of box min (x0, y0, z0), max (x1, y1, z1), into
   its bin of [slot], counts at [io] in [c] (the bin of its centroid's coordinate along
   [axis], from [cmin] at [scale] bins a unit), and that bin into [tag]. Each bound is
   stored only when it may change: [not (r.x0 < v)] is when [fmin r.x0 v] is [v], for any
   floats. *)
let[@inline] bin_put_box tag (slot : bin array) c io axis cmin scale i x0 y0 z0 x1 y1 z1 =
  let v =
    if axis = 0 then 0.5 *. (x0 +. x1)
    else if axis = 1 then 0.5 *. (y0 +. y1)
    else 0.5 *. (z0 +. z1)
  in
  let b = bin_of cmin scale v in
  Bytes.unsafe_set tag i (Char.unsafe_chr b);
  let k = io + 1 + b in
  Array.unsafe_set c k (Array.unsafe_get c k + 1);
  let r = Array.unsafe_get slot b in
  if not (r.x0 < x0) then r.x0 <- x0;
  if not (r.y0 < y0) then r.y0 <- y0;
  if not (r.z0 < z0) then r.z0 <- z0;
  if not (r.x1 > x1) then r.x1 <- x1;
  if not (r.y1 > y1) then r.y1 <- y1;
  if not (r.z1 > z1) then r.z1 <- z1

(* [bin_put_box] of the box at position [i] of [pb]. *)
let[@inline] bin_put pb tag slot c io axis cmin scale i =
  let q = 6 * i in
  bin_put_box tag slot c io axis cmin scale i (fget pb q)
    (fget pb (q + 1))
    (fget pb (q + 2))
    (fget pb (q + 3))
    (fget pb (q + 4))
    (fget pb (q + 5))

(* Bin [r]'s bounds added to the 12 at [doff] in [dst]. *)
let bound_merge_bin dst doff r =
  fset dst doff (fmin (fget dst doff) r.x0);
  fset dst (doff + 1) (fmin (fget dst (doff + 1)) r.y0);
  fset dst (doff + 2) (fmin (fget dst (doff + 2)) r.z0);
  fset dst (doff + 3) (fmax (fget dst (doff + 3)) r.x1);
  fset dst (doff + 4) (fmax (fget dst (doff + 4)) r.y1);
  fset dst (doff + 5) (fmax (fget dst (doff + 5)) r.z1)

(* The binning's origin and scale along [axis] over the bounds at [coff] in [c] (a large
   node's box, or its centroids' bounds: see [over_box]). *)
let[@inline] bin_min c coff axis = if axis < 0 then 0. else fget c (coff + axis)

let[@inline] bin_scale c coff axis =
  if axis < 0 then 0.
  else Float.of_int bins /. (fget c (coff + 3 + axis) -. fget c (coff + axis))

(* Bin ids[lo, hi) along [axis] into the slot of [depth], in one pass. *)
let bin_range w lo hi depth axis b boff =
  let slot = w.pbins.(depth) and c = w.pcount and io = slot_i * depth in
  bins_clear slot c io axis;
  let cmin = bin_min b boff axis and scale = bin_scale b boff axis in
  let pb = w.pbox and tag = w.tag in
  for i = lo to hi - 1 do
    bin_put pb tag slot c io axis cmin scale i
  done

(* Binned SAH: bin the centroids, sweep the bins from both ends, and keep the cheapest
   split cost SA(L)·nL + SA(R)·nR with both sides occupied. The split (axis, first bin of
   the right side) is stored in [split] and its cost in [cost]; infinity when no axis
   splits. Nodes of more than [small] primitives, the only ones that come here, bin only
   along their widest axis: a million-triangle mesh's tree builds a quarter faster than
   with three axes down to 4096 primitives, for an SAH cost 2% higher. Where [over_box]
   lets them, they bin over their box (in [cbox]) rather than their centroids' bounds, so
   that a bin keeps 6 bounds, not 12, and its parent's partition bins it. The
   million-triangle torus of [make bench-limit] loads in 5.33 G instructions under
   cachegrind at 64×48, for an SAH cost 0.4 % higher than over the centroids' bounds
   (the fused binning of 12 bounds a bin loaded it in 6.13 G with a one-ended partition;
   a pass for the centroids' bounds at every large node, in 6.84 G). The node's bins are
   in the slot of [depth] when its parent's partition made them, else made here (over
   its centroids' bounds where [over_box] says no). *)
let best_split w lo hi depth split =
  let best_cost = ref Float.infinity in
  split.(0) <- -1;
  let io = slot_i * depth in
  (if Array.unsafe_get w.pcount io < 0 then
     let axis = bin_axis_of w.cbox 0 (hi - lo) in
     if axis >= 0 && over_box w w.cbox 0 axis then bin_range w lo hi depth axis w.cbox 0
     else (
       bound_range w lo hi w.cen12 0;
       let axis = widest w.cen12 6 in
       if axis >= 0 then bin_range w lo hi depth axis w.cen12 6));
  let axis = Array.unsafe_get w.pcount io in
  if axis >= 0 then (
    let slot = w.pbins.(depth) and c = w.pcount in
    (* right_area.(b): area of bins b..bins−1; right_n likewise. An empty bin changes
       neither, and a split just after one costs what the split before it does. *)
    let x0 = ref Float.infinity and y0 = ref Float.infinity and z0 = ref Float.infinity in
    let x1 = ref Float.neg_infinity
    and y1 = ref Float.neg_infinity
    and z1 = ref Float.neg_infinity in
    let acc_n = ref 0 in
    for b = bins - 1 downto 1 do
      let k = Array.unsafe_get c (io + 1 + b) in
      if k > 0 then (
        let r = Array.unsafe_get slot b in
        if not (!x0 < r.x0) then x0 := r.x0;
        if not (!y0 < r.y0) then y0 := r.y0;
        if not (!z0 < r.z0) then z0 := r.z0;
        if not (!x1 > r.x1) then x1 := r.x1;
        if not (!y1 > r.y1) then y1 := r.y1;
        if not (!z1 > r.z1) then z1 := r.z1;
        acc_n := !acc_n + k);
      fset w.right_area b (area6 !x0 !y0 !z0 !x1 !y1 !z1);
      Array.unsafe_set w.right_n b !acc_n
    done;
    let x0 = ref Float.infinity and y0 = ref Float.infinity and z0 = ref Float.infinity in
    let x1 = ref Float.neg_infinity
    and y1 = ref Float.neg_infinity
    and z1 = ref Float.neg_infinity in
    let acc_n = ref 0 in
    for b = 0 to bins - 2 do
      let k = Array.unsafe_get c (io + 1 + b) in
      if k > 0 then (
        let r = Array.unsafe_get slot b in
        if not (!x0 < r.x0) then x0 := r.x0;
        if not (!y0 < r.y0) then y0 := r.y0;
        if not (!z0 < r.z0) then z0 := r.z0;
        if not (!x1 > r.x1) then x1 := r.x1;
        if not (!y1 > r.y1) then y1 := r.y1;
        if not (!z1 > r.z1) then z1 := r.z1;
        acc_n := !acc_n + k;
        let nl = !acc_n and nr = Array.unsafe_get w.right_n (b + 1) in
        if nr > 0 && nl > 0 then
          let cost =
            (area6 !x0 !y0 !z0 !x1 !y1 !z1 *. Float.of_int nl)
            +. (fget w.right_area (b + 1) *. Float.of_int nr)
          in
          if cost < !best_cost then (
            best_cost := cost;
            split.(0) <- axis;
            split.(1) <- b + 1))
    done);
  fset w.cost 0 !best_cost

(* Partition ids[lo, hi) of the binned node at [depth] so that the primitives in bins
   below [split] come first; the index of the first of the others. From both ends: the
   first primitive from the left that belongs to the right is swapped with the first
   from the right that belongs to the left, so that a primitive already on its side is
   not moved (most of them, where the items come in spatial order, as a mesh's faces
   do: the million-triangle torus loads in 5 % fewer instructions than with every
   primitive of the right side moved once). Each primitive's bin is read from [tag], the
   children's bounds are unions of bins, and the children that [best_split] will bin are
   binned here, as each primitive reaches its place, into the slots of the left child
   (depth + 1) and of the right child (the right slot of [depth]). *)
let partition_binned w lo hi depth split =
  let slot = w.pbins.(depth) and c = w.pcount and io = slot_i * depth in
  let dl = w.pend and loff = 12 * (depth + 1) in
  let dr = w.pend_right and roff = 12 * depth in
  bound_empty dl loff;
  bound_empty dr roff;
  let nl = ref 0 and nr = ref 0 in
  for b = 0 to bins - 1 do
    let n = Array.unsafe_get c (io + 1 + b) in
    if n = 0 then ()
    else if b < split then (
      bound_merge_bin dl loff (Array.unsafe_get slot b);
      nl := !nl + n)
    else (
      bound_merge_bin dr roff (Array.unsafe_get slot b);
      nr := !nr + n)
  done;
  let la = bin_axis_of dl loff !nl and ra = bin_axis_of dr roff !nr in
  let la = if la >= 0 && over_box w dl loff la then la else -1
  and ra = if ra >= 0 && over_box w dr roff ra then ra else -1 in
  let ls = w.pbins.(depth + 1) and lc = c and lio = slot_i * (depth + 1) in
  let rs = w.pbins_right.(depth) and rc = w.pcount_right and rio = io in
  bins_clear ls lc lio la;
  bins_clear rs rc rio ra;
  let lmin = bin_min dl loff la and lscale = bin_scale dl loff la in
  let rmin = bin_min dr roff ra and rscale = bin_scale dr roff ra in
  let ids = w.ids and pb = w.pbox and tag = w.tag in
  let i = ref lo and j = ref (hi - 1) in
  while !i <= !j do
    while !i <= !j && Char.code (Bytes.unsafe_get tag !i) < split do
      if la >= 0 then bin_put pb tag ls lc lio la lmin lscale !i;
      incr i
    done;
    while !i <= !j && Char.code (Bytes.unsafe_get tag !j) >= split do
      if ra >= 0 then bin_put pb tag rs rc rio ra rmin rscale !j;
      decr j
    done;
    if !i < !j then (
      let a = !i and b = !j in
      let q = 6 * a and r = 6 * b in
      let pa = Array.unsafe_get ids a and pbb = Array.unsafe_get ids b in
      let x0 = fget pb q and y0 = fget pb (q + 1) and z0 = fget pb (q + 2) in
      let x1 = fget pb (q + 3) and y1 = fget pb (q + 4) and z1 = fget pb (q + 5) in
      let u0 = fget pb r and v0 = fget pb (r + 1) and w0 = fget pb (r + 2) in
      let u1 = fget pb (r + 3) and v1 = fget pb (r + 4) and w1 = fget pb (r + 5) in
      Array.unsafe_set ids a pbb;
      Array.unsafe_set ids b pa;
      box_set pb q u0 v0 w0 u1 v1 w1;
      box_set pb r x0 y0 z0 x1 y1 z1;
      if la >= 0 then bin_put_box tag ls lc lio la lmin lscale a u0 v0 w0 u1 v1 w1;
      if ra >= 0 then bin_put_box tag rs rc rio ra rmin rscale b x0 y0 z0 x1 y1 z1;
      i := a + 1;
      j := b - 1)
  done;
  !i

(* Bounds waiting for their node, 12 floats per depth (its box, then its centroids' bounds,
   which a large node's partition leaves empty for its children and [small_setup] fills
   in): [pend] at depth d those of the node being built there, [pend_right] at d those of
   its right child while its left subtree is built; the bins likewise. *)
let reserve w depth =
  if 12 * (depth + 2) > Float.Array.length w.pend then (
    let d = 2 * (depth + 2) in
    let grow a n =
      let b = Float.Array.create (n * d) in
      Float.Array.blit a 0 b 0 (Float.Array.length a);
      b
    in
    let grow_i a =
      let b = Array.make (slot_i * d) (-1) in
      Array.blit a 0 b 0 (Array.length a);
      b
    in
    w.pend <- grow w.pend 12;
    w.pend_right <- grow w.pend_right 12;
    w.pcount <- grow_i w.pcount;
    w.pcount_right <- grow_i w.pcount_right)

(* Bins for a large node at [depth] and its children, made as deep as large nodes go. *)
let reserve_bins w depth =
  if depth + 2 > Array.length w.pbins then (
    let grow_s a =
      Array.init (depth + 2) (fun k -> if k < Array.length a then a.(k) else new_slot ())
    in
    w.pbins <- grow_s w.pbins;
    w.pbins_right <- grow_s w.pbins_right)

(* The children of the node at [depth] are not binned yet. *)
let unbinned w depth =
  w.pcount.(slot_i * (depth + 1)) <- -1;
  w.pcount_right.(slot_i * depth) <- -1

(* --- Small subtrees ----------------------------------------------------------------- *)

(* A subtree of at most [small] primitives is searched with each axis's order of its
   centroids made once, by a sort when it starts, rather than by a sort of every node
   along every axis: a node's bins along an axis are a monotone function of the centroid
   there, so its primitives in centroid order are in bin order, and a partition that
   keeps each axis's order (a stable split of each list) hands the children theirs.
   Primitives move as identities only ([s_pos], swapped as [ids] would be, which are
   written once at the end): [pbox] is not moved within the subtree, and a primitive's box
   is read at its identity's place there, its centroid from [s_cen]. The children's
   bounds come from the split search (the boxes of its two sides) and from the lists (the
   first and last centroid along each axis): min and max are exact on finite floats, and
   padded bounds and their midpoints are never −0, so bounds gathered in any order are
   those a pass over the children computes, bit for bit. *)

(* Start the subtree ids[lo, lo + n), n > 0: the centroids by identity, each axis's list
   of identities sorted by centroid (by insertion: at most [small] of them; in their
   order where centroids coincide), and the centroids' bounds into [c] at [coff], the
   first and last of each list (its parent's bins kept boxes only). *)
let small_setup w lo n c coff =
  let pb = w.pbox and sc = w.s_cen and ss = w.s_sorted and key = w.s_key in
  w.s_lo <- lo;
  for i = 0 to n - 1 do
    Array.unsafe_set w.s_pos i i;
    let q = 6 * (lo - w.p_lo + i) in
    fset sc (3 * i) (cen pb q 0);
    fset sc ((3 * i) + 1) (cen pb q 1);
    fset sc ((3 * i) + 2) (cen pb q 2)
  done;
  for axis = 0 to 2 do
    let base = small * axis in
    for i = 0 to n - 1 do
      let x = fget sc ((3 * i) + axis) in
      let j = ref i in
      while !j > 0 && fget key (!j - 1) > x do
        fset key !j (fget key (!j - 1));
        Array.unsafe_set ss (base + !j) (Array.unsafe_get ss (base + !j - 1));
        decr j
      done;
      fset key !j x;
      Array.unsafe_set ss (base + !j) i
    done;
    fset c (coff + axis) (fget key 0);
    fset c (coff + 3 + axis) (fget key (n - 1))
  done

(* [best_split] for the small node at positions [a, b), with the same answer, along its
   widest centroid axis ({!widest}): along an axis its primitives in centroid order are
   in bin order, and the cost is evaluated only between two occupied bins. A split among empty bins has the cost of the split just
   after the occupied bin below it, and sends the same primitives to each side, so the
   full sweep keeps that one (the first of equal costs). The axis goes in [split], the
   size of the left side in [split.(1)] (its first in that axis's order), the sides'
   boxes in [s_best] and the cost in [cost]. *)
let small_split w a b split =
  let n = b - a and cb = w.cbox in
  let pb = w.pbox and sc = w.s_cen and ss = w.s_sorted and bin = w.s_bin in
  let q0 = 6 * (w.s_lo - w.p_lo) in
  let sa = w.s_area and rb = w.s_rbox and best = w.s_best in
  let best_cost = ref Float.infinity in
  split.(0) <- -1;
  let axis = widest cb 0 in
  if axis >= 0 then (
    let cmin = fget cb axis in
    let ext = fget cb (3 + axis) -. cmin in
    let scale = Float.of_int bins /. ext in
    let base = (small * axis) + a in
    for j = 0 to n - 1 do
      let c = fget sc ((3 * Array.unsafe_get ss (base + j)) + axis) in
      Array.unsafe_set bin j (bin_of cmin scale c)
    done;
    (* sa.(j) and rb at j: the area and box of ranks j..n−1, where j starts a bin. *)
    let x0 = ref Float.infinity and y0 = ref Float.infinity and z0 = ref Float.infinity in
    let x1 = ref Float.neg_infinity
    and y1 = ref Float.neg_infinity
    and z1 = ref Float.neg_infinity in
    for j = n - 1 downto 1 do
      let q = q0 + (6 * Array.unsafe_get ss (base + j)) in
      let v0 = fget pb q and v1 = fget pb (q + 1) and v2 = fget pb (q + 2) in
      let v3 = fget pb (q + 3) and v4 = fget pb (q + 4) and v5 = fget pb (q + 5) in
      if not (!x0 < v0) then x0 := v0;
      if not (!y0 < v1) then y0 := v1;
      if not (!z0 < v2) then z0 := v2;
      if not (!x1 > v3) then x1 := v3;
      if not (!y1 > v4) then y1 := v4;
      if not (!z1 > v5) then z1 := v5;
      if Array.unsafe_get bin j <> Array.unsafe_get bin (j - 1) then (
        fset sa j (area6 !x0 !y0 !z0 !x1 !y1 !z1);
        let r = 6 * j in
        fset rb r !x0;
        fset rb (r + 1) !y0;
        fset rb (r + 2) !z0;
        fset rb (r + 3) !x1;
        fset rb (r + 4) !y1;
        fset rb (r + 5) !z1)
    done;
    let x0 = ref Float.infinity and y0 = ref Float.infinity and z0 = ref Float.infinity in
    let x1 = ref Float.neg_infinity
    and y1 = ref Float.neg_infinity
    and z1 = ref Float.neg_infinity in
    for j = 0 to n - 2 do
      let q = q0 + (6 * Array.unsafe_get ss (base + j)) in
      let v0 = fget pb q and v1 = fget pb (q + 1) and v2 = fget pb (q + 2) in
      let v3 = fget pb (q + 3) and v4 = fget pb (q + 4) and v5 = fget pb (q + 5) in
      if not (!x0 < v0) then x0 := v0;
      if not (!y0 < v1) then y0 := v1;
      if not (!z0 < v2) then z0 := v2;
      if not (!x1 > v3) then x1 := v3;
      if not (!y1 > v4) then y1 := v4;
      if not (!z1 > v5) then z1 := v5;
      if Array.unsafe_get bin j <> Array.unsafe_get bin (j + 1) then
        let cost =
          (area6 !x0 !y0 !z0 !x1 !y1 !z1 *. Float.of_int (j + 1))
          +. (fget sa (j + 1) *. Float.of_int (n - j - 1))
        in
        if cost < !best_cost then (
          best_cost := cost;
          split.(0) <- axis;
          split.(1) <- j + 1;
          fset best 0 !x0;
          fset best 1 !y0;
          fset best 2 !z0;
          fset best 3 !x1;
          fset best 4 !y1;
          fset best 5 !z1;
          let r = 6 * (j + 1) in
          for k = 0 to 5 do
            fset best (6 + k) (fget rb (r + k))
          done)
    done);
  fset w.cost 0 !best_cost

(* Split each axis's list of the node at [a, b) by [s_left], keeping its order: the left
   side's first, from [a], the right's after them. Not that of [axis], split already,
   nor those of axes along which the node's centroids coincide. *)
let small_split_lists w a b axis =
  let ss = w.s_sorted and left = w.s_left and tmp = w.s_tmp and cb = w.cbox in
  for t = 0 to 2 do
    if t <> axis && fget cb (3 + t) > fget cb t then (
      let base = small * t in
      let k = ref (base + a) and r = ref 0 in
      for p = base + a to base + b - 1 do
        let id = Array.unsafe_get ss p in
        if Bytes.unsafe_get left id = '\001' then (
          Array.unsafe_set ss !k id;
          incr k)
        else (
          Array.unsafe_set tmp !r id;
          incr r)
      done;
      for p = 0 to !r - 1 do
        Array.unsafe_set ss (!k + p) (Array.unsafe_get tmp p)
      done)
  done

(* Swap the positions of the node at [a, b) as [ids] are partitioned by [s_left], as
   [partition_binned] does: the first from the left that belongs to the right with the
   first from the right that belongs to the left. *)
let small_swap w a b =
  let pos = w.s_pos and left = w.s_left in
  let i = ref a and j = ref (b - 1) in
  while !i <= !j do
    while !i <= !j && Bytes.unsafe_get left (Array.unsafe_get pos !i) = '\001' do
      incr i
    done;
    while !i <= !j && Bytes.unsafe_get left (Array.unsafe_get pos !j) <> '\001' do
      decr j
    done;
    if !i < !j then (
      let id = Array.unsafe_get pos !i in
      Array.unsafe_set pos !i (Array.unsafe_get pos !j);
      Array.unsafe_set pos !j id;
      incr i;
      decr j)
  done

(* The centroid bounds of the node whose lists are at [a, b), into [dst] at [doff]: the
   first and last of each axis's order. *)
let small_cen_bounds w a b dst doff =
  let ss = w.s_sorted and sc = w.s_cen in
  for axis = 0 to 2 do
    let base = small * axis in
    fset dst (doff + axis) (fget sc ((3 * Array.unsafe_get ss (base + a)) + axis));
    fset dst (doff + 3 + axis) (fget sc ((3 * Array.unsafe_get ss (base + b - 1)) + axis))
  done

(* Partition the node at [a, b) by the split [small_split] found along [axis], whose left
   side is the first [k] of that axis's order; the children's bounds go at [loff] in [dl]
   and at [roff] in [dr]. The middle position. *)
let small_partition w a b axis k dl loff dr roff =
  let ss = w.s_sorted and left = w.s_left in
  let base = small * axis in
  for p = base + a to base + a + k - 1 do
    Bytes.unsafe_set left (Array.unsafe_get ss p) '\001'
  done;
  for p = base + a + k to base + b - 1 do
    Bytes.unsafe_set left (Array.unsafe_get ss p) '\000'
  done;
  small_swap w a b;
  small_split_lists w a b axis;
  let best = w.s_best in
  for k = 0 to 5 do
    fset dl (loff + k) (fget best k);
    fset dr (roff + k) (fget best (6 + k))
  done;
  small_cen_bounds w a (a + k) dl (loff + 6);
  small_cen_bounds w (a + k) b dr (roff + 6);
  a + k

(* The box of the positions [a, b), into [dst] at [doff]. *)
let small_box w a b dst doff =
  let pos = w.s_pos and pb = w.pbox and q0 = 6 * (w.s_lo - w.p_lo) in
  let x0 = ref Float.infinity and y0 = ref Float.infinity and z0 = ref Float.infinity in
  let x1 = ref Float.neg_infinity
  and y1 = ref Float.neg_infinity
  and z1 = ref Float.neg_infinity in
  for i = a to b - 1 do
    let q = q0 + (6 * Array.unsafe_get pos i) in
    let v0 = fget pb q and v1 = fget pb (q + 1) and v2 = fget pb (q + 2) in
    let v3 = fget pb (q + 3) and v4 = fget pb (q + 4) and v5 = fget pb (q + 5) in
    if not (!x0 < v0) then x0 := v0;
    if not (!y0 < v1) then y0 := v1;
    if not (!z0 < v2) then z0 := v2;
    if not (!x1 > v3) then x1 := v3;
    if not (!y1 > v4) then y1 := v4;
    if not (!z1 > v5) then z1 := v5
  done;
  fset dst doff !x0;
  fset dst (doff + 1) !y0;
  fset dst (doff + 2) !z0;
  fset dst (doff + 3) !x1;
  fset dst (doff + 4) !y1;
  fset dst (doff + 5) !z1

(* Split the node at [a, b) into its halves by position, when no split divides it; the
   children's bounds as in [small_partition]. The middle position. *)
let small_halves w a b dl loff dr roff =
  let pos = w.s_pos and left = w.s_left in
  let mid = a + ((b - a) / 2) in
  for p = a to b - 1 do
    Bytes.unsafe_set left (Array.unsafe_get pos p) (if p < mid then '\001' else '\000')
  done;
  small_split_lists w a b (-1);
  small_box w a mid dl loff;
  small_box w mid b dr roff;
  small_cen_bounds w a mid dl (loff + 6);
  small_cen_bounds w mid b dr (roff + 6);
  mid

(* [Float.Array.blit] for the few floats of a node's bounds, without its checks. *)
let[@inline] copy src soff dst doff n =
  for k = 0 to n - 1 do
    fset dst (doff + k) (fget src (soff + k))
  done

(* Whether every item at the positions [a, b) of the small subtree is flagged cheap. *)
let all_cheap w a b =
  let ok = ref true and p = ref a in
  while !ok && !p < b do
    let id = Array.unsafe_get w.ids (w.s_lo + Array.unsafe_get w.s_pos !p) in
    if Bytes.unsafe_get w.cheap id <> '\001' then ok := false;
    incr p
  done;
  !ok

(* The node over the positions [a, b) of the small subtree, whose bounds are at [pend]
   for [depth]: [build_node]'s, with [small_split] and [small_partition]. *)
let rec build_small w split a b depth =
  let node = new_node w in
  if depth > w.max_depth then w.max_depth <- depth;
  reserve w depth;
  let off = 8 * node and here = 12 * depth in
  let pend = w.pend in
  copy pend here w.nodes_b off 6;
  copy pend (here + 6) w.cbox 0 6;
  let n = b - a in
  let below = here + 12 in
  let mid =
    if n <= 2 || (n <= w.cheap_max && all_cheap w a b) then -1
    else (
      small_split w a b split;
      let best_cost = fget w.cost 0 in
      let node_area = area w.nodes_b off in
      (* Cost model: one box test per child against one intersection per primitive. *)
      let leaf_cost = Float.of_int n *. node_area in
      if split.(0) < 0 then
        if n <= max_leaf then -1 else small_halves w a b pend below w.pend_right here
      else if n <= max_leaf && leaf_cost <= node_area +. best_cost then -1
      else
        (* Both sides of a split the search found have primitives. *)
        small_partition w a b split.(0) split.(1) pend below w.pend_right here)
  in
  if mid < 0 then (
    fset w.nodes_b (off + 6) (Float.of_int (w.s_lo + a));
    fset w.nodes_b (off + 7) (Float.of_int n))
  else (
    ignore (build_small w split a mid (depth + 1));
    (* The left subtree may have grown the scratch: read it again. *)
    copy w.pend_right here w.pend below 12;
    let right = build_small w split mid b (depth + 1) in
    (* The node arrays may have moved while the subtrees were built. *)
    fset w.nodes_b (off + 6) (Float.of_int right);
    fset w.nodes_b (off + 7) 0.);
  node

(* The small subtree over ids[lo, hi): its primitives in their final order at the end. *)
let build_small_root w split lo hi depth =
  let n = hi - lo in
  if n <= 2 then (
    w.s_lo <- lo;
    build_small w split 0 n depth)
  else (
    small_setup w lo n w.pend ((12 * depth) + 6);
    let node = build_small w split 0 n depth in
    let ids = w.ids and tmp = w.s_tmp and pos = w.s_pos in
    for p = 0 to n - 1 do
      Array.unsafe_set tmp p (Array.unsafe_get ids (lo + p))
    done;
    for p = 0 to n - 1 do
      Array.unsafe_set ids (lo + p) (Array.unsafe_get tmp (Array.unsafe_get pos p))
    done;
    node)

(* The node over ids[lo, hi), whose bounds are at [pend] for [depth]. *)
let rec build_node w split lo hi depth =
  if hi - lo <= small then build_small_root w split lo hi depth
  else build_large w split lo hi depth

(* A node of more than [small] > [max_leaf] primitives: never a leaf. *)
and build_large w split lo hi depth =
  let node = new_node w in
  if depth > w.max_depth then w.max_depth <- depth;
  reserve w depth;
  reserve_bins w depth;
  let off = 8 * node and here = 12 * depth in
  let pend = w.pend in
  copy pend here w.nodes_b off 6;
  copy pend here w.cbox 0 6;
  let n = hi - lo in
  let below = here + 12 in
  best_split w lo hi depth split;
  let mid =
    let mid = if split.(0) < 0 then lo else partition_binned w lo hi depth split.(1) in
    if mid = lo || mid = hi then (
      unbinned w depth;
      bound_range w lo (lo + (n / 2)) pend below;
      bound_range w (lo + (n / 2)) hi w.pend_right here;
      lo + (n / 2))
    else mid
  in
  ignore (build_node w split lo mid (depth + 1));
  (* The left subtree may have grown the scratch: read it again. *)
  copy w.pend_right here w.pend below 12;
  let io = slot_i * depth in
  let axis = w.pcount_right.(io) in
  w.pcount.(io + slot_i) <- axis;
  if axis >= 0 then (
    Array.blit w.pcount_right io w.pcount (io + slot_i) slot_i;
    (* The right child's bins become those at depth + 1, whose slot is free now. *)
    let free = w.pbins.(depth + 1) in
    w.pbins.(depth + 1) <- w.pbins_right.(depth);
    w.pbins_right.(depth) <- free);
  let right = build_node w split mid hi (depth + 1) in
  (* The node arrays may have moved while the subtrees were built. *)
  fset w.nodes_b (off + 6) (Float.of_int right);
  fset w.nodes_b (off + 7) 0.;
  node

(* The box min (x0, y0, z0), max (x1, y1, z1) padded by a relative 1e-9 of its
   magnitude, as item [k] of [pb]: rounding in the slab test then never culls an item
   whose hit lies on its own bounds. *)
let[@inline] pad_into pb k x0 y0 z0 x1 y1 z1 =
  let m =
    Floats.max
      (Floats.max (Float.abs x0) (Floats.max (Float.abs y0) (Float.abs z0)))
      (Floats.max (Float.abs x1) (Floats.max (Float.abs y1) (Float.abs z1)))
  in
  let e = (1e-9 *. m) +. 1e-300 in
  let q = 6 * k in
  fset pb q (x0 -. e);
  fset pb (q + 1) (y0 -. e);
  fset pb (q + 2) (z0 -. e);
  fset pb (q + 3) (x1 +. e);
  fset pb (q + 4) (y1 +. e);
  fset pb (q + 5) (z1 +. e)

type t = {
  nodes : Float.Array.t;
      (** 8 per node, one cache line: min x y z, max x y z (padded), then a leaf's (first,
          count > 0) into [order], an interior node's (right child, 0), its left child
          being the next node; the two integers are stored as floats (exact) *)
  order : int array;  (** the items in leaf order *)
  depth : int;  (** the tree's depth: an upper bound on the traversal stack *)
}

let widths pbox =
  let ext = Float.Array.make 3 0. in
  for k = 0 to (Float.Array.length pbox / 6) - 1 do
    for a = 0 to 2 do
      let e = fget pbox ((6 * k) + 3 + a) -. fget pbox ((6 * k) + a) in
      if e > fget ext a then fset ext a e
    done
  done;
  ext

(* --- Large builds ----------------------------------------------------------------- *)

(* From [large] items (a million spheres, a mesh of a million triangles), the nodes of
   more than [small] items are not searched. The binned search reads every item at every
   level of a large node, some twenty times in all over a million; this reads each a few
   times.

   - The items are sorted once along a Morton curve (z-order) over their centroids, on a
     grid of cubic cells over the centroids' bounds ([morton_keys]).
   - A node splits its range of that order where the highest bit in which its codes
     differ changes: a spatial median, halving cells. Where they are all equal, at its
     middle ([morton_split]).
   - The small subtrees below are searched as before, each over a copy of its own boxes;
     one whose items are all cheap is cut the same way down to leaves of at most
     [cheap_max], as those leaves are made without a search anyway.
   - An item wider than a [wide]th of the centroids' extent (a floor under small
     objects) would widen every box above it down to its leaf, and every ray would visit
     those boxes. Such items are set apart: the root's left subtree is theirs, built by the
     search; its right subtree holds the others in Morton order.

   What it costs and saves ([doc/explanation/speed.md], against the same build with
   [large] set to [max_int]): the million coloured spheres of [make bench-limit] reach
   their first pixel at 64×48 in 5.79 G instructions rather than 7.63 G, the
   million-triangle torus (shaded flat) in 3.68 G rather than 5.29 G, with its walk 10 %
   dearer at 480×360 (the walk of the spheres is the same). Over 300 000 spheres on a
   floor box, the walk is 37 % cheaper than the search's tree, which keeps the floor
   lower down. Below [large] the search's build is a small part of a render (about 0.2 G
   of [field_100000]'s 7.4 G instructions at 1920×1080), and a mesh's walk, 10 % dearer
   in Morton order, would cost more over a picture than the search's build saves. The
   sort's keys are an array of m integers beside [ids] while the tree is built: 8 MB
   over a million items. *)
let wide = 64.

(* The bits of a cell along one axis: 1024 cells a side, a code of 30 bits. *)
let cell_bits = 10

(* Each cell's bits moved to every third bit, looked up rather than computed. *)
let spread =
  Array.init (1 lsl cell_bits) (fun x ->
      let r = ref 0 in
      for k = 0 to cell_bits - 1 do
        r := !r lor (((x lsr k) land 1) lsl (3 * k))
      done;
      !r)

(* The cell of coordinate [v] from [lo] at [scale] cells a unit, in [0, top]. *)
let[@inline] cell v lo scale top =
  let k = int_of_float ((v -. lo) *. scale) in
  if k < 0 then 0 else if k > top then top else k

let rec bits_for n = if n <= 1 then 1 else 1 + bits_for (n lsr 1)

(* The bits a radix pass sorts by. *)
let digit = 10

(* The Morton order of the items that are not wide: the wide ones' indices into
   [w.ids] from 0, in order, and the others' keys, sorted: (keys, ib, count of wide),
   each key the item's code over [3·cell_bits] bits above its index over [ib] bits
   (62 bits in all up to 2^32 items, far more than memory holds). [w.ids] beyond the
   wide ones is the sort's second buffer. *)
let morton_keys w m =
  let pb = w.pbox in
  let ib = bits_for (m - 1) and b = cell_bits in
  if ib + (3 * b) > 62 then invalid_arg "Bvh.build: too many items for a Morton key";
  let x0 = ref Float.infinity and y0 = ref Float.infinity and z0 = ref Float.infinity in
  let x1 = ref Float.neg_infinity
  and y1 = ref Float.neg_infinity
  and z1 = ref Float.neg_infinity in
  for i = 0 to m - 1 do
    let q = 6 * i in
    let cx = cen pb q 0 and cy = cen pb q 1 and cz = cen pb q 2 in
    if not (!x0 < cx) then x0 := cx;
    if not (!y0 < cy) then y0 := cy;
    if not (!z0 < cz) then z0 := cz;
    if not (!x1 > cx) then x1 := cx;
    if not (!y1 > cy) then y1 := cy;
    if not (!z1 > cz) then z1 := cz
  done;
  let ext = fmax (!x1 -. !x0) (fmax (!y1 -. !y0) (!z1 -. !z0)) in
  let limit = ext /. wide in
  (* Whether each item is wide, in [tag] by item until the search of the wide ones uses
     it. *)
  let ids = w.ids and tag = w.tag and nw = ref 0 in
  for i = 0 to m - 1 do
    let q = 6 * i in
    if
      fget pb (q + 3) -. fget pb q > limit
      || fget pb (q + 4) -. fget pb (q + 1) > limit
      || fget pb (q + 5) -. fget pb (q + 2) > limit
    then (
      Bytes.unsafe_set tag i '\001';
      Array.unsafe_set ids !nw i;
      incr nw)
    else Bytes.unsafe_set tag i '\000'
  done;
  let nw = !nw and top = (1 lsl b) - 1 in
  let scale = if ext > 0. then Float.of_int (1 lsl b) /. ext else 0. in
  let cx0 = !x0 and cy0 = !y0 and cz0 = !z0 in
  let n = m - nw in
  let keys = Array.make n 0 and j = ref 0 in
  for i = 0 to m - 1 do
    let q = 6 * i in
    if Bytes.unsafe_get tag i = '\000' then (
      let code =
        (Array.unsafe_get spread (cell (cen pb q 0) cx0 scale top) lsl 2)
        lor (Array.unsafe_get spread (cell (cen pb q 1) cy0 scale top) lsl 1)
        lor Array.unsafe_get spread (cell (cen pb q 2) cz0 scale top)
      in
      Array.unsafe_set keys !j ((code lsl ib) lor i);
      incr j)
  done;
  (* Least significant digit first, over the code's bits only: the indices below them
     are in order already, and every pass is stable. One read counts every pass's
     digits; a pass whose digit is the same for every key is skipped. The second buffer
     is [ids] past the wide items. *)
  let passes = ((3 * b) + digit - 1) / digit and mask = (1 lsl digit) - 1 in
  let count = Array.make (passes lsl digit) 0 in
  for i = 0 to n - 1 do
    let v = Array.unsafe_get keys i lsr ib in
    for d = 0 to passes - 1 do
      let k = (d lsl digit) + ((v lsr (d * digit)) land mask) in
      Array.unsafe_set count k (Array.unsafe_get count k + 1)
    done
  done;
  let src = ref keys and dst = ref ids and soff = ref 0 and doff = ref nw in
  for d = 0 to passes - 1 do
    let s = ib + (d * digit) and a = !src and dd = !dst and ao = !soff and dof = !doff in
    let c0 = d lsl digit in
    if
      n > 0 && Array.unsafe_get count (c0 + ((Array.unsafe_get a ao lsr s) land mask)) < n
    then (
      let sum = ref dof in
      for k = c0 to c0 + mask do
        let c = Array.unsafe_get count k in
        Array.unsafe_set count k !sum;
        sum := !sum + c
      done;
      for i = ao to ao + n - 1 do
        let v = Array.unsafe_get a i in
        let k = c0 + ((v lsr s) land mask) in
        let p = Array.unsafe_get count k in
        Array.unsafe_set dd p v;
        Array.unsafe_set count k (p + 1)
      done;
      src := dd;
      dst := a;
      soff := dof;
      doff := ao)
  done;
  if !src != keys then Array.blit !src !soff keys 0 n;
  (keys, ib, nw)

(* Where the positions [lo, hi) split, their keys sorted in [keys] from position [ko]:
   the first position whose code has the highest bit in which the range's first and last
   codes differ, or the middle where they are equal. *)
let morton_split keys ko ib lo hi =
  let a = Array.unsafe_get keys (lo - ko) lsr ib
  and z = Array.unsafe_get keys (hi - 1 - ko) lsr ib in
  if a = z then lo + ((hi - lo) / 2)
  else
    let d = a lxor z and h = ref 0 in
    while d lsr (!h + 1) > 0 do
      incr h
    done;
    let bit = 1 lsl !h in
    let l = ref (lo + 1) and r = ref (hi - 1) in
    while !l < !r do
      let mid = (!l + !r) / 2 in
      if (Array.unsafe_get keys (mid - ko) lsr ib) land bit <> 0 then r := mid
      else l := mid + 1
    done;
    !l

(* The box of node [node] is its children's, [node + 1] and [right]: min and max are
   exact, so it is the box of their items. *)
let join w node right =
  let nb = w.nodes_b in
  let off = 8 * node and l = 8 * (node + 1) and r = 8 * right in
  for k = 0 to 2 do
    fset nb (off + k) (fmin (fget nb (l + k)) (fget nb (r + k)));
    fset nb (off + 3 + k) (fmax (fget nb (l + 3 + k)) (fget nb (r + 3 + k)))
  done;
  fset nb (off + 6) (Float.of_int right);
  fset nb (off + 7) 0.

(* The node over the positions [lo, hi) of the Morton order. [pb] holds the boxes by
   item; a small subtree's are copied into [w.pbox] (room for [small]) from [lo] on. *)
let rec build_morton w split pb keys ko ib lo hi depth =
  if hi - lo <= small then (
    if cheap_range w lo hi then cheap_morton w pb keys ko ib lo hi depth
    else
      let ids = w.ids and sb = w.pbox in
      for p = lo to hi - 1 do
        let q = 6 * Array.unsafe_get ids p and r = 6 * (p - lo) in
        box_set sb r (fget pb q)
          (fget pb (q + 1))
          (fget pb (q + 2))
          (fget pb (q + 3))
          (fget pb (q + 4))
          (fget pb (q + 5))
      done;
      w.p_lo <- lo;
      reserve w depth;
      bound_range w 0 (hi - lo) w.pend (12 * depth);
      build_small_root w split lo hi depth)
  else
    let node = new_node w in
    if depth > w.max_depth then w.max_depth <- depth;
    let mid = morton_split keys ko ib lo hi in
    ignore (build_morton w split pb keys ko ib lo mid (depth + 1));
    let right = build_morton w split pb keys ko ib mid hi (depth + 1) in
    join w node right;
    node

(* Whether every item at the positions [lo, hi) is cheap (none is where none is
   flagged). *)
and cheap_range w lo hi =
  w.cheap_max > 0
  && Bytes.length w.cheap > 0
  &&
  let ok = ref true and p = ref lo in
  while !ok && !p < hi do
    if Bytes.unsafe_get w.cheap (Array.unsafe_get w.ids !p) <> '\001' then ok := false;
    incr p
  done;
  !ok

(* A range of cheap items: cut in Morton order down to leaves of at most [cheap_max],
   with nothing searched (a leaf of them costs less to test than a search would save). *)
and cheap_morton w pb keys ko ib lo hi depth =
  let node = new_node w in
  if depth > w.max_depth then w.max_depth <- depth;
  (if hi - lo <= w.cheap_max then (
     let x0 = ref Float.infinity
     and y0 = ref Float.infinity
     and z0 = ref Float.infinity in
     let x1 = ref Float.neg_infinity
     and y1 = ref Float.neg_infinity
     and z1 = ref Float.neg_infinity in
     for p = lo to hi - 1 do
       let q = 6 * Array.unsafe_get w.ids p in
       x0 := fmin !x0 (fget pb q);
       y0 := fmin !y0 (fget pb (q + 1));
       z0 := fmin !z0 (fget pb (q + 2));
       x1 := fmax !x1 (fget pb (q + 3));
       y1 := fmax !y1 (fget pb (q + 4));
       z1 := fmax !z1 (fget pb (q + 5))
     done;
     let off = 8 * node in
     box_set w.nodes_b off !x0 !y0 !z0 !x1 !y1 !z1;
     fset w.nodes_b (off + 6) (Float.of_int lo);
     fset w.nodes_b (off + 7) (Float.of_int (hi - lo)))
   else
     let mid = morton_split keys ko ib lo hi in
     ignore (cheap_morton w pb keys ko ib lo mid (depth + 1));
     let right = cheap_morton w pb keys ko ib mid hi (depth + 1) in
     join w node right);
  node

(* The tree over [m] items: the wide ones first, searched over a copy of their boxes,
   the others in Morton order after them. [pbox] is left as it was. *)
let build_large_morton w m =
  let pb = w.pbox and split = [| -1; 0 |] in
  let keys, ib, nw = morton_keys w m in
  let mask = (1 lsl ib) - 1 and ids = w.ids in
  for p = nw to m - 1 do
    Array.unsafe_set ids p (Array.unsafe_get keys (p - nw) land mask)
  done;
  (* The wide items' boxes, in their order, for the search to move. *)
  let wide_boxes () =
    w.ext <- widths pb;
    let wb = Float.Array.create (6 * nw) in
    for p = 0 to nw - 1 do
      Float.Array.blit pb (6 * Array.unsafe_get ids p) wb (6 * p) 6
    done;
    w.pbox <- wb;
    w.p_lo <- 0
  in
  let scratch = Float.Array.create (6 * small) in
  (if nw = m then (
     wide_boxes ();
     bound_range w 0 m w.pend 12;
     ignore (build_node w split 0 m 1))
   else if nw = 0 then (
     w.pbox <- scratch;
     ignore (build_morton w split pb keys 0 ib 0 m 1))
   else
     let root = new_node w in
     w.max_depth <- 1;
     wide_boxes ();
     reserve w 2;
     bound_range w 0 nw w.pend 24;
     ignore (build_node w split 0 nw 2);
     w.pbox <- scratch;
     let right = build_morton w split pb keys nw ib nw m 2 in
     join w root right);
  w.pbox <- pb;
  w.p_lo <- 0

let large = 1 lsl 18

let build ?(cheap = (Bytes.empty, 0)) ?(large = large) pbox =
  let cheap, cheap_max = cheap in
  if Bytes.length cheap > 0 && Bytes.length cheap <> Float.Array.length pbox / 6 then
    invalid_arg "Bvh.build: cheap does not flag every item";
  let m = Float.Array.length pbox / 6 in
  let morton = m >= large in
  (* A tree of m items has at most 2m − 1 nodes; with leaves of one or two, as the cost
     model makes them, a little more than m: m/8 more from the search, about m/7 in
     Morton order (1 128 507 nodes over the million triangles of a torus, 1 111 159 from
     the search), for which m/6 is room. Where every item is cheap, leaves hold up to
     [cheap_max] of them: about 2m/cheap_max nodes (262 143 over a million spheres,
     leaves of 8). The array grows if it must, but that copy is at the peak of memory. *)
  let all_cheap =
    cheap_max > 1 && Bytes.length cheap = m && not (Bytes.contains cheap '\000')
  in
  let cap =
    (if all_cheap then 2 * m / cheap_max else m) + (if morton then m / 6 else m / 8) + 16
  in
  let w =
    {
      pbox;
      p_lo = 0;
      ids = Array.init m Fun.id;
      tag = Bytes.create m;
      nodes_b = Float.Array.create (8 * cap);
      count = 0;
      max_depth = 0;
      cheap;
      cheap_max;
      right_area = Float.Array.make bins 0.;
      right_n = Array.make bins 0;
      cbox = Float.Array.create 6;
      cen12 = Float.Array.create 12;
      ext = (if morton then Float.Array.create 0 else widths pbox);
      cost = Float.Array.create 1;
      pend = Float.Array.create (12 * 64);
      pend_right = Float.Array.create (12 * 64);
      pbins = [||];
      pbins_right = [||];
      pcount = Array.make (slot_i * 64) (-1);
      pcount_right = Array.make (slot_i * 64) (-1);
      s_lo = 0;
      s_cen = Float.Array.make (3 * small) 0.;
      s_pos = Array.make small 0;
      s_sorted = Array.make (3 * small) 0;
      s_tmp = Array.make small 0;
      s_key = Float.Array.make small 0.;
      s_left = Bytes.make small '\000';
      s_bin = Array.make small 0;
      s_area = Float.Array.make small 0.;
      s_rbox = Float.Array.make (6 * small) 0.;
      s_best = Float.Array.make 12 0.;
    }
  in
  if morton then build_large_morton w m
  else (
    bound_range w 0 m w.pend 12;
    ignore (build_node w [| -1; 0 |] 0 m 1));
  (* The node arrays as they are when little of them is unused, rather than a copy
     beside them at the peak of memory. *)
  let nodes =
    if 8 * w.count >= 7 * (Float.Array.length w.nodes_b / 8) then w.nodes_b
    else Float.Array.sub w.nodes_b 0 (8 * w.count)
  in
  { nodes; order = w.ids; depth = w.max_depth }

(* Node [k]'s two integers: a leaf's first slot and its count (> 0), an interior node's
   right child and 0. *)
let[@inline] link nodes k = int_of_float (fget nodes ((8 * k) + 6))
let[@inline] count nodes k = int_of_float (fget nodes ((8 * k) + 7))

(* --- Walks ------------------------------------------------------------------------ *)

(* A depth-first walk's stack, kept from one query to the next: the nodes still to visit
   in [ids] with their entry t in [ts], their count [sp] between two descents, and the
   interval [span] (tmin, then tmax or the best t so far) the descents cull boxes by,
   which the walk sets. The descent in C reads and writes these fields by their position:
   keep their order. *)
type walk = {
  mutable ids : int array;
  mutable ts : Float.Array.t;
  mutable sp : int;
  span : Float.Array.t;
}

let new_walk () =
  { ids = [||]; ts = Float.Array.create 0; sp = 0; span = Float.Array.create 2 }

(* [w] made ready for a tree of depth [depth]. *)
let[@inline] ready w depth =
  if Array.length w.ids <= depth then (
    w.ids <- Array.make (depth + 1) 0;
    w.ts <- Float.Array.create (depth + 1))

(* The descent of every walk, in C ([descent_stubs.c], which says why): from the top of
   the stack, past the entries whose entry t is beyond [span]'s second, to the next leaf
   (−1: none is left). It allocates nothing and calls nothing back. *)
external next_leaf : Float.Array.t -> Probe.t -> walk -> (int[@untagged])
  = "lancer_next_leaf_byte" "lancer_next_leaf"
[@@noalloc]

(* The same from an empty stack, beginning at the root if the ray enters its box within
   [span]. *)
external first_leaf : Float.Array.t -> Probe.t -> walk -> (int[@untagged])
  = "lancer_first_leaf_byte" "lancer_first_leaf"
[@@noalloc]

(* A walk begun over [tmin, tmax]: its first leaf. *)
let[@inline] start nodes q w tmin tmax =
  fset w.span 0 tmin;
  fset w.span 1 tmax;
  first_leaf nodes q w
