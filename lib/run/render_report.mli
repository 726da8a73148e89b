(** What a render says of itself: the summary line, the [--stats] JSON, warnings about bad
    samples and long renders, and the rays estimated before rendering that [lancer check]
    prints. *)

val summary :
  ?size:int * int ->
  ?resumed_rays:int ->
  out:string ->
  Scene.t ->
  build:float ->
  render:float ->
  workers:string ->
  Counters.t ->
  string
(** The line a render prints when done: the file, size, total, build and render seconds,
    [workers] ("2 domains"), rays and rays per second of the render; [size] is the size
    written when it is not the scene's (a crop). [resumed_rays] (default 0) of the rays
    counted were cast by an earlier run (a checkpoint's tiles): the line says how many
    this run cast, and its rays per second count only those. Where the render estimated
    its noise ({!Lancer_render.Counters.noise}), the line ends with it: "noise ≈
    0.81/255". *)

val stats_json :
  ?resumed_rays:int ->
  Options.t ->
  Scene.t ->
  build:float ->
  wall:float ->
  domains:int ->
  ranks:int ->
  Counters.t ->
  Yojson.Safe.t
(** The [--stats] JSON: [wall_seconds] (build and render), [build_seconds] ([build]:
    loading, evaluation, acceleration structure), [render_seconds] ([wall]: tracing), ray
    counts, [resumed_rays] (those of a checkpoint's tiles, as for {!summary}), rays per
    second of this run's rays, [noise] ({!Lancer_render.Counters.noise}, or null where
    nothing is stochastic), peak memory, features and options. *)

val peak_memory_kib : unit -> int option
(** The process's peak resident set (VmHWM), where /proc exists. *)

val warn_bad_samples : Counters.t -> unit
(** A warning on stderr when some samples were NaN or infinite. *)

val rays_text : float -> string
(** A ray count as a person reads it: [307 200] as "307 k", "18.4 M", "1.28 G". *)

val cost_report : Scene.t -> string
(** The estimated rays ({!Lancer_render.Cost}) of the scene as set and under each quality
    preset, with how many times the scene's own cost each is; the header says it is an
    estimate. *)

val long_render_rays : float
(** 10⁹: a render estimated above this says so before it starts. *)

val warn_long_render : Options.t -> Scene.t -> unit
(** A note on stderr (unless [--quiet]) when the estimated rays pass {!long_render_rays}.
*)
