(** The runner: runs a compiled program ({!Compile}) at one instant and states the scene
    it describes ({!Lancer_description.Description.t}), or the located errors its run found; with {!State},
    the limits, the steps, the cancellation, and the memo of what does not change between
    instants. It reads no file: the images and meshes a scene names are the renderer's.

    Errors are collected, not thrown: a statement that fails is reported and skipped (a
    [let] that fails binds its name to a poisoned value, so that later uses do not report
    the same mistake again), and the run goes on with the next statement. Only the limits
    stop it. *)

module D = Description

type memo
(** What a program's first run did in the top-level statements that cannot do anything
    else at another instant, so that later runs skip them. Such a statement builds objects
    and nothing else (no settings, camera, light, animation, physics or body, nor a macro
    that makes one), and mentions no name that may hold a different value at another
    instant: not [time], [frame], a body, nor a name defined from one of them (through a
    [let], a function or a macro, at the point where it is defined). *)

val memo : Ast.stmt list -> memo
(** [memo prog]: which top-level statements of [prog] (includes flattened) are such
    statements; nothing recorded yet. *)

type analysis
(** {!val-memo}, statement by statement. *)

val analysis : unit -> analysis

val analyse : analysis -> Ast.stmt -> unit
(** The next top-level statement (an include's statements, each). *)

val memo_of : analysis -> memo

val again : memo -> memo
(** The same statements, nothing recorded. *)

val fixed_objects : memo -> D.obj list
(** The objects the recorded statements built, in program order: in every later
    description from {!run} with this memo, the very same values (physically), in this
    order, among the others, as long as each such statement starts with the count of
    objects it started with then (a statement that does not is run again, and its objects
    are new values). *)

val fixed_pieces : memo -> D.obj list list
(** {!fixed_objects} by recorded statement, in program order: with [parts], {!run} gives a
    replayed statement's objects as the very list here. *)

val run :
  ?memo:memo ->
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  ?on_objects:(int -> unit) ->
  ?cancel:Cancel.t ->
  ?objects:bool ->
  ?parts:(D.obj list list -> unit) ->
  ?on_file:(D.file_use -> unit) ->
  file:string ->
  sources:(string, string) Hashtbl.t ->
  time:float ->
  frame:int ->
  Compile.t ->
  (D.t, Error.t list) result
(** [run ~file ~sources ~time ~frame prog] runs [prog] (the program of [file]) with [time]
    and [frame] bound. [sources] maps each file name to its text (for error display).
    [body_state name t] is (position, velocity) of body [name] at time [t]; without it (or
    when it answers [None]) a body stays at its initial centre with its initial velocity.
    With [~objects:false] [objects] is left empty. With [parts], [objects] is left empty
    too and [parts] is given them in pieces, in order (their concatenation is what
    [objects] would have been, body spheres last): each piece a memo's statement replayed
    is the very list its first run recorded, not a copy, so that a caller that kept what
    it made of those can tell them at a glance. [on_objects n] is called every 65 536
    objects built, with their count (for progress during a long build). [on_file] is told
    each use of a file (image, mesh, height field) as it is met, also in a run that fails:
    what reading them finds wrong is the renderer's to report. [cancel] is polled every
    4096 loop iterations and calls: once it is cancelled, [run] raises [Sys.Break]. The
    first run given a [memo] runs every statement and records what the memo's statements
    did (when it succeeds); later ones skip them and give the same description they would
    have given had they run them. *)

val sort_errors : Error.t list -> Error.t list
(** Errors in source order: files in the order they first appear in the list, then by line
    and column (stable). *)
