(** The command line that [lancer] and [lancer-mpi] share: the options of each command as
    cmdliner terms over {!Lancer.Options.t} (what they do is {!Lancer_run}'s), the exit
    statuses they document, and the hint for a negative value. *)

type command =
  | Render
  | Animate
  | Golden
  | Bench_domains
  | Bench_quality  (** The commands that take a scene and the rendering options. *)

val term : command -> Lancer.Options.t Cmdliner.Term.t
(** The options a command acts on, and only those (the others stay unset): [render] takes
    all of them; [animate] needs a scene and takes [-o DIR] but no [--time], [--frame] or
    [--stats]; [golden] needs a scene and writes no [-o] nor [--stats]; [bench domains]
    times the domain counts of its own [--counts], and [bench quality] sets the preset and
    the time itself. *)

val size : (int option * int option) Cmdliner.Term.t
(** [--width W] and [--height H] alone (1 to 65536 each), for [check]. *)

val resume_still : bool Cmdliner.Term.t
(** [--resume] of [render]: keep and reuse a checkpoint of finished tiles. *)

val encoding_term : Lancer.Output.encoding Cmdliner.Term.t
(** The options [--bits 8|16], [--alpha], [--region x0,y0,x1,y1], [--crop] and
    [--format png|ppm]. *)

val aov_term : string option Cmdliner.Term.t
(** [--aov object,depth,normal] of [render], as written: the names are checked when the
    command runs ({!Lancer.Aov_run.parse}). *)

val max_error_term : Lancer.Compare.metric option Cmdliner.Term.t
(** [--max-error E] and [--metric flip|rmse|psnr] of [render]: the limit, checked when the
    command runs ({!Lancer.Budget.check}); [--metric] alone changes nothing. *)

val frames_term : Lancer.Frames_run.options Cmdliner.Term.t
(** [--frames A..B], [--resume], [--video OUT] and [--shard K/N|slurm] of [animate], as
    [lancer] and [lancer-mpi] take them. *)

val bug_tracker : string
(** Where bugs are reported: the project's issue tracker. *)

val bugs : Cmdliner.Manpage.block list
(** A man page's BUGS section, naming {!bug_tracker}. *)

val exits : Cmdliner.Cmd.Exit.info list
(** The exit statuses every command documents: 0, 1, 2 and 130. *)

val envs : Cmdliner.Cmd.Env.info list
(** The environment variables every command reads, for the man pages. *)

val slurm_envs : Cmdliner.Cmd.Env.info list
(** What [--shard slurm] reads. *)

val negative_value_hint : string array -> string option
(** For a command line such as [--time -5], which the parser refuses ([-5] reads as an
    option): the hint to write [--time=-5]. *)

val status_of_eval : int -> int
(** Map cmdliner's own statuses onto lancer's: a command-line mistake (124) is a user
    error, 1; cmdliner's internal error (125) is 2. *)
