(** An animation's frames rendered to [DIR/frame_0000.png …]: the plan (which frames, of
    which shard, less those already done), each frame's scene, writing and recording each
    frame ({!Frameset}), and the scheduling of the render.

    With at least twice as many frames as domains, and scenes small enough that a batch of
    them fits in about 2 GB, whole frames render in parallel, one domain each; otherwise
    one after the other, each over all domains in tiles. Either way a frame's bytes are
    the same. Each frame is written atomically and recorded with a digest of the scene's
    text and includes and of the options that change pixels, the frame's size and MD5, and
    the MD5 of the images and meshes it read, so that a resumed run skips frames already
    written for the same scene, inputs and options and re-renders those that are missing,
    stale or damaged. Shards may run at once into one directory; lancer-mpi uses the same
    plan, names and records, so either command resumes the other's frames. *)

type plan = private {
  source : Scenes.t;
  overrides : Overrides.t;
  dir : string;
  format : Image.format;  (** the frames' format *)
  bits : int option;  (** and depth *)
  fps : float;
  first : int;
  last : int;
  shard : (int * int) option;
  todo : int list;
      (** the frames to render: this shard's of [first..last], less those resumed *)
  resumed : int;  (** this shard's frames found done and skipped *)
  stale : (string * int list) list;
      (** with [resume], the frames of [todo] that a run recorded and that are rendered
          again, by the reason ({!Frameset.why_not_done}), in order *)
  set : Frameset.t;
  inputs : (int, (string * string) list) Hashtbl.t;
      (** frames evaluated and not yet written: the files they read *)
  inputs_lock : Mutex.t;
  chosen :
    (Provenance.budget * (Scene.t -> time:float -> frame:int -> Scene.t * string list))
    option;
      (** settings chosen for every frame ({!with_settings}) *)
}

val plan :
  ?getenv:(string -> string option) ->
  ?format:Image.format ->
  ?bits:int ->
  ?job:(string * string) list ->
  dir:string option ->
  frames:(int * int) option ->
  shard:Plan.shard option ->
  resume:bool ->
  overrides:Overrides.t ->
  (unit -> Scenes.t) ->
  plan
(** [plan ~dir ~frames ~shard ~resume ~overrides load]: check the output directory (made
    if missing), the shard (a Slurm one read through [getenv]), load the scene with
    [load], check the range against its animation, refuse frames that would replace the
    scene's own files, claim the directory for this scene ({!Lancer_job.Frameset.open_}),
    and work out which frames to render: this shard's frames of the range
    ({!Lancer_job.Plan.shard_frames}), less, with [resume], those already done for the
    same job. The frames are written in [format] (default PNG; [frame_0000.exr] for EXR)
    at [bits] ({!Lancer_image.Image.file_of}), which are part of the job, as is [job]
    (what else changes every frame's pixels, named: [--max-error]'s limit). Raises
    {!Job_error.User}. *)

val with_settings :
  plan ->
  Provenance.budget ->
  (Scene.t -> time:float -> frame:int -> Scene.t * string list) ->
  plan
(** [with_settings p budget adjust]: [p] whose frames are rendered at the settings
    [--max-error] chose: each frame's scene is [adjust]ed (with the files that adds to
    what the frame read), and each frame's record keeps [budget]. *)

val frame_scene : ?cancel:Cancel.t -> plan -> int -> Scene.t
(** The scene of frame k (time k / fps), with the overrides; the image and mesh files it
    read are kept for {!write_frame}. [cancel] stops the evaluation with [Sys.Break]. *)

val frame_inputs : plan -> int -> (string * string) list option
(** The files (with their digests) frame k was made of, from {!frame_scene} until the
    frame is written. *)

val write_frame : plan -> int -> Scene.t -> Framebuffer.t -> unit
(** Write frame k atomically and record it in this run's journal. Safe from several
    domains at once. *)

val render :
  ?cancel:Cancel.t -> domains:int -> on_frame:(int -> Counters.t -> unit) -> plan -> unit
(** Render and write every frame of [todo] over a pool of [domains] domains, scheduled as
    above; [on_frame k stats] once frame k is written, from whichever domain wrote it.
    Raises [Sys.Break] once [cancel] is cancelled; the frames written by then are kept. *)

val finish : plan -> unit
(** Close the journal; write the merged [lancer-frames.json] when every frame is done. *)

val frames_text : int -> string
(** ["1 frame"], ["24 frames"]. *)

val describe_range : plan -> string
(** ["0..119 at 24 fps"], with the shard when there is one. *)

val check_video : ?format:Image.format -> shard:bool -> string -> unit
(** Refuse, before rendering, a video that is not .mp4 or .gif, cannot be written, comes
    with a shard ([shard]), would be made of frames that are not PNG ([format]), or cannot
    be made because ffmpeg is not found on PATH. *)

val make_video : plan -> string -> unit
(** Assemble the frames into a .mp4 or .gif with ffmpeg ({!check_video} found it); a clear
    error when it fails. *)
