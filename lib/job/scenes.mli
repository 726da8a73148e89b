(** The scenes a job renders: not a program, but what the job layer asks of one (the scene
    at a time, the files it read and their digests), as functions that
    {!Lancer_program.Program.as_scenes} supplies. The job layer never reads a scene's
    text; how a program becomes a {!Lancer_render.Scene.t} is the language's business
    alone. *)

type t = {
  file : string;
      (** the scene's file name as given (["<stdin>"] for standard input, the file name of
          the built-in showcase for it) *)
  builtin : bool;  (** the built-in showcase: no file of the user's *)
  animation : (float * int) option;  (** frames per second and frame count, if any *)
  evaluate :
    progress:(string -> unit) option ->
    cancel:Cancel.t option ->
    time:float ->
    frame:int ->
    Scene.t * string list;
      (** the scene at a time, as the file sets it, and the image and mesh files it read
          (their MD5s come from [input_digest] where they are recorded); raises
          {!Job_error.Scene} for its located errors *)
  inputs : unit -> string list;
      (** the files read so far: the scene, its includes, images and meshes *)
  names : unit -> string list;
      (** every file some scene of the program may read, at any time: a superset of what
          any frame reads, known before any frame is made *)
  text_digest : unit -> string;  (** a digest of the scene's text and includes *)
  input_digest : string -> string;
      (** the MD5 of an input file as this run's scenes read it (see
          {!Lancer_program.Program.input_digest}) *)
}

val scene :
  ?progress:(string -> unit) ->
  ?cancel:Cancel.t ->
  t ->
  Overrides.t ->
  time:float ->
  frame:int ->
  Scene.t * string list
(** [evaluate], then the overrides ({!Overrides.apply}). When the scene's camera has an
    open shutter ({!Lancer_description.Camera.motion_blur}, after the overrides), also the
    scenes at its instants ({!Lancer_description.Camera.shutter_times}: [time] + s/fps,
    fps the animation's or 24 without one), evaluated and overridden alike and given as
    the scene's {!Lancer_render.Scene.moments}; the files are those of them all. *)

val with_instants :
  ?progress:(string -> unit) ->
  ?cancel:Cancel.t ->
  t ->
  Overrides.t ->
  Scene.t ->
  time:float ->
  frame:int ->
  Scene.t * string list
(** [with_instants t o sc ~time ~frame]: [sc] (the scene at [time] and [frame], the
    overrides applied) with the scenes at its open shutter's instants, as {!scene} makes
    them, and the files they read; [sc] and no file for a closed shutter. *)

val reads : t -> (string * string) list
(** The files a run of this scene reads, as (path, what it is): the scene file (not for
    the built-in showcase), its includes, images and meshes loaded so far. *)

val max_time : float
(** 1e9 s: the largest time in magnitude (the frame number must fit an integer). *)

val time_of : t -> time:float option -> frame:int option -> float * int
(** The (time, frame) of a still chosen by [--time] or [--frame] (default 0, 0): a time
    gives the frame under way then (24 fps without an animation block); a frame needs an
    animation that has it. Raises {!Job_error.User}. *)
