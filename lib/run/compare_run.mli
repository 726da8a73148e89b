(** [lancer diff] and [lancer golden] as library functions: two images compared, or a
    scene rendered and held against a golden image, with what the commands print. *)

val check_tolerance : int -> float -> unit
(** Refuse a [--tolerance] outside 0–255 or a [--max-share] outside 0–1
    ({!Lancer_job.Job_error.User}). *)

(** The figure [lancer diff] judges by: the per-channel difference, or one of
    {!Lancer_image.Compare.metric}'s. *)
type metric = Max | Rmse | Psnr | Flip | Ssim

val metric_names : (string * metric) list
(** The names [--metric] takes: [max], [rmse], [psnr], [flip], [ssim]. *)

val judge : metric -> float option -> share:float -> int * Compare.metric option
(** [judge metric tolerance ~share]: what [--metric], [--tolerance] and [--max-share] ask
    for, as the per-channel tolerance (1 with a metric other than [Max]) and the library's
    metric; refuses a metric without its limit and a limit out of its range
    ({!Lancer_job.Job_error.User}). *)

val diff :
  ?out:string ->
  ?json:bool ->
  metric:metric ->
  tolerance:float option ->
  share:float ->
  string ->
  string ->
  bool
(** [lancer diff A B]: the verdict ([same], [within tolerance] or [differ], with the
    metric's value against its limit for a metric other than [Max]) and the figures (those
    of {!Lancer_image.Compare.pp}, the mean FLIP and the SSIM), or all of them as one JSON
    object with [json]; FLIP's error map written to [out] (grey). With [Max], [tolerance]
    is the per-channel difference (a whole number, default 1) and [share] the share of
    pixels that may exceed it; otherwise [tolerance] is the metric's limit, required.
    Whether the images are within the tolerance. Raises {!Lancer_job.Job_error.User}. *)

val golden :
  ?cancel:Cancel.t ->
  ?metric:Compare.metric ->
  Options.t ->
  golden:string ->
  tolerance:int ->
  share:float ->
  update:bool ->
  bool
(** [lancer golden SCENE GOLDEN]: the scene rendered as [lancer render] would and compared
    with the golden PNG (refused before rendering when its size differs), or written as
    the golden with [update]; on a difference the actual and diff images are written
    beside the golden and named, with the objects the changed pixels lie on
    ({!Aov_run.golden_hint}). With a [metric], the image is judged by it, and the diff
    image is FLIP's error map. Whether the render matches (or was written). Raises
    {!Lancer_job.Job_error.User} and {!Lancer_job.Job_error.Scene}. *)
