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
