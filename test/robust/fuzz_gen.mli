(** Inputs for the robustness tests and for [make fuzz]: random and mutated OBJ text,
    image bytes and scene text, with the oracles that judge what the loaders do with them.
    Every generator is a function of a [Random.State.t], so a seed replays a case. *)

val contains : string -> string -> bool
(** [contains s sub]: whether [sub] occurs in [s]. *)

val random_obj : Random.State.t -> string
(** OBJ text made of random statements, indices and numbers. *)

val mutated_obj : Random.State.t -> string
(** A valid OBJ file with random insertions, deletions and replacements. *)

val check_obj : string -> (unit, string) result
(** The OBJ loader's contract: [Error] (the case fails) when {!Lancer.Obj_file.parse}
    raises, answers a message without the file name or on several lines, or returns no
    triangle or one with non-finite bounds. *)

val check_obj_lines : string -> (unit, string) result
(** The loader's one-pass reading of plain lines against its word-by-word reading: the
    text and the same text with every line indented by a blank (which no line's one-pass
    reading takes) must give the same triangles, bit for bit, or the same message. *)

type ply_mesh
(** A small random mesh: vertices, perhaps normals and (u, v), polygons. *)

val random_ply : Random.State.t -> ply_mesh

val ply_text : string -> ply_mesh -> string
(** [ply_text format m] is [m] as a PLY file of that format ([ascii],
    [binary_little_endian], [binary_big_endian]), written here byte by byte, with extra
    properties and an extra element that a reader must read past. *)

val obj_of_ply : ply_mesh -> string
(** The same mesh as OBJ text. *)

val mutated_ply : Random.State.t -> string
(** A random mesh's PLY file with random insertions, deletions and replacements. *)

val check_ply : string -> (unit, string) result
(** The PLY reader's contract: triangles, or one [fuzz.ply:…] line; never an exception. *)

val check_ply_formats : ply_mesh -> (unit, string) result
(** The mesh reads to the same triangles, bit for bit, from ASCII, little- and big-endian
    PLY and from OBJ. *)

val with_temp_file : string -> string -> (string -> 'a) -> 'a
(** [with_temp_file ext contents f] is [f path] for a temporary file holding [contents],
    removed afterwards. *)

val image_case : Random.State.t -> string * string
(** (extension, bytes): a random or mutated PNG or PPM file. *)

val check_image : string * string -> (unit, string) result
(** The decoder's contract: [Error] (the case fails) when reading raises, fails with a
    message of several lines or one that reports a crash (an internal error, or the name
    of an OCaml exception such as [Invalid_argument]), or returns a framebuffer of the
    wrong size or with values outside [[0, 1]]. *)

val judge_image_error : string -> (unit, string) result
(** How {!check_image} judges a reader's [Error] message: [Ok] for a one-line reason, an
    [Error] for a crash or a message of several lines. *)

val png_claiming : int -> int -> string
(** A PNG file with valid checksums whose header claims [w × h] pixels. *)

val dsl_tokens : string array
(** The words, symbols and literals of the scene language (and some bytes that are not)
    that random scenes are made of; shared with the language's own properties. *)

val png_one_pixel : unit -> string
(** A valid 1×1 PNG file. *)

val scene_seeds : string -> (string * string) array
(** (name, text) of every scene under [root/scenes], the seeds of the scene mutations. *)

val scene_case : (string * string) array -> Random.State.t -> string * string
(** (name, text): random tokens of the language, or a mutated seed scene. *)

val check_scene : string * string -> (unit, string) result
(** The language's contract: [Error] (the case fails) when loading, evaluating, printing
    an error or {!Lancer.Program.to_json} raises, when loading fails with no error, or
    when loading or evaluating reports an internal error (an exception the language's
    boundary caught: a crash). *)

val judge_scene_errors : Lancer_dsl.Error.t list -> (unit, string) result
(** How {!check_scene} judges the errors of a load or an evaluation: [Ok] for located
    errors, an [Error] for none at all or for an internal error. *)
