(** The runner: runs a compiled program ({!Compile}) at one instant and states the scene
    it describes ({!Lancer_description.Description.t}), or the located errors its run
    found; with {!State}, the limits, the steps, the cancellation; and the program's
    static statements, run once and taken as they were at other instants. It reads no
    file: the images and meshes a scene names are the renderer's.

    Errors are collected, not thrown: a statement that fails is reported and skipped (a
    [let] that fails binds its name to a poisoned value, so that later uses do not report
    the same mistake again), and the run goes on with the next statement. Only the limits
    stop it. *)

module D = Description

type plan
(** Which top-level statements (includes flattened; see
    {!Lancer_description.Description.static}) are static: such a statement builds objects
    and nothing else (no settings, camera, light, animation, physics or body, nor a macro
    that makes one), and mentions no name that may hold a different value at another
    instant: not [time], [frame], a body, nor a name defined from one of them (through a
    [let], a function or a macro, at the point where it is defined). *)

val plan : Ast.stmt list -> plan
(** [plan prog]: which top-level statements of [prog] (includes flattened) are static. *)

type analysis
(** {!val-plan}, statement by statement. *)

val analysis : unit -> analysis

val analyse : analysis -> Ast.stmt -> unit
(** The next top-level statement (an include's statements, each). *)

val plan_of : analysis -> plan

type static
(** What one run ({!record}) did in a plan's static statements, by position: the objects
    each built, its steps, the files it used and the warnings it gave. Immutable. *)

val objects : static -> Description.static
(** The objects each recorded statement built, by position. *)

type 'a runner =
  ?on_objects:(int -> unit) ->
  ?cancel:Cancel.t ->
  ?on_file:(D.file_use -> unit) ->
  file:string ->
  sources:(string, string) Hashtbl.t ->
  time:float ->
  frame:int ->
  Compile.t ->
  ('a, Error.t list) result
(** A run of a program at one instant (see {!run}). *)

val run :
  ?static:static ->
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  ?objects:bool ->
  D.t runner
(** [run ~file ~sources ~time ~frame prog] runs [prog] (the program of [file]) with [time]
    and [frame] bound. [sources] maps each file name to its text (for error display).
    [body_state name t] is (position, velocity) of body [name] at time [t]; without it (or
    when it answers [None]) a body stays at its initial centre with its initial velocity.
    With [~objects:false] [objects] is left empty. [on_objects n] is called every 65 536
    objects built, with their count (for progress during a long build). [on_file] is told
    each use of a file (image, mesh, height field) as it is met, also in a run that fails:
    what reading them finds wrong is the renderer's to report. [cancel] is polled every
    4096 loop iterations and calls: once it is cancelled, [run] raises [Sys.Break]. With
    [static] (what {!record} did in a run of the same program), a static statement that
    starts with the count of objects and no more steps than it started with then is not
    run: what it did then is taken instead, and the description is the one running it
    would have given. *)

val record : ?emit:(D.obj -> unit) -> plan -> (D.t * static) runner
(** {!run}, every statement run, and what the plan's static statements did. With [emit],
    each object the program's own scope gets is handed to [emit] as it is made, in the
    order of the description's [objects], and nothing is kept of it: the description has
    no [objects] but its bodies' spheres, and nothing is recorded. *)

val run_parts :
  ?static:static ->
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  (D.t * D.part list) runner
(** {!run}, with the description's [objects] left empty and given as parts instead: a
    static statement taken from [static] is [Static] its position, the objects built in
    between (body spheres last) [Built]. Their objects in order are what [objects] would
    have been. *)

val sort_errors : Error.t list -> Error.t list
(** Errors in source order: files in the order they first appear in the list, then by line
    and column (stable). *)
