(** What a mesh reader fills as it reads: growable flat arrays of vertices, normals and
    texture coordinates, and of triangles' corner indices, and the area test that drops
    degenerate triangles. The OBJ and PLY readers share them. *)

type floats = { mutable fl : Float.Array.t; mutable len : int; width : int }
(** [len] elements of [width] floats in [fl] (which may be longer). *)

val floats : int -> floats
(** An empty array of elements of this width. *)

val push3 : floats -> float -> float -> float -> unit
val push2 : floats -> float -> float -> unit

type corners = { mutable ix : Trimesh.ints; mutable n : int }
(** [n] triangles' three corner indices in [ix] (which may be longer). *)

val corners : unit -> corners
(** None yet. *)

val push_corners : corners -> int -> int -> int -> unit

val push_absent : corners -> unit
(** A triangle without this kind of corner (normals or (u, v)): only counted while no
    triangle has one, so that a mesh without them writes nothing. *)

val push_present : corners -> int -> int -> int -> unit
(** A triangle with them: the earlier triangles are marked absent (−1) at the first. *)

val trimmed : corners -> Trimesh.ints
(** Exactly the [3n] indices. *)

val trimmed_floats : floats -> Float.Array.t
(** Exactly the [width·len] floats. *)

type mesh = {
  pos : Float.Array.t;
  nrm : Float.Array.t;
  tex : Float.Array.t;
  tv : Trimesh.ints;
  tn : Trimesh.ints;
  tt : Trimesh.ints;
}
(** What a reader read, exactly sized, before the hierarchy is built ({!Trimesh.make}'s
    arguments, made by {!Mesh_normals.build}): a reader hands it over so that its input
    can be let go first. *)

val mesh :
  floats -> floats -> floats -> corners -> corners option -> corners option -> mesh
(** [mesh vs vns vts tv tn tt]: the vertices, normals, texture coordinates and the
    triangles' corners trimmed to their lengths; [tn] and [tt] [None] where no triangle
    has them. *)

val area : Float.Array.t -> int -> int -> int -> float
(** [area pos a b c] is |(b − a) × (c − a)| for vertices [a], [b], [c] of [pos] (three
    coordinates each): a triangle is kept where it is finite and positive. *)
