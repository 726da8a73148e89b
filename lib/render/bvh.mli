(** A bounding volume hierarchy over boxes, built by the binned surface area heuristic:
    what the scene's acceleration structure and a mesh's own hierarchy are made of. Items
    are given as padded boxes in one float array; the tree is one float array of nodes. *)

val pad_into :
  Float.Array.t -> int -> float -> float -> float -> float -> float -> float -> unit
(** [pad_into pb k x0 y0 z0 x1 y1 z1] stores the box min (x0, y0, z0), max (x1, y1, z1),
    padded by a relative 1e-9 of its magnitude, as item [k] of [pb] (6 floats an item):
    rounding in the slab test then never culls an item whose hit lies on its own bounds.
*)

type t = {
  nodes : Float.Array.t;
      (** 8 floats a node, one cache line: min x y z, max x y z (padded), then a leaf's
          (first, count > 0) into [order], an interior node's (right child, 0), its left
          child being the next node; the two integers are stored as floats (exact) *)
  order : int array;  (** the items in leaf order *)
  depth : int;  (** the tree's depth: an upper bound on the traversal stack *)
}

val build : ?cheap:Bytes.t * int -> Float.Array.t -> t
(** [build pb] builds the tree over the items of [pb] (as {!pad_into} writes them; their
    centroids are the boxes' midpoints). It allocates nothing per item or node beyond its
    arrays. With [~cheap:(flags, k)], a node of at most [k] items whose flags (by item,
    ['\001']) all say cheap is a leaf, with no split searched: for items whose test costs
    less than a box's. *)

val link : Float.Array.t -> int -> int
(** Node [k]'s first integer: a leaf's first slot in [order], an interior node's right
    child. *)

val count : Float.Array.t -> int -> int
(** Node [k]'s second integer: a leaf's item count (> 0), 0 for an interior node. *)

val near : float -> int
(** [near i]: the offset in a node of the near plane's coordinate along an axis of
    reciprocal direction [i] (0, the min plane, unless [i] < 0: 3, the max plane). A ray
    computes it once per axis for {!box_entry} and {!box_hit}: [nx = near ix],
    [ny = 1 + near iy], [nz = 2 + near iz], and the far offsets [3 - nx], [5 - ny],
    [7 - nz]. *)

val box_entry :
  Float.Array.t ->
  int ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  int ->
  int ->
  int ->
  int ->
  int ->
  int ->
  float ->
  float ->
  float ->
  float
(** [box_entry nodes k ox oy oz ix iy iz nx ny nz fx fy fz tmin tmax inf]: the entry t of
    the ray (origin o, reciprocal direction i) into node [k]'s box within [tmin, tmax], or
    [inf] (infinity) for a miss, the near and far planes given by their offsets ({!near}).
    A NaN from 0·inf (origin on a slab plane, ray parallel to it) leaves the interval
    open. *)

val box_hit :
  Float.Array.t ->
  int ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  int ->
  int ->
  int ->
  int ->
  int ->
  int ->
  float ->
  float ->
  bool
(** Whether the ray meets node [k]'s box within [tmin, tmax]: {!box_entry}'s answer,
    except where both the entry and the exit are infinite (a ray parallel to a slab it
    lies beyond), which it lets through; one comparison fewer, for the walks that need no
    entry t. *)

(** {1 Walks} *)

type walk = {
  mutable ids : int array;  (** the nodes still to visit *)
  mutable ts : Float.Array.t;  (** their entry t, for the nearest walk *)
  mutable busy : bool;  (** whether a walk holds it *)
  mutable sp : int;  (** how many of [ids] are on the stack between two descents *)
  span : Float.Array.t;
      (** the interval the descents cull boxes by (tmin, then tmax or the best t so far),
          set by the walk *)
}
(** A depth-first walk's stack, kept from one query to the next (one per domain). *)

val new_walk : unit -> walk

val take : walk -> int -> walk
(** [take w depth]: [w] made ready for a tree of depth [depth] and marked busy, or a fresh
    walk where [w] is busy (a query inside another's visit). The walk clears [busy]. *)

val next_leaf : Float.Array.t -> Probe.t -> walk -> int
(** [next_leaf nodes q w]: from the nodes on [w]'s stack, the next leaf whose box [q]'s
    ray crosses within [w.span] (−1: none is left), depth first, the crossed children of
    the interior nodes passed pushed right below left. It calls nothing, so that the ray's
    floats stay in registers: in a loop that also tests primitives, OCaml would reload
    them from the stack at every box. *)

val next_near_leaf : Float.Array.t -> Probe.t -> walk -> int -> int
(** [next_near_leaf nodes q w start]: the nearest walk's next leaf (−1: none is left),
    from node [start], or with [start] = −1 from the top of the stack past the entries
    whose entry t is beyond the best t ([w.span]'s second). At an interior node the nearer
    child whose box the ray enters by the best t comes next, the farther one is pushed
    with its entry t. Calls nothing, as {!next_leaf}. *)

val start : Float.Array.t -> Probe.t -> walk -> float -> float -> unit
(** [start nodes q w tmin tmax] begins a depth-first walk over [tmin, tmax] for
    {!next_leaf}: the interval kept in [w.span], and the root on the stack if [q]'s ray
    crosses its box. *)

val start_near : Float.Array.t -> Probe.t -> walk -> float -> float -> bool
(** [start_near nodes q w tmin best] begins the nearest walk over [tmin, best] for
    {!next_near_leaf} (from node 0): whether the ray enters the root's box. The walk
    updates [w.span]'s second as its best t improves. *)
