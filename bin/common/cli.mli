(** What [lancer] and [lancer-mpi] share: the command-line options, loading a scene (or
    the embedded showcase) and handing it to the job layer ({!Lancer_job}), checking the
    outputs, writing images and statistics, and the lines they print. Errors are reported
    by {!Report}. *)

exception User_error of string
(** {!Lancer_job.Job_error.User}: a mistake the user can fix (options, files); one clear
    message, exit 1. *)

val user : ('a, unit, string, 'b) format4 -> 'a
(** [user fmt …] raises [User_error] with the formatted message. *)

type opts = {
  scene : string option;  (** None: the embedded showcase *)
  output : string option;
  width : int option;
  height : int option;
  samples : int option;
  depth : int option;
  quality : Lancer.Quality.t option;
  domains : int option;
  time : float option;
  frame : int option;
  stats : string option;
  quiet : bool;
  progress : bool;  (** report progress as lines when stderr is not a terminal *)
}

val default_opts : unit -> opts
(** Every option unset. *)

val overrides : opts -> Lancer_job.Overrides.t
(** The options that change pixels: size, samples, depth, quality. *)

type command =
  | Render
  | Animate
  | Golden
  | Bench_domains
  | Bench_quality  (** The commands that take a scene and the rendering options. *)

val term : command -> opts Cmdliner.Term.t
(** The options a command acts on, and only those (the others stay unset): [render] takes
    all of them; [animate] needs a scene and takes [-o DIR] but no [--time], [--frame] or
    [--stats]; [golden] needs a scene and writes no [-o] nor [--stats]; [bench domains]
    times the domain counts of its own [--counts], and [bench quality] sets the preset and
    the time itself. *)

val opts_term : opts Cmdliner.Term.t
(** [term Render]. *)

val resume_still : bool Cmdliner.Term.t
(** [--resume] of [render]: keep and reuse a checkpoint of finished tiles. *)

val writing : opts -> string -> (unit -> 'a) -> 'a
(** [writing o path f] runs [f] (the write of [path]) under a progress note,
    [writing PATH]: redrawn in place on a terminal and cleared after, a line with
    [--progress], nothing otherwise. A large PNG takes seconds to compress. *)

val progress : opts -> label:string -> total:int -> Progress.t
(** The progress report the options ask for: redrawn in place on a terminal, lines with
    [--progress] otherwise, nothing with [--quiet]. *)

val exits : Cmdliner.Cmd.Exit.info list
(** The exit statuses every command documents: 0, 1, 2 and 130. *)

val max_side : int
(** 65536: the largest [--width] or [--height], as in the language; refused as the option
    is read. *)

val max_domains : int
(** 128: the most domains [--domains] may ask for (the OCaml runtime's own limit). *)

val domains : opts -> int
(** [--domains N] if given (1 to {!max_domains}; raises [User_error] otherwise), else the
    recommended count for this machine. *)

val source : opts -> string * string
(** The scene's (file name, text): the file given, standard input for ["-"] (named
    ["<stdin>"], read once, its includes found from the current directory), or the
    embedded showcase. Raises [User_error] for a missing or unreadable file. *)

val load_source :
  ?progress:(string -> unit) -> ?digests:bool -> string * string -> Lancer.Program.t
(** Parse and check a scene's text; raises {!Lancer_job.Job_error.Scene} with every
    located error. Includes are found relative to the file name. [digests] is
    {!Lancer.Program.load_string}'s. *)

val load_bundle : Lancer.Program.bundle -> Lancer.Program.t
(** The program of a bundle ({!Lancer.Program.load_bundle}); raises {!Lancer_job.Job_error.Scene}. *)

val load : ?progress:(string -> unit) -> ?digests:bool -> string option -> Lancer.Program.t
(** [load_source (source …)] for a scene file, or the showcase with [None]. *)

val scene_source : opts -> Lancer.Program.t -> Lancer_job.Source.t
(** The program as the job layer takes it ({!Lancer.Program.source}); built in without a scene. *)

val default_output : opts -> string
(** [-o] if given, else the scene's base name with [.png] ([showcase.png] without a
    scene); a scene read from standard input needs [-o] (raises [User_error]). *)

val check_writable : string -> unit
(** {!Lancer_job.Files.check_writable}. *)

val check_output : ?format:Lancer.Image.format -> string -> unit
(** Refuse, before any rendering, an output with an unknown extension (or one that
    [format] contradicts), in a missing directory, that is a directory or read-only, and
    [-] when standard output is a terminal; raises [User_error]. *)

val reads : Lancer_job.Source.t -> (string * string) list
(** {!Lancer_job.Source.reads}: the files a run of this scene reads. *)

val guard_writes :
  ?distinct:bool -> reads:(string * string) list -> (string * string) list -> unit
(** {!Lancer_job.Files.guard_writes}. *)

val check_stats_name : string option -> unit
(** Refuse a [--stats] file named like a scene, image, mesh or video ([.rts], [.png], …):
    the sign that the option took the scene as its value. *)

val guard_render : opts -> Lancer_job.Source.t -> out:string -> unit
(** {!guard_writes} for a still: the image and the statistics against the scene's files.
*)

val scene_at :
  ?progress:(string -> unit) ->
  ?cancel:Lancer.Cancel.t ->
  opts ->
  Lancer_job.Source.t ->
  time:float ->
  frame:int ->
  Lancer.Scene.t
(** The scene at a time with the command-line overrides ({!Lancer_job.Source.scene});
    [progress] and [cancel] as for the language's evaluation. *)

val scene_with_files :
  ?progress:(string -> unit) ->
  ?cancel:Lancer.Cancel.t ->
  opts ->
  Lancer_job.Source.t ->
  time:float ->
  frame:int ->
  Lancer.Scene.t * string list
(** [scene_at], and the image and mesh files it read (paths; their digests are taken where
    a checkpoint records them). *)

val checkpoint :
  opts ->
  Lancer_job.Source.t ->
  out:string ->
  time:float ->
  frame:int ->
  files:string list ->
  Lancer.Scene.t ->
  Lancer_job.Checkpoint.t
(** The checkpoint of [out] for this still ({!Lancer_job.Checkpoint.start} with its key),
    saying how many tiles it brings back (unless [--quiet]). *)

val time_of : opts -> Lancer_job.Source.t -> float * int
(** The (time, frame) chosen by [--time] / [--frame] (default 0, 0):
    {!Lancer_job.Source.time_of}. *)

type encoding = {
  bits : int;  (** 8 or 16 bits per channel *)
  alpha : bool;  (** an alpha channel of coverage *)
  region : Lancer.Image.region option;  (** render only these pixels *)
  crop : bool;  (** write only the region *)
  format : Lancer.Image.format option;  (** [--format], for [-o -] *)
}
(** How the image of a still is rendered and written ([--bits], [--alpha], [--region],
    [--crop]). *)

val default_encoding : encoding
(** 8 bits, no alpha, the whole image. *)

val encoding_term : encoding Cmdliner.Term.t
(** The options [--bits 8|16], [--alpha], [--region x0,y0,x1,y1], [--crop] and
    [--format png|ppm]. *)

val is_stdout : string -> bool
(** Whether an output path is [-], standard output. *)

val check_encoding : encoding -> out:string -> Lancer.Scene.t -> unit
(** Refuse a region outside the scene's image, [--crop] without [--region], and [--alpha]
    with a PPM output; raises [User_error]. *)

val write_image :
  ?cancel:Lancer.Cancel.t ->
  ?encoding:encoding ->
  ?alpha:Float.Array.t ->
  string ->
  Lancer.Scene.t ->
  Lancer.Image.t ->
  unit
(** Encode with the scene's gamma (and [encoding]: 8 bits, whole image by default; the
    coverage [alpha] as a fourth channel) and write atomically, or to standard output for
    [-] (PNG unless [--format ppm]; a closed pipe is an error, not a signal); raises
    [User_error]. With [cancel] an interrupt during the write does not cut it short
    ({!Lancer_job.Files.uninterrupted}). *)

val build : opts -> ((string -> unit) -> 'a) -> 'a * float
(** [build o f] runs [f say], the building of a scene (loading, evaluation, acceleration
    structure), and times it: [say what] shows what it is doing ("building: what…",
    redrawn in place on a terminal, a line with [--progress], nothing otherwise), and the
    line is cleared when [f] returns or raises. The result and the seconds it took. *)

val summary :
  ?size:int * int ->
  out:string ->
  Lancer.Scene.t ->
  build:float ->
  render:float ->
  workers:string ->
  Lancer.Stats.t ->
  string
(** The line a render prints when done: the file, size, total, build and render seconds,
    [workers] ("2 domains"), rays and rays per second of the render; [size] is the size
    written when it is not the scene's (a crop). *)

val rays_text : float -> string
(** A ray count as a person reads it: [307 200] as "307 k", "18.4 M", "1.28 G". *)

val cost_report : Lancer.Scene.t -> string
(** The estimated rays ({!Lancer.Cost}) of the scene as set and under each quality preset,
    with how many times the scene's own cost each is; the header says it is an estimate.
*)

val long_render_rays : float
(** 10⁹: a render estimated above this says so before it starts. *)

val warn_long_render : opts -> Lancer.Scene.t -> unit
(** A note on stderr (unless [--quiet]) when the estimated rays pass {!long_render_rays}.
*)

val stats_json :
  opts ->
  Lancer.Scene.t ->
  build:float ->
  wall:float ->
  domains:int ->
  ranks:int ->
  Lancer.Stats.t ->
  Yojson.Safe.t
(** The [--stats] JSON: [wall_seconds] (build and render), [build_seconds] ([build]:
    loading, evaluation, acceleration structure), [render_seconds] ([wall]: tracing), ray
    counts, rays per second of the render, peak memory, features and options. *)

val write_json : ?cancel:Lancer.Cancel.t -> string -> Yojson.Safe.t -> unit
(** {!Lancer_job.Files.write_json}. *)

val peak_memory_kib : unit -> int option
(** The process's peak resident set (VmHWM), where /proc exists. *)

val warn_bad_samples : Lancer.Stats.t -> unit
(** A warning on stderr when some samples were NaN or infinite. *)

val negative_value_hint : string array -> string option
(** For a command line such as [--time -5], which the parser refuses ([-5] reads as an
    option): the hint to write [--time=-5]. *)

val status_of_eval : int -> int
(** Map cmdliner's own statuses onto lancer's: a command-line mistake (124) is a user
    error, 1; cmdliner's internal error (125) is 2. *)
