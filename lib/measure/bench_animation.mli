(** [lancer bench animation]: a whole [lancer animate] of a scene against one
    [lancer render] of it, each a child process from start to exit, alternated, and their
    ratio: what the frames after the first cost. *)

val run :
  exe:string -> scene:string -> repeat:int -> domains:int option -> json:bool -> unit
(** Time lancer [exe] animating [scene] into a temporary directory and rendering its
    still, [repeat] times each (medians), with [--domains] when given, and print a
    Markdown table, or JSON with [json]. Raises {!Lancer.Job_error.User} when a command
    fails. *)
