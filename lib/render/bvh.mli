(** A bounding volume hierarchy over boxes, built by the surface area heuristic (and, over
    {!large} items or more, in Morton order above small subtrees): what the scene's
    acceleration structure and a mesh's own hierarchy are made of. Items are given as
    padded boxes in one float array; the tree is one float array of nodes. *)

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

val widths : Float.Array.t -> Float.Array.t
(** [widths pb]: the largest extent of the items of [pb] along x, y and z (3 floats, 0
    where there are none). {!build} bins a large node over its box only where no item is
    wider than half of it along the box's widest axis, else over its centroids' bounds. *)

val large : int
(** 262 144: the number of items from which {!build} cuts a tree's large nodes in Morton
    order rather than search their splits. *)

val build : ?cheap:Bytes.t * int -> ?large:int -> Float.Array.t -> t
(** [build pb] builds the tree over the items of [pb] (as {!pad_into} writes them; their
    centroids are the boxes' midpoints). It allocates nothing per item or node beyond its
    arrays. With [~cheap:(flags, k)], a node of at most [k] items whose flags (by item,
    ['\001']) all say cheap is a leaf, with no split searched: for items whose test costs
    less than a box's.

    Nodes of at most 16 items are split by the surface area heuristic, searched along
    their centroids' widest axis; larger ones the same way by binning, below [large] items
    (default {!large}). From [large] items on, the items are sorted along a Morton curve
    over their centroids, and a node of more than 16 splits its range where the highest
    differing bit of their codes changes; a range of at most 16 cheap items is cut the
    same way down to leaves of at most [k]. Items wider than a 64th of the centroids'
    extent are set apart under the root and searched. Over a million items the binned
    search reads each about twenty times; the Morton order, a few times. *)

val link : Float.Array.t -> int -> int
(** Node [k]'s first integer: a leaf's first slot in [order], an interior node's right
    child. *)

val count : Float.Array.t -> int -> int
(** Node [k]'s second integer: a leaf's item count (> 0), 0 for an interior node. *)

(** {1 Walks} *)

type walk = {
  mutable ids : int array;  (** the nodes still to visit *)
  mutable ts : Float.Array.t;  (** their entry t *)
  mutable sp : int;  (** how many of [ids] are on the stack between two descents *)
  span : Float.Array.t;
      (** the interval the descents cull boxes by (tmin, then tmax or the best t so far),
          set by the walk *)
}
(** A depth-first walk's stack, kept from one query to the next. *)

val new_walk : unit -> walk

val ready : walk -> int -> unit
(** [ready w depth] makes [w] hold the stack of a walk over a tree of depth [depth]. *)

val next_leaf : Float.Array.t -> Probe.t -> walk -> int
(** [next_leaf nodes q w]: the next leaf of the walk (−1: none is left), from the top of
    [w]'s stack past the entries whose entry t is beyond [w.span]'s second (the best t of
    a nearest walk, which the walk lowers as it finds hits; the end of the interval of the
    others). At an interior node the nearer child whose box the ray enters within the span
    comes next, the farther one is pushed with its entry t, so that leaves come nearest
    first. The one descent of every walk, written in C: both children's boxes tested at
    once, each slab's bounds taken without a branch. *)

val start : Float.Array.t -> Probe.t -> walk -> float -> float -> int
(** [start nodes q w tmin tmax] begins a walk over [tmin, tmax]: the interval kept in
    [w.span], the stack emptied, and the first leaf, the descent beginning at the root if
    [q]'s ray enters its box (−1: it does not, or no leaf is met). *)
