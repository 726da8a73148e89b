(** Vertex normals of a mesh that has none: each corner's normal is the average of the
    normals of the faces around its vertex, weighted by the angle each face makes at that
    vertex, taking only the faces that meet the corner's own face at no more than the
    crease angle, so that a sharp edge stays sharp. The faces around a vertex are those
    that name it (the same vertex of the file, not merely the same position).

    Corners whose averages come out the same (a smooth vertex: every face around it within
    the crease of every other) share one normal, so a smooth mesh stores about one per
    vertex. Everything is in flat arrays, as the mesh's own data. *)

val complete :
  ?crease:float ->
  pos:Float.Array.t ->
  nrm:Float.Array.t ->
  tv:Trimesh.ints ->
  tn:Trimesh.ints ->
  unit ->
  Float.Array.t * Trimesh.ints * int
(** [complete ~pos ~nrm ~tv ~tn ()], for a mesh as {!Trimesh.make} takes it, gives every
    triangle without normals ([tn] empty, or [tn.{3k}] = −1) computed ones, [crease]
    (degrees, default {!Lancer_description.Description.crease}) apart: the normals (those
    of [nrm], then the computed ones, unit), each triangle's normal indices, and how many
    triangles were given normals. A mesh whose triangles all have normals comes back as it
    was. *)

val mesh :
  smooth:bool ->
  pos:Float.Array.t ->
  nrm:Float.Array.t ->
  tex:Float.Array.t ->
  tv:Trimesh.ints ->
  tn:Trimesh.ints ->
  tt:Trimesh.ints ->
  Trimesh.t
(** {!Trimesh.make} of a mesh as a reader found it; with [smooth], the triangles it found
    no normals for get computed ones ({!complete}). *)
