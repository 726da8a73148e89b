(** PLY meshes (Stanford's polygon format): ASCII, binary little-endian and binary
    big-endian, as scanners and exporters write them.

    The [vertex] element's [x], [y], [z] are read, with [nx], [ny], [nz] (normals) and
    [u], [v] (or [s], [t], [texture_u], [texture_v]) when present; the [face] element's
    [vertex_indices] (or [vertex_index]) lists make polygons, fan-triangulated from their
    first corner as OBJ's are. Every other property and element is read past. Triangles of
    zero area are dropped. A malformed file never raises: the error is located as the OBJ
    reader's are, [file:LINE: message] in the header or an ASCII body,
    [file: byte N: message] in a binary body, and says what was expected. *)

val read_mesh : ?smooth:bool -> file:string -> string -> (Tri_builder.mesh, string) result
(** {!parse_mesh}'s reading, without the hierarchy: what a caller builds
    ({!Mesh_normals.build}) once it has let [text] go. *)

val parse_mesh : ?smooth:bool -> file:string -> string -> (Trimesh.t, string) result
(** [parse_mesh ~file text] reads the PLY file whose bytes are [text] into one indexed
    mesh; [file] names it in messages. With [smooth] (default true) a mesh with vertex
    normals interpolates them, and one without gets normals computed from its faces
    ({!Mesh_normals.complete}). *)
