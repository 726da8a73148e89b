(** Indexed triangle meshes: vertex positions, normals and texture coordinates in flat
    float arrays, three 32-bit indices per triangle, and a bounding volume hierarchy over
    the triangles whose leaves hold triangle indices. Nothing is stored per triangle
    beyond its indices and its place in the tree. Rays walk the hierarchy with {!Walk}'s
    queries, the scene's own, testing the triangles with {!root}. *)

type ints = (int32, Bigarray.int32_elt, Bigarray.c_layout) Bigarray.Array1.t
type t

val ints : int -> ints
(** A fresh index array of this length. *)

val no_ints : ints
(** The empty index array: no triangle has normals (or uvs). *)

val make :
  ?computed:int ->
  pos:Float.Array.t ->
  nrm:Float.Array.t ->
  tex:Float.Array.t ->
  tv:ints ->
  tn:ints ->
  tt:ints ->
  unit ->
  t
(** [make ~pos ~nrm ~tex ~tv ~tn ~tt ()]: [pos] 3 coordinates per vertex, [nrm] 3 per
    normal (as read, not normalised), [tex] 2 per (u, v); triangle k has vertices
    [tv.{3k..3k+2}], normals [tn.{3k..3k+2}] (or [tn] empty, or [tn.{3k}] = −1 for none)
    and (u, v)s likewise in [tt]. [computed] (default 0) says how many triangles' normals
    were computed ({!Mesh_normals.complete}) rather than read. Builds the hierarchy (from
    8 triangles). *)

val count : t -> int
(** The number of triangles. *)

val computed : t -> int
(** How many triangles have normals computed from the faces rather than read from the
    file; the others with normals ({!has_normals}) have the file's. *)

val bounds : t -> Bbox.t
(** The box of every corner. *)

val has_normals : t -> int -> bool
val has_uvs : t -> int -> bool

val vertex : t -> int -> int -> Vec3.t
(** [vertex m k j] is corner j (0, 1, 2) of triangle k. *)

val normal : t -> int -> int -> Vec3.t
(** The normal of corner j of triangle k, as read. *)

val uv : t -> int -> int -> float * float

val translate : Vec3.t -> t -> t
(** Every position moved by d (x +. d.x, …), the hierarchy built again. *)

val triangle_s :
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float
(** [triangle_s a b c o d tmin tmax], each point and vector as three scalars: the
    watertight ray–triangle test, the root t in (tmin, tmax) or infinity. *)

val root : t -> int -> Probe.t -> float -> float
(** [root m k q tmax] is triangle [k]'s root along the probe's ray in ([q.p_tmin],
    [tmax]), or infinity: {!triangle_s} on its corners. *)

val nodes : t -> Float.Array.t
(** The hierarchy's nodes ({!Bvh.t}'s), empty for a mesh of fewer than 8 triangles or
    unbounded corners, which has none. *)

val order : t -> int array
(** The triangles in leaf order (a tree's leaf [(first, count)] holds
    [order.(first .. first + count − 1)]); in index order for a mesh without a tree. *)

val depth : t -> int
(** The tree's depth (0 without one): an upper bound on a walk's stack. *)

val first : t -> int
(** How many of [order] a walk tests in order before the tree: all of them without one,
    none with one. *)
