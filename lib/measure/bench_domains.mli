(** [lancer bench domains]: the wall time of one render over several domain counts, median
    of several runs, with the speed-up over one domain, and on one domain the minor words
    allocated per ray; a Markdown table or JSON. *)

val run : Lancer.Options.t -> counts:int list -> repeat:int -> json:bool -> unit
(** Measure the scene of the options (the showcase without one) at their time, size,
    samples and depth, on each domain count of [counts] ([repeat] runs each, after a
    warm-up), and print the table, or JSON with [json]. Raises {!Lancer.Job_error.User}
    and {!Lancer.Job_error.Scene}. *)
