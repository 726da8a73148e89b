(** A loaded scene program and the renderer: its scene at any time, described by the
    language, its bodies moved by {!Lancer_physics.Physics}, compiled
    ({!Lancer_render.Compile.compile}) with one cache of images and meshes per program.

    Every function returns located errors, as the language does, and raises nothing but
    [Sys.Break]. *)

module Dsl = Lancer_dsl.Dsl

type t
(** A loaded program: the language's program, the cache of the images and meshes its
    scenes read ({!assets}), and what is made once for all its scenes: the motion of its
    bodies and its static part ({!Dsl.static}) compiled, each when first needed. *)

val load_file :
  ?single:bool ->
  ?digests:bool ->
  ?after_read:(string -> unit) ->
  string ->
  (t, Diagnostic.t list) result
(** {!Dsl.load_file}, with the images and meshes the program uses read (into its
    {!assets}) and their problems reported with the program's. [digests] (default [true])
    and [after_read] are {!Lancer_render.Compile.val-assets}': a run that records what its
    pixels were made of (an animation's frames, a checkpoint) keeps the digest of every
    file it decodes. [single] (default [false]) says that the program is loaded for its
    scene at time 0, frame 0 only (a still's render): a still without bodies or motion
    blur ({!Dsl.emitted}) then has its objects compiled as the load makes them, and any
    other program's first scene at time 0 may let the load's description go as it is
    compiled, so that a large scene is never held twice (see {!scene}). *)

val load_string :
  ?single:bool ->
  ?progress:(string -> unit) ->
  ?digests:bool ->
  ?after_read:(string -> unit) ->
  ?filename:string ->
  string ->
  (t, Diagnostic.t list) result
(** {!Dsl.load_string}, as {!load_file}. *)

type bundle = Dsl.bundle
(** A program's texts as it read them: its file and every include (plain data, sent to the
    other MPI ranks). *)

val bundle : t -> bundle
(** The texts a program was loaded from. *)

val load_bundle :
  ?single:bool ->
  ?progress:(string -> unit) ->
  ?digests:bool ->
  bundle ->
  (t, Diagnostic.t list) result
(** {!Dsl.load_bundle}, as {!load_file}: the program another process loaded, from the
    texts it read (an MPI rank's copy of rank 0's program), reading no scene file. *)

val source_problem : string -> string option
(** Why a path cannot be read as a scene file, from its status alone; [None] if it can. *)

val language : t -> Dsl.t
(** The language's program. *)

val assets : t -> Compile.assets
(** The program's cache of images and meshes. *)

val file : t -> string
(** The file name the program was loaded as. *)

val animation : t -> (float * int) option
(** (fps, frames) of the animation block. *)

val bodies : t -> Dsl.body list
(** The bodies, in program order. *)

val empty : t -> bool
(** Whether the program has no statement at all. *)

val inputs : t -> string list
(** {!Dsl.inputs}: the files the program has read or named so far. *)

val named_files : t -> string list
(** {!Dsl.named_files}: every file any of its scenes may read. *)

val text_digest : t -> string
(** {!Dsl.text_digest}. *)

val input_digest : t -> string -> string
(** [input_digest p f]: the MD5 (hex) of image or mesh file [f] (named as
    {!Dsl.scene_relative} names it) as this program's scenes see it: the digest of the
    very bytes its {!assets} decoded, when they kept it; otherwise of the file on disk
    when first asked ("-" when it cannot be read). Two evaluations at the same time and
    frame of programs with the same {!text_digest} name the same files, so these digests
    are what else a frame depends on ([lancer animate --resume] and checkpoints rely on
    it). *)

(** {1 Bodies} *)

val colliders : t -> Physics.collider list
(** The static obstacles of the bodies ({!Lancer_physics.Physics.colliders} of the scene
    at time 0). A CSG object that is not a union or merge of planes, parallelograms and
    boxes makes the simulation fail with an error at its block (raised as an exception
    inside this module's error boundary: call it through {!simulate} or {!describe} to get
    it as an error). *)

val simulate : t -> until:float -> (Physics.trajectory, Diagnostic.t list) result
(** The motion of the bodies among {!colliders} under the program's [physics] block,
    computed for [[0, max until duration]] (duration: the animation's, 0 for a still). The
    animation's is made once and kept, so that every frame samples the same simulation;
    one for a later time is made for it. *)

(** {1 Scenes} *)

val describe :
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  ?progress:(string -> unit) ->
  ?cancel:Cancel.t ->
  t ->
  time:float ->
  frame:int ->
  (Description.t, Diagnostic.t list) result
(** {!Dsl.describe} with the bodies where {!simulate} has them (unless [body_state] says
    otherwise). At time 0, frame 0 it is the description the load made. *)

val scene :
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  ?progress:(string -> unit) ->
  ?cancel:Cancel.t ->
  ?index:bool ->
  t ->
  time:float ->
  frame:int ->
  (Scene.t, Diagnostic.t list) result
(** The scene at [time] and [frame]: {!describe}, then {!Lancer_render.Compile.compile}
    ([index] is its). The program is evaluated once per call, and not at all for a scene
    at time 0, frame 0 of a still without bodies: that one is the load's description. An
    animation's scene is its static part, compiled once for all of them, joined with the
    objects its other statements build at [time] ({!Dsl.describe_parts}). In a program
    loaded [~single:true], the first scene asked for is, at time 0, frame 0 of a still
    without bodies, made of the primitives its load compiled as it went
    ({!Lancer_render.Compile.finish}), or else of the load's description, let go
    ({!Dsl.release}) as the compile goes through it, object by object; any later scene
    evaluates the program again. *)

val scenes :
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  ?progress:(string -> unit) ->
  ?cancel:Cancel.t ->
  ?index:bool ->
  t ->
  times:float array ->
  frame:int ->
  (Scene.t array, Diagnostic.t list) result
(** The scenes at each of [times], all numbered [frame] (the instants of one frame), as
    {!scene} makes them: they share the static part. The errors of the first that fails.
*)

val scene_at :
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  ?progress:(string -> unit) ->
  ?cancel:Cancel.t ->
  ?index:bool ->
  t ->
  time:float ->
  frame:int ->
  (Scene.t, Diagnostic.t list) result
(** {!scene}. *)

val scene_with_files :
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  ?progress:(string -> unit) ->
  ?cancel:Cancel.t ->
  t ->
  time:float ->
  frame:int ->
  (Scene.t * string list, Diagnostic.t list) result
(** {!scene}, and the image and mesh files that scene names, sorted, as paths from the
    main file's directory. Their digests ({!input_digest}) are left to the callers that
    record them: a still without a checkpoint never reads a mesh twice. *)

val scenes_with_files :
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  ?progress:(string -> unit) ->
  ?cancel:Cancel.t ->
  t ->
  times:float array ->
  frame:int ->
  ((Scene.t * string list) array, Diagnostic.t list) result
(** {!scene_with_files} at each of [times] (seconds, in order) of frame [frame]: the
    instants of a motion-blurred frame, as {!val-scenes}. What does not change with time
    is evaluated and built once for them all, as for the frames of an animation (and for a
    still whose camera's shutter is open). *)

(** {1 For [lancer check]} *)

val summary : t -> Scene.t -> string
(** {!Lancer_description.Scene_report.summary} of [sc] (a scene of the program, whose
    description is made again), with the program's animation, bodies and warnings (those
    at time 0, colours given as 0–255 among them). *)

val warnings : t -> Scene.t -> Diagnostic.t list
(** {!Lancer_description.Scene_report.warnings} of [sc], as {!summary} prints them (the
    program's at time 0, with {!Lancer_description.Scene_report.colour_warnings}): what
    [lancer render] prints before it renders. *)

val to_json :
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  t ->
  Scene.t ->
  Yojson.Safe.t
(** {!Lancer_description.Scene_report.json} of [sc], as {!summary}; bodies are shown at
    [sc]'s time by [body_state] or else the simulation. *)

(** {1 For the command line and the job layer} *)

val truncated_physics : t -> float option
(** When the exact physics simulation stopped handling collisions after
    {!Lancer_physics.Physics.max_events} events: the time of its last event. *)

val as_scenes : builtin:bool -> t -> Scenes.t
(** The program as the job layer takes it; its [evaluate] raises
    {!Lancer_job.Job_error.Scene}. [builtin]: the program is the built-in showcase. *)
