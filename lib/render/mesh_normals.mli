(** Vertex normals of a mesh that has none. The faces around a vertex (those that name it:
    the same vertex of the file, not merely the same position) fall into smooth groups:
    two faces that share an edge from the vertex and whose normals are at most the crease
    angle apart are in one group. Each corner's normal is the average of the normals of
    its group's faces, each weighted by the angle the face makes at the vertex. An edge
    where faces meet at more than the crease angle stays sharp; a curved surface shades
    smoothly.

    The corners of one group share one normal, so a smooth mesh stores one per vertex. The
    work per vertex is that of sorting its edges, whatever its number of faces (a polygon
    of a million corners, fanned, is one vertex of a million faces). Everything is in flat
    arrays, as the mesh's own data. *)

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

val build : smooth:bool -> Tri_builder.mesh -> Trimesh.t
(** {!Trimesh.make} of a mesh as a reader read it; with [smooth], the triangles it found
    no normals for get computed ones ({!complete}). *)
