(** [lancer bench]: measured speed and the speed/accuracy trade, as Markdown tables, JSON,
    or an SVG chart.

    - [domains]: wall time of one scene over a list of domain counts, median of several
      runs, with the speed-up over one domain.
    - [quality]: the scene rendered across each knob (samples, adaptive threshold, depth,
      soft-shadow samples, quality presets), each with its wall time, rays and error
      against a reference render (RMSE, PSNR, share of pixels off by more than 1/255). The
      reference render and the measured rows are cached under [$XDG_CACHE_HOME/lancer] (or
      [~/.cache/lancer]), keyed by the scene text, the size and options, the build of the
      executable and the host; [--fresh] ignores the cache.
    - [physics]: a ball dropped from 1 m with restitution 1 and 0.8, simulated by each
      method and step, against its closed-form motion: position, impact-time and apex
      errors, and the cost (wall time, steps, events).
    - [scaling]: random spheres against the sphere count, the domain count and the image
      size: build and render times, rays per second, peak memory, each configuration in a
      child process so that its peak memory is its own.
    - [animation]: a whole [lancer animate] of a scene against one [lancer render] of it,
      each a child process, and their ratio.
    - [language]: the scene language's evaluation of a 3-million-iteration loop, beside
      the same loop in CPython when [python3] is on the PATH, and of a million sphere
      blocks, as many with a material expression each, and as many rotated boxes in
      translated groups (in this process: time, words allocated and held per block). *)

val domains_cmd : Lancer.Options.t -> int list -> int -> bool -> unit
(** [domains_cmd opts counts repeat json]. *)

val quality_cmd : Lancer.Options.t -> bool -> string option -> bool -> unit
(** [quality_cmd opts json svg fresh]. *)

val physics_cmd : float list -> float -> float -> bool -> unit
(** [physics_cmd rates until sample_rate json]: fixed steps of 1/rate s. *)

val sphere_field : int -> Lancer.Primitive.t list * Lancer.Camera.t * Lancer.Light.t list
(** [sphere_field n]: the scene of [scaling]: [n] random spheres from a fixed seed,
    uniform in a cube of side n^(1/3), radii in [0.1, 0.4], the camera outside the cube
    and one point light. *)

val cmd : int Cmdliner.Cmd.t
(** The [bench] command group. *)
