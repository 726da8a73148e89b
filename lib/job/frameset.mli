(** The record of an animation's frames in its output directory: which frames are done,
    for which scene and options, shared by any number of runs at once.

    [DIR/lancer-frames.d/] holds one journal per run ([HOST-PID-RAND.jsonl]): a line per
    frame written, with the job's digest (scene text, includes and pixel options), the
    frame's size and MD5, and the MD5 of each image and mesh that frame read. A journal
    has one writer and is only appended to (each line written whole; synced at most once a
    second and when closed), so runs never overwrite each other's entries, on a local disk
    or on NFS, and recording a frame costs the same whatever the number of frames. Readers
    merge every journal (and the view below). A frame counts as done when some entry has
    the current job, the file on disk is a regular file of that size and MD5, and every
    input it read still has its MD5.

    [DIR/lancer-frames.d/scene.json] names the scene the directory belongs to (the scene
    file's base name); it is created once, atomically (a hard link of a complete file,
    which NFS performs on the server), and a run of another scene into the directory is
    refused. [DIR/lancer-frames.json] is the merged view, one entry per frame in order,
    written (atomically) by the run that finds every frame of the animation done; its
    bytes depend only on the frames, not on how many runs made them. *)

type t

val frame_name : ?ext:string -> int -> string
(** [frame_0042.png] ([ext], default ["png"], the frames' extension). *)

val journal_dir : string
(** ["lancer-frames.d"]. *)

val view_name : string
(** ["lancer-frames.json"]. *)

val open_ :
  ?ext:string ->
  ?made_with:(string * string) list ->
  dir:string ->
  scene:string ->
  job:string ->
  count:int ->
  unit ->
  t
(** Claim [dir] (an existing directory) for the scene named [scene], or join it if it
    already holds that scene's frames, and read what every run recorded; its frames are
    [frame_NNNN.ext] (default [png]). [made_with] names what the job's digest is made of
    (["scene"] for the scene's text, an option's name such as ["--width"] for its value,
    ["-"] when not given); each entry keeps it, so that {!why_not_done} can say what
    changed. Raises {!Lancer_job.Job_error.User} when [dir] holds another scene's frames
    or cannot be used. *)

val is_done : t -> int -> input_digest:(string -> string) -> bool
(** Whether frame k is on disk as an entry of this job recorded it, with every input it
    read still having the recorded MD5 ([input_digest f] is the MD5 of input [f] now). *)

val why_not_done : t -> int -> input_digest:(string -> string) -> string option
(** Why frame k, which a run recorded, is not done now, in words: what differs between the
    job it was made for and this one (["--width was 64, is now 32"],
    ["the scene (or a file it includes) has changed"]), an input it read that has changed,
    or its file missing or not the one written; [None] when it is done or no run recorded
    it. *)

val record : t -> int -> written:Image.written -> inputs:(string * string) list -> unit
(** Record frame k, just written, in this run's journal, with the size and MD5 of the
    bytes this run wrote ([written], digested from those bytes, not read back): a run that
    replaced the file since is not taken for this one. Safe to call from several domains.
    Raises {!Lancer_job.Job_error.User} if the journal cannot be written. *)

val drop_view : t -> unit
(** Remove the merged view: frames are about to change. *)

val finish : t -> input_digest:(string -> string) -> bool
(** Close this run's journal, merge every journal again, and when every frame of the
    animation is done write the merged view; whether it was. *)

val close : t -> unit
(** Close this run's journal (after an error or an interrupt). *)
