(** [lancer animate]: render an animation's frames to [DIR/frame_0000.png …].

    With at least twice as many frames as domains, and scenes small enough that a batch
    of them fits in about 2 GB, whole frames render in parallel, one domain each;
    otherwise one after the other, each over all domains in tiles. Either
    way a frame's bytes are the same. Each frame is
    written atomically, and a manifest ([DIR/lancer-frames.json]) records for each frame
    a digest of the scene (with its includes, images and meshes), the options that change
    pixels and the frame number, so
    [--resume] skips frames already written for the same scene and options and re-renders
    those that are missing or stale. [--video] assembles the frames with ffmpeg.
    [lancer-mpi animate] uses the same plan, names and manifest, so either command
    resumes the other's frames. *)

val frames_of_string : string -> (int * int, string) result
(** ["A..B"] (inclusive) or ["K"]. *)

type plan = private {
  opts : Cli.opts;
  source : string * string;  (** file name and text of the scene *)
  prog : Lancer_dsl.Dsl.t;
  inputs : string;  (** {!Lancer_dsl.Dsl.inputs_digest}: the scene, its includes, images and meshes *)
  dir : string;
  fps : float;
  first : int;
  last : int;
  todo : int list;  (** the frames to render: all of [first..last], less those resumed *)
  mutable manifest : (string * string) list;  (** frame file name → digest *)
}

val plan : Cli.opts -> frames:(int * int) option -> resume:bool -> plan
(** Load the scene, check the options and the output directory (made if missing), and
    work out which frames to render. Raises [Cli.User_error]. *)

val frame_scene : plan -> int -> Lancer.Scene.t
(** The scene of frame k (time k / fps), with the command-line overrides. *)

val write_frame : plan -> int -> Lancer.Scene.t -> Lancer.Image.t -> Lancer.Stats.t -> unit
(** Write frame k atomically and record it in the manifest (also written atomically). *)

val check_video : string option -> unit
(** Refuse, before rendering, a [--video] that is not .mp4 or .gif or cannot be written. *)

val make_video : plan -> string -> unit
(** Assemble the frames into a .mp4 or .gif with ffmpeg; a clear error without it. *)

val progress : plan -> Progress.t
(** A progress line over the frames to render (only on a terminal, without --quiet). *)

val interrupted : string
(** What [lancer animate] says when interrupted: the frames already written are kept. *)

val run : Cli.opts -> frames:(int * int) option -> resume:bool -> video:string option -> unit
(** [lancer animate]. *)

val options_term : ((int * int) option * bool * string option) Cmdliner.Term.t
(** [--frames A..B], [--resume] and [--video OUT], as [lancer] and [lancer-mpi] take them. *)
