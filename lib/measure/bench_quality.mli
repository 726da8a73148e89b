(** [lancer bench quality]: the scene rendered across each quality knob (samples, adaptive
    threshold, depth, soft-shadow, lens and shutter samples, the presets), each with its
    wall time, rays and error against a reference render (RMSE, PSNR, share of pixels off
    by more than 1/255). The reference image and the measured rows are cached under
    [$XDG_CACHE_HOME/lancer] (or [~/.cache/lancer]), keyed by the scene text, the size and
    options, the build of the running executable and the host. *)

val run : Lancer.Options.t -> json:bool -> svg:string option -> fresh:bool -> unit
(** Measure (or read from the cache, unless [fresh]) the rows of the options' scene at
    time 0, and print them as a Markdown table, or JSON with [json]; with [svg], also draw
    time against PSNR there ({!Svg}). Raises {!Lancer.Job_error.User} and
    {!Lancer.Job_error.Scene}. *)
