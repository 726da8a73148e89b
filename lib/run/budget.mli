(** [--max-error]: the cheapest settings (samples, adaptive threshold, depth, area-light,
    lens and shutter samples) whose error against the [reference] quality preset is
    predicted to be within a limit.

    The prediction comes from probes: the image of one pixel per k×k block (a render with
    [stride = k], each pixel exactly as the whole render computes it), rendered once at
    the reference and at each candidate. From the cheapest value of every knob, the search
    raises one knob a notch at a time, the one whose probe error falls most per ray it
    adds, until the error is within three quarters of the limit (the probes are a sample
    of the image) or every knob is at the reference's, then lowers what the climb turned
    out not to need. Settings that cost what the reference costs give way to the cheapest
    candidate within the limit itself. Mean FLIP is taken at the image's own pixels per
    degree and at [k] times fewer (a probe pixel stands for a block), the larger of the
    two.

    The search runs in two rounds: a first on about 1/2400 of the pixels (at least 128),
    then, where the first round's choice and its cost per probe allow at least three times
    as many, a second on as many probes as keep the whole search within 15% of the rays of
    the image at the first round's choice and of the image at the cheapest settings (up to
    about 1/150 of the pixels). The choice depends on rays and pixels alone, never on
    time: the same whatever the number of domains. *)

type choice = {
  limit : Compare.metric;
  settings : (string * string) list;  (** each knob's name and chosen value, as text *)
  values : (string * float) list;
      (** the same values as numbers (an adaptive threshold of 0: off), what {!apply}
          takes and an image's record keeps *)
  scene : Scene.t;  (** the scene at those settings *)
  rays : float;
      (** the predicted rays of the whole image at the choice (from the probes' rays: the
          same on any number of domains) *)
  predicted : float;  (** the probes' error, in the metric's unit *)
  seconds : float;  (** the predicted render time of the whole image at the choice *)
  reference_seconds : float;  (** and at the reference *)
  search_seconds : float;  (** the wall time of the search *)
  search_rays : int;  (** the rays of all its probe renders *)
  probes : int;  (** how many probe renders it made *)
  probe_pixels : int;  (** the pixels of a probe render of the last round *)
}

val check : Compare.metric -> unit
(** Raises {!Lancer_job.Job_error.User} for a limit that is not above 0 and within its
    metric's range (a mean FLIP under 1, an RMSE at most 255, a finite PSNR), or an SSIM.
*)

val check_options : Options.t -> resume:bool -> unit
(** Raises {!Lancer_job.Job_error.User} for options that set what [--max-error] chooses
    ([--samples], [--depth], [--quality]), or [resume] for a still (its checkpoint is of
    one set of settings). *)

val choose :
  ?cancel:Cancel.t ->
  ?pool:Pool.t option ->
  domains:int ->
  Options.t ->
  Scenes.t ->
  Scene.t ->
  time:float ->
  frame:int ->
  Compare.metric ->
  choice
(** [choose ~domains o src base ~time ~frame limit]: the choice for [base] (the scene of
    [src] at [time] and [frame] with [o]'s overrides), searched over [domains] domains (or
    on [pool], a pool the caller holds: [None] for one domain). Raises
    {!Lancer_job.Job_error.User} as {!check}. *)

val apply :
  ?cancel:Cancel.t ->
  Scenes.t ->
  Overrides.t ->
  Scene.t ->
  time:float ->
  frame:int ->
  (string * float) list ->
  Scene.t * string list
(** [apply src overrides base ~time ~frame values]: [base] (the scene of [src] at [time]
    and [frame] with [overrides]) at a choice's {!choice.values}, the same scene {!choose}
    rendered that choice with: how an animation's frames and [lancer verify] use one; with
    the files that the instants of a chosen number of shutter samples read. Raises
    {!Lancer_job.Job_error.User} as {!check_values}, and for a scene the settings do not
    fit. *)

val check_values : (string * float) list -> unit
(** Raises {!Lancer_job.Job_error.User} for a setting [--max-error] does not choose or a
    value out of its range: values read back from a file are input. *)

val record : choice -> Provenance.budget
(** What an image's record keeps of the choice. *)

val limit_value : Compare.metric -> float
(** The number a limit holds, in its metric's unit. *)

val record_of_limit : Compare.metric -> Provenance.budget
(** The limit as a record names it, with no settings. *)

val text : choice -> string
(** The line that says what was chosen: the limit, the settings, the predicted error and
    time against the reference's, and the search's time. *)

val json : choice -> Yojson.Safe.t
(** The choice for [--stats]. *)
