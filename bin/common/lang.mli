(** The scene language as the command line uses it: the one module of [lancer] and
    [lancer-mpi] that calls {!Lancer_dsl}. It loads a program and hands the job layer the
    functions that make its scenes ({!Lancer_job.Source.t}). *)

type program = Lancer_dsl.Dsl.t
(** A scene's program, parsed and checked. *)

type error = Lancer.Diagnostic.t
(** A located error of a scene. *)

val source_problem : string -> string option
(** Why a path cannot be read as a scene file, from its status alone; [None] if it can. *)

val load :
  ?progress:(string -> unit) ->
  ?digests:bool ->
  filename:string ->
  string ->
  (program, error list) result
(** Parse and check a scene's text; includes are found relative to [filename]. With
    [digests] (default [true]) the program keeps the MD5 of every image and mesh it decodes,
    for the records of frames and checkpoints ({!Lancer.Program.load_string}). *)

type bundle = Lancer_dsl.Dsl.bundle
(** A program's texts as it read them: its file and every include (plain data, sent to
    the other MPI ranks). *)

val bundle : program -> bundle
(** The texts a program was loaded from. *)

val load_bundle : ?progress:(string -> unit) -> bundle -> (program, error list) result
(** The program of a bundle, reading no scene file: the same program whatever the files
    on this machine say now. *)

val animation : program -> (float * int) option
(** (fps, frames) of the animation block. *)

val inputs : program -> string list
(** The files the program has read so far. *)

val truncated_physics : program -> float option
(** When the exact physics simulation stopped handling collisions after
    {!Lancer.Physics.max_events} events: the time of its last event. *)

val scene_at :
  ?index:bool -> program -> time:float -> frame:int -> (Lancer.Scene.t, error list) result
(** The scene as the file sets it (no overrides). *)

val single_scene : program -> unit
(** The program is loaded for one scene only (a still's render): the load's description
    may be let go as that scene is compiled. *)

val summary : program -> Lancer.Scene.t -> string
(** What [lancer check] prints about a scene. *)

val to_json : program -> Lancer.Scene.t -> Yojson.Safe.t
(** The evaluated scene as JSON ([lancer check --json]). *)

val source : builtin:bool -> program -> Lancer_job.Source.t
(** The program as the job layer takes it; its [evaluate] raises
    {!Lancer_job.Job_error.Scene}. [builtin]: the program is the built-in showcase. *)
