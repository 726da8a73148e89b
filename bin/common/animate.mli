(** [lancer animate]: render an animation's frames to [DIR/frame_0000.png …] with the job
    layer ({!Lancer_job.Animation}: the plan, the scheduling, the frames record), printing
    its progress and summary. [--resume] skips frames already written for the same scene,
    inputs and options; [--shard K/N] renders a share of the frames, and shards may run at
    once into one directory; [--video] assembles the frames with ffmpeg.
    [lancer-mpi animate] uses the same plan, names and record, so either command resumes
    the other's frames. *)

val frames_of_string : string -> (int * int, string) result
(** ["A..B"] (inclusive) or ["K"]: {!Lancer_job.Plan.frames_of_string}. *)

type options = {
  frames : (int * int) option;  (** [--frames A..B] *)
  resume : bool;
  video : string option;
  shard : Lancer_job.Plan.shard option;
}

val default_options : options

val plan :
  ?getenv:(string -> string option) ->
  Cli.opts ->
  options ->
  Lancer.Program.t * Lancer_job.Animation.plan
(** {!Lancer_job.Animation.plan} for these options, the scene loaded as {!Cli.source}
    says, saying how many frames a resumed run skips; with the program it loaded. Raises
    [Cli.User_error]. *)

val write_frame :
  Lancer_job.Animation.plan ->
  int ->
  Lancer.Scene.t ->
  Lancer.Image.t ->
  Lancer.Stats.t ->
  unit
(** {!Lancer_job.Animation.write_frame}, with a warning when some samples were NaN. *)

val check_video : options -> unit
(** Refuse, before rendering, a [--video] that is not .mp4 or .gif, cannot be written, or
    comes with [--shard]. *)

val make_video : Cli.opts -> Lancer_job.Animation.plan -> string -> unit
(** {!Lancer_job.Animation.make_video}, saying where the video is. *)

val progress : Cli.opts -> Lancer_job.Animation.plan -> Progress.t
(** A progress line over the frames to render (only on a terminal, without --quiet). *)

val interrupted : string
(** What [lancer animate] says when interrupted: the frames already written are kept. *)

val run : Report.stop -> Cli.opts -> options -> unit
(** [lancer animate]. *)

val options_term : options Cmdliner.Term.t
(** [--frames A..B], [--resume], [--video OUT] and [--shard K/N|slurm], as [lancer] and
    [lancer-mpi] take them. *)
