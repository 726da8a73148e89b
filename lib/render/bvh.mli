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

val build : Float.Array.t -> t
(** [build pb] builds the tree over the items of [pb] (as {!pad_into} writes them; their
    centroids are the boxes' midpoints). It allocates nothing per item or node beyond its
    arrays. *)

val link : Float.Array.t -> int -> int
(** Node [k]'s first integer: a leaf's first slot in [order], an interior node's right
    child. *)

val count : Float.Array.t -> int -> int
(** Node [k]'s second integer: a leaf's item count (> 0), 0 for an interior node. *)

val box_entry :
  Float.Array.t ->
  int ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float
(** [box_entry nodes k ox oy oz ix iy iz tmin tmax]: the entry t of the ray (origin o,
    reciprocal direction i) into node [k]'s box within [tmin, tmax], or infinity for a
    miss. A NaN from 0·inf (origin on a slab plane, ray parallel to it) leaves the
    interval open. *)
