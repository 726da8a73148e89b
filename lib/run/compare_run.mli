(** [lancer diff] and [lancer golden] as library functions: two images compared, or a
    scene rendered and held against a golden image, with what the commands print. *)

val check_tolerance : int -> float -> unit
(** Refuse a [--tolerance] outside 0–255 or a [--max-share] outside 0–1
    ({!Lancer_job.Job_error.User}). *)

val diff : ?out:string -> tolerance:int -> share:float -> string -> string -> bool
(** [lancer diff A B]: the verdict ([same], [within tolerance] or [differ]) and the
    figures, a picture of the differences written to [out]; whether the images are within
    the tolerance. Raises {!Lancer_job.Job_error.User}. *)

val golden :
  ?cancel:Cancel.t ->
  Options.t ->
  golden:string ->
  tolerance:int ->
  share:float ->
  update:bool ->
  bool
(** [lancer golden SCENE GOLDEN]: the scene rendered as [lancer render] would and compared
    with the golden PNG (refused before rendering when its size differs), or written as
    the golden with [update]; on a difference the actual and diff images are written
    beside the golden and named. Whether the render matches (or was written). Raises
    {!Lancer_job.Job_error.User} and {!Lancer_job.Job_error.Scene}. *)
