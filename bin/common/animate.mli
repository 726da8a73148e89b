(** [lancer animate]: render an animation's frames to [DIR/frame_0000.png …].

    With at least twice as many frames as domains, and scenes small enough that a batch of
    them fits in about 2 GB, whole frames render in parallel, one domain each; otherwise
    one after the other, each over all domains in tiles. Either way a frame's bytes are
    the same. Each frame is written atomically and recorded ({!Frameset}) with a digest of
    the scene's text and includes and of the options that change pixels, the frame's size
    and MD5, and the MD5 of the images and meshes it read, so [--resume] skips frames
    already written for the same scene, inputs and options and re-renders those that are
    missing, stale or damaged. [--shard K/N] renders a share of the frames; shards may run
    at once into one directory. [--video] assembles the frames with ffmpeg.
    [lancer-mpi animate] uses the same plan, names and manifest, so either command resumes
    the other's frames. *)

val frames_of_string : string -> (int * int, string) result
(** ["A..B"] (inclusive) or ["K"]. *)

type shard = Shard of int * int  (** [--shard K/N] *) | Slurm  (** [--shard slurm] *)

val shard_of_string : string -> (shard, string) result
(** ["K/N"] with 0 <= K < N, or ["slurm"]. *)

val slurm_shard : (string -> string option) -> int * int
(** (K, N) from a Slurm job array's environment, read through the given [getenv]: N =
    [SLURM_ARRAY_TASK_COUNT], K = ([SLURM_ARRAY_TASK_ID] − [SLURM_ARRAY_TASK_MIN]) /
    [SLURM_ARRAY_TASK_STEP] (MIN 0 and STEP 1 when unset). Raises [Cli.User_error]. *)

type options = {
  frames : (int * int) option;  (** [--frames A..B] *)
  resume : bool;
  video : string option;
  shard : shard option;
}

val default_options : options

type plan = private {
  opts : Cli.opts;
  source : string * string;  (** file name and text of the scene *)
  prog : Lancer_dsl.Dsl.t;
  dir : string;
  fps : float;
  first : int;
  last : int;
  shard : (int * int) option;
  todo : int list;
      (** the frames to render: this shard's of [first..last], less those resumed *)
  set : Frameset.t;
  inputs : (int, (string * string) list) Hashtbl.t;
      (** frames evaluated and not yet written: the files they read *)
  inputs_lock : Mutex.t;
}

val plan : ?getenv:(string -> string option) -> Cli.opts -> options -> plan
(** Load the scene, check the options and the output directory (made if missing), claim it
    for this scene ({!Frameset.open_}), and work out which frames to render: this shard's
    frames of the range ([index mod N = K]), less, with [resume], those already done for
    the same job. Raises [Cli.User_error]. *)

val frame_scene : ?cancel:Lancer.Cancel.t -> plan -> int -> Lancer.Scene.t
(** The scene of frame k (time k / fps), with the command-line overrides; the image and
    mesh files it read are kept for {!write_frame}. [cancel] stops the evaluation with
    [Sys.Break]. *)

val write_frame :
  plan -> int -> Lancer.Scene.t -> Lancer.Image.t -> Lancer.Stats.t -> unit
(** Write frame k atomically and record it in this run's journal. Safe from several
    domains at once. *)

val finish : plan -> unit
(** Close the journal; write the merged [lancer-frames.json] when every frame is done. *)

val describe_range : plan -> string
(** ["0..119 at 24 fps"], with the shard when there is one. *)

val check_video : options -> unit
(** Refuse, before rendering, a [--video] that is not .mp4 or .gif, cannot be written, or
    comes with [--shard]. *)

val make_video : plan -> string -> unit
(** Assemble the frames into a .mp4 or .gif with ffmpeg; a clear error without it. *)

val progress : plan -> Progress.t
(** A progress line over the frames to render (only on a terminal, without --quiet). *)

val interrupted : string
(** What [lancer animate] says when interrupted: the frames already written are kept. *)

val run : Cli.opts -> options -> unit
(** [lancer animate]. *)

val options_term : options Cmdliner.Term.t
(** [--frames A..B], [--resume], [--video OUT] and [--shard K/N|slurm], as [lancer] and
    [lancer-mpi] take them. *)
