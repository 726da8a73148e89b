(** Wavefront OBJ meshes: [v], [vt], [vn] and [f] statements into triangles.

    Faces take [a], [a/b], [a/b/c] or [a//c] corners, with 1-based or negative (relative
    to the last element defined so far) indices; polygons are fan-triangulated from their
    first corner. Grouping and material statements ([o], [g], [s], [usemtl], [mtllib], …)
    are accepted and ignored. Triangles of zero area are dropped. A malformed file never
    raises: every problem is an [Error "file:line: message"]. *)

val read_mesh : ?smooth:bool -> file:string -> string -> (Tri_builder.mesh, string) result
(** {!parse_mesh}'s reading, without the hierarchy: what a caller builds
    ({!Mesh_normals.build}) once it has let [text] go. *)

val parse_mesh : ?smooth:bool -> file:string -> string -> (Trimesh.t, string) result
(** [parse_mesh ~file text] reads OBJ [text] into one indexed mesh, straight into its
    arrays; [file] names it in messages. With [smooth] (default true) faces whose corners
    all carry a [vn] interpolate those normals, and the others normals computed from the
    faces ({!Mesh_normals.complete}). *)

val load_mesh : ?smooth:bool -> string -> (Trimesh.t, string) result
(** [load_mesh path] reads and parses the file at [path]. *)

val parse : ?smooth:bool -> file:string -> string -> (Shape.t list, string) result
(** {!parse_mesh}, its faces as triangles ({!Lancer_render.Shape.faces}). *)

val load : ?smooth:bool -> string -> (Shape.t list, string) result
(** {!load_mesh}, its faces as triangles. *)

val float_at : string -> int -> int -> float
(** [float_at text s e] is the number written in bytes \[s, e) of [text], as
    [float_of_string] reads it (without a copy for plain decimals); NaN when those bytes
    are not one. *)

val int_at : string -> int -> int -> int option
(** [int_at text s e] is the integer written in bytes \[s, e), as [int_of_string_opt]. *)

val open_edges : Shape.t list -> int
(** [open_edges triangles] is how many edges (pairs of corner positions) are not shared by
    exactly two of the triangles: 0 for a closed mesh. *)

val open_edges_mesh : Trimesh.t -> int
(** {!open_edges} of the mesh's faces. *)
