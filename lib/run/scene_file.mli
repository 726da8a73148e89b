(** Where a command's scene comes from: a file, standard input (["-"]), or the built-in
    showcase; loaded into a {!Lancer_program.Program.t} with its errors raised as
    {!Lancer_job.Job_error.Scene}. *)

val showcase : string
(** The text of the built-in showcase (scenes/showcase.rts). *)

val read : string option -> string * string
(** The scene's (file name, text): the file given, standard input for ["-"] (named
    ["<stdin>"], read once however often it is asked for, its includes found from the
    current directory), or the built-in showcase ([showcase.rts]) for [None]. Raises
    {!Lancer_job.Job_error.User} for a missing or unreadable file. *)

val load_source :
  ?single:bool ->
  ?progress:(string -> unit) ->
  ?digests:bool ->
  string * string ->
  Program.t
(** Parse and check a scene's text, with a warning on stderr when its physics stopped
    handling collisions; raises {!Lancer_job.Job_error.Scene} with every located error.
    Includes are found relative to the file name. [single] and [digests] are
    {!Lancer_program.Program.load_string}'s. *)

val load_bundle : Program.bundle -> Program.t
(** The program of a bundle ({!Lancer_program.Program.load_bundle}); raises
    {!Lancer_job.Job_error.Scene}. *)

val load :
  ?single:bool ->
  ?progress:(string -> unit) ->
  ?digests:bool ->
  string option ->
  Program.t
(** [load_source (read scene)]. *)

val source : Options.t -> Program.t -> Scenes.t
(** The program as the job layer takes it ({!Lancer_program.Program.as_scenes}); built in
    without a scene. *)

val default_output : Options.t -> string
(** [-o] if given, else the scene's base name with [.png] ([showcase.png] without a
    scene); a scene read from standard input needs [-o] (raises
    {!Lancer_job.Job_error.User}). *)
