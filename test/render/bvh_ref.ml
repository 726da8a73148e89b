(* The reference for Bvh.build: the binned-SAH build in its first form, each node binned
   in one pass and partitioned in another, the children's bounds from the partition. The
   test compares the two trees bit for bit. *)

let fget = Float.Array.unsafe_get
let fset = Float.Array.unsafe_set
let max_leaf = 8
let bins = 16
let small = 16
(* --- Construction ----------------------------------------------------------------- *)

(* The build allocates nothing per primitive or per node beyond its arrays: per-primitive
   data is one Float.Array of padded bounds (centroids are their midpoints), moved with
   the primitives' order as nodes are partitioned, nodes are written
   into arrays grown by half, and the binning scratch is reused at every node. Floats
   stay in local mutable variables and inlined functions, so that none is boxed. *)
type work = {
  pbox : Float.Array.t;
      (** 6 per primitive: padded min x y z, max x y z, in the order of [ids], so that
          every pass over a node reads memory in sequence *)
  ids : int array;  (** a permutation of 0..m−1, partitioned in place *)
  mutable nodes_b : Float.Array.t;  (** 8 per node (see [t]) *)
  mutable count : int;
  mutable max_depth : int;
  (* Bin scratch, reused at every node: counts and bounds per bin, the areas and counts
     of the bins from b to the last, and the node's centroid bounds. *)
  bin_n : int array;
  bin_b : Float.Array.t;
  right_area : Float.Array.t;
  right_n : int array;
  cbox : Float.Array.t;
  mutable pend : Float.Array.t;
  mutable pend_right : Float.Array.t;
  (* Small nodes: each primitive's bin, the primitives (3 × index) sorted by bin, and the
     area of the boxes from each position to the last. *)
  small_bin : int array;
  small_p : int array;
  small_area : Float.Array.t;
  cheap : Bytes.t;  (** by item: whether it may end a split search (see [cheap_max]) *)
  cheap_max : int;  (** a node of at most this many cheap items is a leaf *)
  ext : Float.Array.t;  (** the largest extent of an item along each axis (Bvh.widths) *)
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

(* Typed comparisons rather than Float.min/max: the bounds are finite (checked at
   entry), and Float.min's NaN and signed-zero handling costs a C call per use. *)
let[@inline] fmin (a : float) b = if a < b then a else b
let[@inline] fmax (a : float) b = if a > b then a else b

(* Surface area of the box stored at [off] in [a] (6 floats), 0 when empty. *)
let[@inline] area a off =
  let dx = fget a (off + 3) -. fget a off
  and dy = fget a (off + 4) -. fget a (off + 1)
  and dz = fget a (off + 5) -. fget a (off + 2) in
  if dx < 0. || dy < 0. || dz < 0. then 0.
  else 2. *. ((dx *. dy) +. (dy *. dz) +. (dz *. dx))

let box_empty a off =
  for k = 0 to 2 do
    fset a (off + k) Float.infinity;
    fset a (off + 3 + k) Float.neg_infinity
  done

let box_merge a off b boff =
  for k = 0 to 2 do
    fset a (off + k) (fmin (fget a (off + k)) (fget b (boff + k)));
    fset a (off + 3 + k) (fmax (fget a (off + 3 + k)) (fget b (boff + 3 + k)))
  done

(* The centroid's coordinate [k] of the padded box at [q] in [pb]. *)
let[@inline] cen pb q k = 0.5 *. (fget pb (q + k) +. fget pb (q + 3 + k))

let[@inline] bin_of cmin scale c =
  let b = int_of_float ((c -. cmin) *. scale) in
  if b < 0 then 0 else if b >= bins then bins - 1 else b

(* Add the primitive at [q] (3 × index) to bin [b] of the bin scratch. *)
let[@inline] bin_add w b q =
  let bin_n = w.bin_n and bb = w.bin_b and pb = w.pbox in
  Array.unsafe_set bin_n b (Array.unsafe_get bin_n b + 1);
  let o = 6 * b in
  fset bb o (fmin (fget bb o) (fget pb q));
  fset bb (o + 1) (fmin (fget bb (o + 1)) (fget pb (q + 1)));
  fset bb (o + 2) (fmin (fget bb (o + 2)) (fget pb (q + 2)));
  fset bb (o + 3) (fmax (fget bb (o + 3)) (fget pb (q + 3)));
  fset bb (o + 4) (fmax (fget bb (o + 4)) (fget pb (q + 4)));
  fset bb (o + 5) (fmax (fget bb (o + 5)) (fget pb (q + 5)))

(* Bin ids[lo, hi) into the bin scratch, in one pass, along each axis k whose [use_k]
   holds (bins k·bins to k·bins + bins − 1): counts and bounds. *)
let bin_axes w lo hi use_x use_y use_z =
  let cb = w.cbox and pb = w.pbox in
  let scale k =
    let e = fget cb (3 + k) -. fget cb k in
    if e > 0. then Float.of_int bins /. e else 0.
  in
  let x0 = fget cb 0 and y0 = fget cb 1 and z0 = fget cb 2 in
  let sx = scale 0 and sy = scale 1 and sz = scale 2 in
  for axis = 0 to 2 do
    if (axis = 0 && use_x) || (axis = 1 && use_y) || (axis = 2 && use_z) then
      for b = axis * bins to (axis * bins) + bins - 1 do
        Array.unsafe_set w.bin_n b 0;
        box_empty w.bin_b (6 * b)
      done
  done;
  for i = lo to hi - 1 do
    let q = 6 * i in
    if use_x then bin_add w (bin_of x0 sx (cen pb q 0)) q;
    if use_y then bin_add w (bins + bin_of y0 sy (cen pb q 1)) q;
    if use_z then bin_add w ((2 * bins) + bin_of z0 sz (cen pb q 2)) q
  done

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
    x0 := fmin !x0 (fget pb q);
    y0 := fmin !y0 (fget pb (q + 1));
    z0 := fmin !z0 (fget pb (q + 2));
    x1 := fmax !x1 (fget pb (q + 3));
    y1 := fmax !y1 (fget pb (q + 4));
    z1 := fmax !z1 (fget pb (q + 5));
    let cx = cen pb q 0 and cy = cen pb q 1 and cz = cen pb q 2 in
    cx0 := fmin !cx0 cx;
    cy0 := fmin !cy0 cy;
    cz0 := fmin !cz0 cz;
    cx1 := fmax !cx1 cx;
    cy1 := fmax !cy1 cy;
    cz1 := fmax !cz1 cz
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

(* Add the box at [q] in [pb] and its centroid to the 12 bounds at [doff] in [dst]. *)
let[@inline] bound_add dst doff pb q =
  fset dst doff (fmin (fget dst doff) (fget pb q));
  fset dst (doff + 1) (fmin (fget dst (doff + 1)) (fget pb (q + 1)));
  fset dst (doff + 2) (fmin (fget dst (doff + 2)) (fget pb (q + 2)));
  fset dst (doff + 3) (fmax (fget dst (doff + 3)) (fget pb (q + 3)));
  fset dst (doff + 4) (fmax (fget dst (doff + 4)) (fget pb (q + 4)));
  fset dst (doff + 5) (fmax (fget dst (doff + 5)) (fget pb (q + 5)));
  let cx = cen pb q 0 and cy = cen pb q 1 and cz = cen pb q 2 in
  fset dst (doff + 6) (fmin (fget dst (doff + 6)) cx);
  fset dst (doff + 7) (fmin (fget dst (doff + 7)) cy);
  fset dst (doff + 8) (fmin (fget dst (doff + 8)) cz);
  fset dst (doff + 9) (fmax (fget dst (doff + 9)) cx);
  fset dst (doff + 10) (fmax (fget dst (doff + 10)) cy);
  fset dst (doff + 11) (fmax (fget dst (doff + 11)) cz)

let bound_empty dst doff =
  box_empty dst doff;
  box_empty dst (doff + 6)

(* [best_split] for a node of at most [small] primitives, with the same answer: the
   primitives sorted by bin, the cost is evaluated only between two occupied bins. A split
   b among empty bins has the cost of the split just after the occupied bin below it, and
   sends the same primitives to each side, so the full sweep keeps that one (the first of
   equal costs); its boxes are unions of the same boxes, which min and max compute exactly
   in any order. Along the node's widest centroid axis only, as [best_split]. *)
let best_split_small w lo hi split =
  let n = hi - lo and cb = w.cbox in
  let sb = w.small_bin and sp = w.small_p and sa = w.small_area in
  let pb = w.pbox in
  let box = w.bin_b in
  let best_cost = ref Float.infinity in
  split.(0) <- -1;
  let e k = fget cb (3 + k) -. fget cb k in
  let widest = if e 0 >= e 1 && e 0 >= e 2 then 0 else if e 1 >= e 2 then 1 else 2 in
  for axis = 0 to 2 do
    let cmin = fget cb axis in
    let ext = fget cb (3 + axis) -. cmin in
    if axis = widest && ext > 0. then (
      let scale = Float.of_int bins /. ext in
      (* Insertion sort by bin. *)
      for i = 0 to n - 1 do
        let q = 6 * (lo + i) in
        let b = bin_of cmin scale (cen pb q axis) in
        let j = ref i in
        while !j > 0 && Array.unsafe_get sb (!j - 1) > b do
          Array.unsafe_set sb !j (Array.unsafe_get sb (!j - 1));
          Array.unsafe_set sp !j (Array.unsafe_get sp (!j - 1));
          decr j
        done;
        Array.unsafe_set sb !j b;
        Array.unsafe_set sp !j q
      done;
      (* sa.(j): the area of the boxes of positions j..n−1, where j starts a bin. *)
      box_empty box 0;
      for j = n - 1 downto 1 do
        let q = Array.unsafe_get sp j in
        fset box 0 (fmin (fget box 0) (fget pb q));
        fset box 1 (fmin (fget box 1) (fget pb (q + 1)));
        fset box 2 (fmin (fget box 2) (fget pb (q + 2)));
        fset box 3 (fmax (fget box 3) (fget pb (q + 3)));
        fset box 4 (fmax (fget box 4) (fget pb (q + 4)));
        fset box 5 (fmax (fget box 5) (fget pb (q + 5)));
        if Array.unsafe_get sb j <> Array.unsafe_get sb (j - 1) then
          fset sa j (area box 0)
      done;
      box_empty box 0;
      for j = 0 to n - 2 do
        let q = Array.unsafe_get sp j in
        fset box 0 (fmin (fget box 0) (fget pb q));
        fset box 1 (fmin (fget box 1) (fget pb (q + 1)));
        fset box 2 (fmin (fget box 2) (fget pb (q + 2)));
        fset box 3 (fmax (fget box 3) (fget pb (q + 3)));
        fset box 4 (fmax (fget box 4) (fget pb (q + 4)));
        fset box 5 (fmax (fget box 5) (fget pb (q + 5)));
        let b = Array.unsafe_get sb j in
        if b <> Array.unsafe_get sb (j + 1) then
          let cost =
            (area box 0 *. Float.of_int (j + 1))
            +. (fget sa (j + 1) *. Float.of_int (n - j - 1))
          in
          if cost < !best_cost then (
            best_cost := cost;
            split.(0) <- axis;
            split.(1) <- b + 1)
      done)
  done;
  !best_cost

(* Binned SAH: for each axis, bin the centroids, sweep the bins from both ends, and keep
   the cheapest split cost SA(L)·nL + SA(R)·nR. The split (axis, first bin of the right
   side) is stored in [split] and its cost returned; infinity when no axis splits. Nodes
   of more than [small] primitives, the only ones that come here, bin only along the
   widest axis of [cbox], which holds their box. *)
let best_split w lo hi split =
  let cb = w.cbox in
  let best_cost = ref Float.infinity in
  split.(0) <- -1;
  let e k = fget cb (3 + k) -. fget cb k in
  let widest = if e 0 >= e 1 && e 0 >= e 2 then 0 else if e 1 >= e 2 then 1 else 2 in
  let use k = k = widest && fget cb (3 + k) -. fget cb k > 0. in
  let use_x = use 0 and use_y = use 1 and use_z = use 2 in
  bin_axes w lo hi use_x use_y use_z;
  let left_a = w.bin_b and la = 6 * 3 * bins in
  for axis = 0 to 2 do
    if (axis = 0 && use_x) || (axis = 1 && use_y) || (axis = 2 && use_z) then (
      let b0 = axis * bins in
      (* right_area.(b): area of bins b..bins−1; right_n likewise. *)
      box_empty left_a la;
      let acc_n = ref 0 in
      for b = bins - 1 downto 1 do
        box_merge left_a la w.bin_b (6 * (b0 + b));
        acc_n := !acc_n + w.bin_n.(b0 + b);
        fset w.right_area b (area left_a la);
        w.right_n.(b) <- !acc_n
      done;
      box_empty left_a la;
      let acc_n = ref 0 in
      for b = 0 to bins - 2 do
        box_merge left_a la w.bin_b (6 * (b0 + b));
        acc_n := !acc_n + w.bin_n.(b0 + b);
        let nl = !acc_n and nr = w.right_n.(b + 1) in
        if nl > 0 && nr > 0 then
          let cost =
            (area left_a la *. Float.of_int nl)
            +. (fget w.right_area (b + 1) *. Float.of_int nr)
          in
          if cost < !best_cost then (
            best_cost := cost;
            split.(0) <- axis;
            split.(1) <- b + 1)
      done)
  done;
  !best_cost

(* Partition ids[lo, hi) so that the centroids in bins below [split] along [axis] come
   first; the index of the first of the others. From both ends: the first primitive from
   the left that belongs to the right is swapped with the first from the right that
   belongs to the left. Each primitive's box goes into the bounds of its side (12 floats:
   box, then centroid bounds), at [loff] in [dl] or at [roff] in [dr]: the children's
   bounds come out of this pass. Min and max are exact, so these are the bounds a pass
   over each side would compute. *)
let partition w lo hi axis split dl loff dr roff =
  let cb = w.cbox and ids = w.ids and pb = w.pbox in
  let cmin = fget cb axis in
  let scale = Float.of_int bins /. (fget cb (3 + axis) -. cmin) in
  let left i = bin_of cmin scale (cen pb (6 * i) axis) < split in
  bound_empty dl loff;
  bound_empty dr roff;
  let i = ref lo and j = ref (hi - 1) in
  while !i <= !j do
    while !i <= !j && left !i do
      bound_add dl loff pb (6 * !i);
      incr i
    done;
    while !i <= !j && not (left !j) do
      bound_add dr roff pb (6 * !j);
      decr j
    done;
    if !i < !j then (
      let p = Array.unsafe_get ids !i in
      Array.unsafe_set ids !i (Array.unsafe_get ids !j);
      Array.unsafe_set ids !j p;
      let a = 6 * !i and b = 6 * !j in
      for k = 0 to 5 do
        let t = fget pb (a + k) in
        fset pb (a + k) (fget pb (b + k));
        fset pb (b + k) t
      done;
      bound_add dl loff pb a;
      bound_add dr roff pb b;
      incr i;
      decr j)
  done;
  !i

(* Bounds waiting for their node, 12 floats per depth: [pend] at depth d those of the
   node being built there, [pend_right] at d those of its right child while its left
   subtree is built. *)
let reserve w depth =
  if 12 * (depth + 2) > Float.Array.length w.pend then (
    let cap = 12 * (2 * (depth + 2)) in
    let grow a =
      let b = Float.Array.create cap in
      Float.Array.blit a 0 b 0 (Float.Array.length a);
      b
    in
    w.pend <- grow w.pend;
    w.pend_right <- grow w.pend_right)

(* The node over ids[lo, hi), whose bounds are at [pend] for [depth]. *)
let rec build_node w split lo hi depth =
  let node = new_node w in
  if depth > w.max_depth then w.max_depth <- depth;
  reserve w depth;
  let off = 8 * node and here = 12 * depth in
  let pend = w.pend in
  let n = hi - lo in
  Float.Array.blit pend here w.nodes_b off 6;
  (* A large node is binned over its box where no item is wider than a quarter of it along
     the box's widest axis, else over its centroids' bounds; a small one over its
     centroids' bounds. *)
  let over_box =
    n > small
    &&
    let e k = fget pend (here + 3 + k) -. fget pend (here + k) in
    let a = if e 0 >= e 1 && e 0 >= e 2 then 0 else if e 1 >= e 2 then 1 else 2 in
    e a > 0. && 2. *. fget w.ext a <= e a
  in
  Float.Array.blit pend (if over_box then here else here + 6) w.cbox 0 6;
  let below = here + 12 in
  let all_cheap () =
    let ok = ref true in
    for i = lo to hi - 1 do
      if Bytes.get w.cheap w.ids.(i) <> '\001' then ok := false
    done;
    !ok
  in
  let mid =
    if n <= 2 || (n <= w.cheap_max && all_cheap ()) then -1
    else
      let best_cost =
        if n <= small then best_split_small w lo hi split else best_split w lo hi split
      in
      let node_area = area w.nodes_b off in
      (* Cost model: one box test per child against one intersection per primitive. *)
      let leaf_cost = Float.of_int n *. node_area in
      if split.(0) < 0 then
        if n <= max_leaf then -1
        else (
          bound_range w lo (lo + (n / 2)) pend below;
          bound_range w (lo + (n / 2)) hi w.pend_right here;
          lo + (n / 2))
      else if n <= max_leaf && leaf_cost <= node_area +. best_cost then -1
      else
        let mid = partition w lo hi split.(0) split.(1) pend below w.pend_right here in
        if mid = lo || mid = hi then (
          bound_range w lo (lo + (n / 2)) pend below;
          bound_range w (lo + (n / 2)) hi w.pend_right here;
          lo + (n / 2))
        else mid
  in
  if mid < 0 then (
    fset w.nodes_b (off + 6) (Float.of_int lo);
    fset w.nodes_b (off + 7) (Float.of_int n))
  else (
    ignore (build_node w split lo mid (depth + 1));
    (* The left subtree may have grown the scratch: read it again. *)
    Float.Array.blit w.pend_right here w.pend below 12;
    let right = build_node w split mid hi (depth + 1) in
    (* The node arrays may have moved while the subtrees were built. *)
    fset w.nodes_b (off + 6) (Float.of_int right);
    fset w.nodes_b (off + 7) 0.);
  node

type t = {
  nodes : Float.Array.t;
      (** 8 per node, one cache line: min x y z, max x y z (padded), then a leaf's (first,
          count > 0) into [order], an interior node's (right child, 0), its left child
          being the next node; the two integers are stored as floats (exact) *)
  order : int array;  (** the items in leaf order *)
  depth : int;  (** the tree's depth: an upper bound on the traversal stack *)
}

(* --- Large builds, written plainly -------------------------------------------------- *)

(* The Morton code of a centroid's cells, bit by bit: x's bit k at 3k + 2, y's at 3k + 1,
   z's at 3k. *)
let interleave b cx cy cz =
  let code = ref 0 in
  for k = 0 to b - 1 do
    code :=
      !code
      lor (((cx lsr k) land 1) lsl ((3 * k) + 2))
      lor (((cy lsr k) land 1) lsl ((3 * k) + 1))
      lor (((cz lsr k) land 1) lsl (3 * k))
  done;
  !code

(* Items wider than a 64th of the centroids' extent first, in their order, searched; the
   others after them sorted by (code, index) on cubic cells, 2^b a side (b = 10, fewer
   where the index needs more than 32 bits), their nodes split at the first position
   whose code has the highest bit in which the range's first and last codes differ (the
   middle where they are equal), searched from 16 items down, or, where they are all
   cheap, cut the same way down to leaves of at most [cheap_max]. *)
let build_morton w m =
  let pb = w.pbox in
  let c i k = cen pb (6 * i) k in
  let bound f z k = List.fold_left (fun a i -> f a (c i k)) z (List.init m Fun.id) in
  let los = Array.init 3 (bound fmin Float.infinity)
  and his = Array.init 3 (bound fmax Float.neg_infinity) in
  let lo k = los.(k) and hi k = his.(k) in
  let ext = fmax (hi 0 -. lo 0) (fmax (hi 1 -. lo 1) (hi 2 -. lo 2)) in
  let wide i =
    List.exists
      (fun k -> fget pb ((6 * i) + 3 + k) -. fget pb ((6 * i) + k) > ext /. 64.)
      [ 0; 1; 2 ]
  in
  let rec bits n = if n <= 1 then 1 else 1 + bits (n lsr 1) in
  let b = min 10 ((62 - bits (m - 1)) / 3) in
  let scale = if ext > 0. then Float.of_int (1 lsl b) /. ext else 0. in
  let cell i k =
    let v = int_of_float ((c i k -. lo k) *. scale) in
    max 0 (min ((1 lsl b) - 1) v)
  in
  let code i = interleave b (cell i 0) (cell i 1) (cell i 2) in
  let all = List.init m Fun.id in
  let wides = List.filter wide all in
  let others =
    List.filter (fun i -> not (wide i)) all
    |> List.map (fun i -> (code i, i))
    |> List.sort compare
  in
  let order = Array.of_list (wides @ List.map snd others) in
  let codes = Array.of_list (List.map (fun _ -> 0) wides @ List.map fst others) in
  let nw = List.length wides in
  (* Boxes and ids in that order. *)
  let sorted = Float.Array.create (6 * m) in
  Array.iteri (fun p i -> Float.Array.blit pb (6 * i) sorted (6 * p) 6) order;
  Float.Array.blit sorted 0 pb 0 (6 * m);
  Array.blit order 0 w.ids 0 m;
  let join node right =
    let l = 8 * (node + 1) and r = 8 * right and off = 8 * node in
    for k = 0 to 2 do
      fset w.nodes_b (off + k) (fmin (fget w.nodes_b (l + k)) (fget w.nodes_b (r + k)));
      fset w.nodes_b
        (off + 3 + k)
        (fmax (fget w.nodes_b (l + 3 + k)) (fget w.nodes_b (r + 3 + k)))
    done;
    fset w.nodes_b (off + 6) (Float.of_int right);
    fset w.nodes_b (off + 7) 0.
  in
  let searched lo hi depth =
    reserve w depth;
    bound_range w lo hi w.pend (12 * depth);
    build_node w [| -1; 0 |] lo hi depth
  in
  let split lo hi =
    let a = codes.(lo) and z = codes.(hi - 1) in
    if a = z then lo + ((hi - lo) / 2)
    else
      let h = ref 0 in
      while (a lxor z) lsr (!h + 1) > 0 do
        incr h
      done;
      let p = ref lo in
      while codes.(!p) land (1 lsl !h) = 0 do
        incr p
      done;
      !p
  in
  let cheap lo hi =
    w.cheap_max > 0
    && Bytes.length w.cheap > 0
    && List.for_all
         (fun p -> Bytes.get w.cheap w.ids.(p) = '\001')
         (List.init (hi - lo) (( + ) lo))
  in
  (* Cheap items are cut in Morton order down to leaves of at most [cheap_max]. *)
  let rec cheap_morton lo hi depth =
    let node = new_node w in
    if depth > w.max_depth then w.max_depth <- depth;
    (if hi - lo <= w.cheap_max then (
       let off = 8 * node in
       box_empty w.nodes_b off;
       for p = lo to hi - 1 do
         box_merge w.nodes_b off w.pbox (6 * p)
       done;
       fset w.nodes_b (off + 6) (Float.of_int lo);
       fset w.nodes_b (off + 7) (Float.of_int (hi - lo)))
     else
       let mid = split lo hi in
       ignore (cheap_morton lo mid (depth + 1));
       join node (cheap_morton mid hi (depth + 1)));
    node
  in
  let rec morton lo hi depth =
    if hi - lo <= small then
      if cheap lo hi then cheap_morton lo hi depth else searched lo hi depth
    else
      let node = new_node w in
      if depth > w.max_depth then w.max_depth <- depth;
      let mid = split lo hi in
      ignore (morton lo mid (depth + 1));
      let right = morton mid hi (depth + 1) in
      join node right;
      node
  in
  if nw = m then ignore (searched 0 m 1)
  else if nw = 0 then ignore (morton 0 m 1)
  else
    let root = new_node w in
    w.max_depth <- 1;
    ignore (searched 0 nw 2);
    let right = morton nw m 2 in
    join root right

let build ?(cheap = (Bytes.empty, 0)) ?(large = Lancer_render.Bvh.large) pbox =
  let cheap, cheap_max = cheap in
  let m = Float.Array.length pbox / 6 in
  (* A tree of m items has at most 2m − 1 nodes; with leaves of one or two, as the cost
     model makes them, a little more than m. *)
  let cap = m + (m / 8) + 16 in
  let w =
    {
      pbox;
      ids = Array.init m Fun.id;
      nodes_b = Float.Array.create (8 * cap);
      count = 0;
      max_depth = 0;
      bin_n = Array.make (3 * bins) 0;
      bin_b = Float.Array.create (6 * ((3 * bins) + 1));
      right_area = Float.Array.make bins 0.;
      right_n = Array.make bins 0;
      cbox = Float.Array.create 6;
      pend = Float.Array.create (12 * 64);
      pend_right = Float.Array.create (12 * 64);
      small_bin = Array.make small 0;
      small_p = Array.make small 0;
      small_area = Float.Array.make small 0.;
      cheap;
      cheap_max;
      ext = Lancer_render.Bvh.widths pbox;
    }
  in
  if m >= large then build_morton w m
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
