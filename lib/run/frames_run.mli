(** [lancer animate] as a library function: an animation's frames rendered to
    [DIR/frame_0000.png …] with the job layer ({!Lancer_job.Animation}: the plan, the
    scheduling, the frames record), with its progress line and summary. [resume] skips
    frames already written for the same scene, inputs and options; [shard] renders a share
    of the frames, and shards may run at once into one directory; [video] assembles the
    frames with ffmpeg. [lancer-mpi animate] uses the same plan, names and record, so
    either command resumes the other's frames. *)

type options = {
  frames : (int * int) option;  (** [--frames A..B] *)
  resume : bool;
  video : string option;
  shard : Plan.shard option;
  format : Image.format;  (** [--format]: the frames' format (default PNG) *)
  bits : int option;  (** [--bits]: their depth; [None] the format's default *)
}

val default_options : options

val plan :
  ?getenv:(string -> string option) ->
  ?max_error:Compare.metric ->
  Options.t ->
  options ->
  Program.t * Animation.plan
(** {!Lancer_job.Animation.val-plan} for these options (and [--max-error]'s limit, part of
    the job), the scene loaded as {!Scene_file.read} says, saying how many frames a
    resumed run skips and why it renders again those a run recorded (another option, a
    changed scene or input, a missing file); with the program it loaded. Raises
    {!Lancer_job.Job_error.User}. *)

val write_frame : Animation.plan -> int -> Scene.t -> Framebuffer.t -> Counters.t -> unit
(** {!Lancer_job.Animation.write_frame}, with a warning when some samples were NaN. *)

val check_video : options -> unit
(** Refuse, before rendering, a [--video] that is not .mp4 or .gif, cannot be written,
    comes with [--shard], or needs an ffmpeg that is not on PATH. *)

val make_video : Options.t -> Animation.plan -> string -> unit
(** {!Lancer_job.Animation.make_video}, saying where the video is. *)

val wrote : ?extra:string -> Options.t -> Animation.plan -> t0:float -> unit
(** The summary line (unless quiet):
    ["wrote 24 frames to DIR in 3.10 s (0..23 at 24 fps)"], the seconds since [t0],
    [extra] added to the parenthesis. *)

val progress : Options.t -> Animation.plan -> Progress.t
(** A progress line over the frames to render, as the options ask for it. *)

val interrupted : string
(** What [lancer animate] says when interrupted: the frames already written are kept. *)

val run : ?cancel:Cancel.t -> ?max_error:Compare.metric -> Options.t -> options -> unit
(** [lancer animate]: the plan, every frame to do rendered over [--domains] domains, the
    record finished, the summary line and the video. With [max_error] (refused with
    [--samples], [--depth] or [--quality]), the settings {!Budget.choose} picks for the
    first, middle and last frames of the whole animation (whatever the range), the choice
    that costs the most rays, said in a line and used for every frame (and kept in each
    frame's record); the same in every shard, whatever the number of domains. *)
