(** The options of a render as plain data: what [lancer render], [animate], [golden],
    [watch] and [bench] take on their command lines (each reads only those it acts on),
    and what follows from them alone. *)

type t = {
  scene : string option;  (** None: the built-in showcase; ["-"]: standard input *)
  output : string option;
  width : int option;
  height : int option;
  samples : int option;
  depth : int option;
  quality : Quality.t option;
  domains : int option;
  time : float option;
  frame : int option;
  stats : string option;
  quiet : bool;
  progress : bool;  (** report progress as lines when stderr is not a terminal *)
}

val default : t
(** Every option unset. *)

val overrides : t -> Overrides.t
(** The options that change pixels: size, samples, depth, quality. *)

val max_side : int
(** 65536: the largest [--width] or [--height], as in the language. *)

val max_domains : int
(** 128: the most domains [--domains] may ask for (the OCaml runtime's own limit). *)

val domains : t -> int
(** [--domains N] if given (1 to {!max_domains}; raises {!Lancer_job.Job_error.User}
    otherwise), else the recommended count for this machine. *)

val time_of : t -> Scenes.t -> float * int
(** The (time, frame) chosen by [--time] / [--frame] (default 0, 0):
    {!Lancer_job.Scenes.time_of}. *)

val at_start : t -> bool
(** Whether the options ask for the scene at time 0, frame 0 (neither [--time] nor
    [--frame], or either at 0): the one scene a still's program, loaded for one scene,
    makes as it is loaded. *)

val scene_at :
  ?progress:(string -> unit) ->
  ?cancel:Cancel.t ->
  t ->
  Scenes.t ->
  time:float ->
  frame:int ->
  Scene.t
(** The scene at a time with the options' overrides ({!Lancer_job.Scenes.scene});
    [progress] and [cancel] as for the language's evaluation. *)
