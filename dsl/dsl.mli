(** The [.rts] scene language, end to end: load a script (and its includes), check it, and
    evaluate it into a {!Lancer.Scene.t} at any animation time.

    This is the one boundary of the language: whatever the input, these functions return
    [Ok] or located {!Error.t}s and never raise, but for [Sys.Break] (an interrupt that
    came during loading or evaluation, which the caller answers). A program is evaluated
    once when it is loaded (at time 0, frame 0), so every error a still scene can have is
    reported by {!load_file}; errors that depend on [time] appear in {!scene_at}. *)

open Lancer

type t
(** A parsed, checked program, ready to be evaluated at any time. *)

val load_file : string -> (t, Error.t list) result
(** [load_file path] reads, parses and checks [path]: the whole program against the fields
    of each block kind ({!Static_check}, code that does not run included), then its
    evaluation at time 0; the errors of both, each once, in source order. Included files
    are found relative to the file that includes them. Errors name files as the paths were
    written. The scene and every include must be a regular file of at most
    {!max_source_bytes}: a device, a FIFO or a larger file is refused from its status,
    before it is opened. *)

val max_source_bytes : int
(** 64 MiB: the largest scene or included file. *)

val source_problem : string -> string option
(** [source_problem path] is why [path] cannot be read as a scene file (missing, not a
    regular file, larger than {!max_source_bytes}), from its status alone; [None] if it
    can. *)

val load_string :
  ?progress:(string -> unit) -> ?filename:string -> string -> (t, Error.t list) result
(** [load_string ~filename text] is as {!load_file} for [text], named [filename] (default
    ["<string>"]; includes are relative to its directory). [progress] is told how many
    objects a long check has built so far. *)

val scene_at :
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  ?progress:(string -> unit) ->
  ?cancel:Cancel.t ->
  t ->
  time:float ->
  frame:int ->
  (Scene.t, Error.t list) result
(** [scene_at p ~time ~frame] evaluates [p] with [time] (seconds) and [frame] bound.
    Bodies move as {!simulate} computes them (once per program, then sampled).
    [body_state name t], when given, replaces the simulation: it gives (position,
    velocity) of body [name] at time [t]; where it answers [None] a body sits at its
    initial centre with its initial velocity. A body's sphere is rendered at its position.
    Errors at any instant but time 0, frame 0 end with [(at frame K, time T s)].
    [progress], when given, is told what a long build is doing ("evaluating the scene:
    131072 objects so far", "building the acceleration structure over 1000000 objects").
    [cancel] is polled as the program runs: once it is cancelled, evaluation stops with
    [Sys.Break]. *)

val animation : t -> (float * int) option
(** (fps, frames) of the [animation] block; [None] without one. *)

val file : t -> string
(** The file name the program was loaded as. *)

val inputs : t -> string list
(** The files the program has read so far, sorted: its own, its includes, and the images
    and meshes it loaded (those used only at some times once a scene at such a time was
    made). Paths are as they were resolved: relative to the scene as it was named. *)

val text_digest : t -> string
(** A digest of the program's text and its included files' (each include known by its path
    from the main file's directory), but not of the path the program was loaded as:
    [./a.rts] and [a.rts] have the same digest. *)

val scene_with_files :
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  ?progress:(string -> unit) ->
  ?cancel:Cancel.t ->
  t ->
  time:float ->
  frame:int ->
  (Scene.t * (string * string) list, Error.t list) result
(** {!scene_at}, and the image and mesh files that evaluation used, sorted: each as (its
    path from the main file's directory, {!input_digest} of it). Two evaluations at the
    same time and frame of programs with the same {!text_digest} use the same files, so
    these digests are what else a frame depends on ([lancer animate --resume] relies on
    it). *)

val input_digest : t -> string -> string
(** [input_digest p f]: the MD5 (hex) of file [f], named as {!scene_with_files} names it;
    ["-"] when it cannot be read. Computed once per program and file. *)

(** {1 For the physics engine} *)

type physics_method = Eval.physics_method = Exact | Verlet | Euler

type physics = Eval.physics = {
  gravity : Vec3.t;  (** m/s²; default (0, −9.81, 0) *)
  method_ : physics_method;  (** default [Exact] *)
  step : float;  (** seconds, for the fixed-step methods; default 1/240 *)
}

type body = Eval.body = {
  name : string;
  center : Vec3.t;  (** initial world-space centre (transforms applied) *)
  radius : float;  (** world-space radius *)
  material : Material.t;
  velocity : Vec3.t;  (** initial velocity, m/s; default (0, 0, 0) *)
  mass : float;  (** kg, > 0; default 1 *)
  restitution : float;  (** in [0, 1]; default 0.9; a pair uses the product *)
  loc : Loc.t;  (** where the body is defined *)
}

val bodies : t -> body list
(** The bodies of the program (evaluated at time 0), in program order. In every scene from
    {!scene_at}, the body spheres are the last [List.length (bodies p)] objects, in this
    order; the objects before them are static (obstacles for the simulation). *)

val physics : t -> physics option
(** The [physics] block; [None] without one (the engine should then use
    {!default_physics}). *)

val default_physics : physics
(** The physics when the scene has no [physics] block: gravity (0, −9.81, 0), the exact
    method, step 1/240. *)

val colliders : t -> Physics.collider list
(** The static obstacles of the bodies: every plane, parallelogram and box of the scene at
    time 0, in world space (a rotated box as its six faces), and the members of a union or
    merge made only of those. Other shapes are not obstacles; a CSG object that is not
    such a union or merge makes the simulation fail with an error at its block (raised as
    an exception inside this module's error boundary: call it through {!simulate} or
    {!scene_at} to get it as an error). *)

val simulate : t -> until:float -> (Physics.trajectory, Error.t list) result
(** The motion of the bodies among {!colliders} under {!val-physics}, computed for
    [[0, max until duration]] (duration: the animation's, 0 for a still) and kept, so that
    every frame samples the same simulation. *)

(** {1 For [lancer check]} *)

val warnings : t -> Scene.t -> Error.t list
(** What is legal but likely a mistake: an empty file, a scene without objects or without
    lights, a loop that runs zero times (at time 0). *)

val summary :
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) -> t -> Scene.t -> string
(** A few lines on what the scene holds: image size, sampling (jitter, adaptive), frames,
    objects by kind, lights, distinct materials, bodies, and which {!Lancer.Features} it
    uses; then its {!warnings}. *)

val to_json :
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  t ->
  Scene.t ->
  Yojson.Safe.t
(** The evaluated scene at [scene]'s time: settings, camera, lights, every object with its
    kind, fields (object space, as written), transforms and material, bodies, physics,
    animation and features. Settings come from [scene] (so command-line overrides show).
*)
