(** [lancer render] as a library function: a still's whole pipeline, from the scene file
    to the image, its statistics and its summary line (load → evaluate → compile →
    checkpoint → render → write), and its steps, which [lancer-mpi render] shares. *)

type built = {
  program : Program.t;
  source : Scenes.t;  (** the program as the job layer sees it *)
  scene : Scene.t;  (** at the chosen time, with the options' overrides *)
  files : string list;  (** the images and meshes that scene read *)
  time : float;
  frame : int;
  seconds : float;  (** the build's wall time: loading, evaluation, structure *)
}
(** A still's scene, built. *)

val check_outputs : ?format:Image.format -> Options.t -> out:string -> unit
(** Refuse, before any work, an image output ({!Output.check_output}) or a [--stats] file
    that cannot be written or is named like an input. *)

val build : ?digests:bool -> Options.t -> built
(** Load the scene ({!Scene_file.load}; [digests] as there, default [true]), evaluate it
    at the options' time with their overrides and compile it, saying what it does on the
    progress channel ({!Progress.build}). The program is loaded for this one scene
    ([~single:true]), and the garbage of a large evaluation is given back before the image
    is allocated when the heap would otherwise grow past its peak, unless the image is
    under a sixteenth of the heap (a preview, which cannot raise the peak by more). *)

val checkpoint : Options.t -> built -> out:string -> Checkpoint.t
(** The checkpoint of [out] for this still ({!Lancer_job.Checkpoint.start} with its key),
    saying how many tiles it brings back (unless [--quiet]). *)

val record :
  ?max_error:Provenance.budget ->
  Options.t ->
  built ->
  Output.encoding ->
  out:string ->
  Provenance.t
(** The record of the image [out] of this still ({!Lancer_job.Provenance.make}), with what
    [--max-error] chose. *)

val finish :
  ?cancel:Cancel.t ->
  ?encoding:Output.encoding ->
  ?alpha:Float.Array.t ->
  ?record:Provenance.t ->
  ?extra:(string * Yojson.Safe.t) list ->
  Options.t ->
  out:string ->
  checkpoint:Checkpoint.t option ->
  build:float ->
  wall:float ->
  domains:int ->
  ranks:int ->
  workers:string ->
  Scene.t ->
  Framebuffer.t ->
  Counters.t ->
  unit
(** What follows a still's last tile: the image written with [record]
    ({!Output.write_image}, under a progress note), the checkpoint removed, a warning for
    bad samples, the [--stats] JSON ({!Render_report.stats_json} and [extra] fields) and,
    unless [--quiet], the summary line ({!Render_report.summary}; on stderr when the image
    goes to standard output). *)

val run :
  ?cancel:Cancel.t ->
  ?aov:Aov_run.kind list ->
  ?max_error:Compare.metric ->
  Options.t ->
  resume:bool ->
  Output.encoding ->
  unit
(** [lancer render]: the output checked, the scene built, the writes guarded, the image
    rendered over [--domains] domains (from a checkpoint with [resume]) with a progress
    line, then {!finish}; then the [aov] images beside it ({!Aov_run.write}), which do not
    change the image's bytes. With [max_error], the settings are those {!Budget.choose}
    picks for that limit (refused with [--samples], [--depth], [--quality] or [resume]),
    said in a line before the render and in the [--stats] JSON as [max_error], and kept in
    the image's record ({!Budget.record}) so that [lancer verify] renders the same
    settings. Raises {!Lancer_job.Job_error.User} and {!Lancer_job.Job_error.Scene};
    [Sys.Break] when [cancel] is cancelled. *)
