(** The physics methods against the closed form ({!Drop}): a ball (radius 0.1 m) dropped
    from 1 m with restitution 1 and 0.8, simulated by the exact method and by Verlet and
    Euler at each fixed step, with the position, impact-time and apex errors and the cost
    (wall time, steps, events); the table of doc/reference/numerics.md. *)

val run : rates:float list -> until:float -> sample_rate:float -> json:bool -> unit
(** Fixed steps of 1/rate s for each of [rates], [until] s simulated, positions compared
    at [sample_rate] Hz; a Markdown table, or JSON with [json]. Raises
    {!Lancer.Job_error.User} for a rate, time or sampling rate that is not positive. *)
