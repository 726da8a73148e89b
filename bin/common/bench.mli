(** [lancer bench]: the speed and accuracy measurements a user runs — [domains] (the
    speed-up over domain counts), [quality] (the speed/accuracy trade of each quality
    knob, cached, with an SVG chart) and [animation] (a whole animation against one still)
    — as the options of {!Lancer_measure}'s functions. The developers' own benchmarks are
    in bench/, outside this command. *)

val cmd : int Cmdliner.Cmd.t
(** The [bench] command group. *)
