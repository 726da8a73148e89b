(** The renderer's form of a scene description: reads the images and meshes it names
    (through a cache shared between frames), builds the shapes, primitives, materials and
    textures, and the acceleration structure ({!Lancer_render.Scene.make}).

    A file that cannot be read, a mesh without triangles or open where a solid is needed,
    a height field too small: each is reported at the place the description recorded, in
    source order, each once. *)

type assets
(** The images read by [image(…)] textures and bump maps, the OBJ files read by [mesh] and
    the images of height fields, each read once, shared between frames and threads. *)

val assets : ?digests:bool -> ?after_read:(string -> unit) -> unit -> assets
(** An empty cache. Each file is read once, whole, and decoded from those bytes. With
    [~digests:true] the cache also keeps the MD5 of the very bytes it decoded ({!digest}),
    for the records of a job that must say what its pictures were made of; a file read a
    second time (a mesh smooth and faceted) must then give the same bytes, or the use is
    an error ("the file changed while the scene was being made"). [after_read path] is
    called as soon as a file's bytes are read, before they are decoded or digested (a test
    replaces the file there). *)

val files : assets -> string list
(** The paths of the images and meshes read so far (or tried), sorted. *)

val digest : assets -> string -> string option
(** [digest assets path] is the MD5 (hex) of the bytes of [path] that the cache decoded,
    when it keeps digests and has read that file. *)

type static
(** A program's static part ({!Lancer_description.Description.static}) compiled: the
    primitives of its objects, made once, known by their statements' positions, and the
    acceleration structure over them (for the last origin asked). *)

val static : assets -> Description.static -> static
(** [static assets st]: the primitives of the objects of [st] (whose positions increase),
    as {!compile} makes them. An object that does not compile leaves the part unused: each
    scene then makes and reports its objects itself. *)

val compile :
  ?source:(string -> string option) ->
  ?progress:(string -> unit) ->
  ?index:bool ->
  ?static:static ->
  ?objects:Description.obj list ->
  ?parts:Description.part list ->
  assets ->
  Description.t ->
  (Scene.t, Diagnostic.t list) result
(** [compile assets d] is the scene [d] describes. [source file] is the text of [file],
    for an error's caret display. [progress] is told when a long build starts its
    acceleration structure ("building the acceleration structure over 1000000 objects").
    With [objects], those are compiled in place of [d]'s: a caller that keeps no other
    reference to them (passing [d] without them) lets each go as it is compiled, so that a
    large scene is not held twice. With [parts], the objects are theirs, in order, in
    place of [d]'s, a [Static] part being the objects [static] has at that position
    ([Invalid_argument] without [static], or for a position it does not have): each
    [Static] part is taken whole, with no work per object, and when every statement of
    [static] that has objects is there, the scene reuses the static part's acceleration
    structure ({!Scene.make_layered}, its {!Accel.fixed_key} the positions of [static]):
    the same scene, made faster (a frame of an animation then costs what its other objects
    cost). With [~index:false] (default [true]), the scene has no acceleration structure
    to query it fast ({!Scene.of_moved}): for [lancer check], which reads what the scene
    holds but traces no ray. *)

type stream
(** Objects compiled as a program makes them, for the one scene it describes: each made
    into its primitives at once, so that a large scene's description is never held whole
    beside them. *)

val stream : assets -> stream
(** An empty stream. *)

val add : stream -> Description.obj -> unit
(** [add s o]: [o]'s primitives, after those of the objects added before it; a problem
    with it (a mesh that cannot be read, …) is kept for {!finish} to report.
    [Invalid_argument] once [s] is finished. *)

val finish :
  ?source:(string -> string option) ->
  ?progress:(string -> unit) ->
  ?index:bool ->
  stream ->
  Description.t ->
  (Scene.t, Diagnostic.t list) result
(** [finish s d]: the scene of [d] (its settings, camera, lights, time and frame) whose
    objects are those added to [s], in order: what {!compile} makes of [d] with those
    objects, problems reported the same way. [Invalid_argument] if [s] is finished
    already: a stream makes one scene. *)

val check_files : assets -> Description.file_use list -> (Loc.t * string) list
(** What reading these files finds wrong, each at the place its use recorded, in the order
    of the uses, each once: what {!compile} would report about them. The files are read
    into [assets], for the compile to come. *)

val rendered : assets -> Scene.t -> Description.rendered
(** What the renderer made of a description, for [lancer check]: the objects by kind, the
    CSG trees, the distinct materials, features, and what the mesh and height-field files
    held. *)

val primitive_count : assets -> Description.obj -> int
(** How many primitives {!compile} makes of an object that compiles, each after the
    previous object's in the scene's [objects]: a height field's triangles, 1 for any
    other (a mesh and a CSG object are one primitive each). *)
