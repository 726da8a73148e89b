(** Indexed triangle meshes: vertex positions, normals and texture coordinates in flat
    float arrays, three 32-bit indices per triangle, and a bounding volume hierarchy over
    the triangles whose leaves hold triangle indices. Nothing is stored per triangle
    beyond its indices and its place in the tree. *)

type ints = (int32, Bigarray.int32_elt, Bigarray.c_layout) Bigarray.Array1.t
type t

val ints : int -> ints
(** A fresh index array of this length. *)

val no_ints : ints
(** The empty index array: no triangle has normals (or uvs). *)

val make :
  pos:Float.Array.t ->
  nrm:Float.Array.t ->
  tex:Float.Array.t ->
  tv:ints ->
  tn:ints ->
  tt:ints ->
  t
(** [make ~pos ~nrm ~tex ~tv ~tn ~tt]: [pos] 3 coordinates per vertex, [nrm] 3 per normal
    (as read, not normalised), [tex] 2 per (u, v); triangle k has vertices
    [tv.{3k..3k+2}], normals [tn.{3k..3k+2}] (or [tn] empty, or [tn.{3k}] = −1 for none)
    and (u, v)s likewise in [tt]. Builds the hierarchy (from 8 triangles). *)

val count : t -> int
(** The number of triangles. *)

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

val nearest : t -> Probe.t -> int
(** [nearest m q] is the triangle nearest along the probe's ray in ([q.p_tmin],
    [q.p_tmax]), ties to the lower index (what a scan of the triangles in order finds):
    its index or −1; its t goes into [q.p_t] (infinity for none). The probe's reciprocal
    direction must be set. Allocates nothing. *)

val first : t -> Probe.t -> int
(** [first m q] is a triangle the probe's ray crosses in ([q.p_tmin], [q.p_tmax]), the
    first the walk meets, or −1: its t goes into [q.p_t] (infinity for none). For shadow
    rays, where any crossing answers. Allocates nothing. *)
