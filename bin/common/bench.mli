(** [lancer bench]: measured speed and the speed/accuracy trade, as Markdown tables,
    JSON, or an SVG chart.

    - [domains]: wall time of one scene over a list of domain counts, median of several
      runs, with the speed-up over one domain.
    - [quality]: the scene rendered across each knob (samples, adaptive threshold,
      depth, soft-shadow samples, quality presets), each with its wall time, rays and
      error against a reference render (RMSE, PSNR, share of pixels off by more than
      1/255). The reference render is cached under [$XDG_CACHE_HOME/lancer] (or
      [~/.cache/lancer]), keyed by the scene text and size. *)

val domains_cmd : Cli.opts -> int list -> int -> bool -> unit
(** [domains_cmd opts counts repeat json]. *)

val quality_cmd : Cli.opts -> bool -> string option -> unit
(** [quality_cmd opts json svg]. *)

val cmd : int Cmdliner.Cmd.t
(** The [bench] command group. *)
