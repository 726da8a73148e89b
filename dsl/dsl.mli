(** The [.rts] scene language, end to end: load a script (and its includes), check it, and
    evaluate it into a {!Lancer_description.Description.t} at any animation time (which
    the renderer compiles; [Lancer.Program] does both, and moves the bodies).

    This is the one boundary of the language: whatever the input, these functions return
    [Ok] or located {!Error.t}s and never raise, but for [Sys.Break] (an interrupt that
    came during loading or evaluation, which the caller answers). A program is evaluated
    once when it is loaded (at time 0, frame 0), so every error of the program a still
    scene can have is reported by {!load_file} (those of the files it names, when they are
    read); errors that depend on [time] appear in {!describe}. *)

type t
(** A parsed, checked program, ready to be evaluated at any time. *)

val load_file :
  ?files:(Description.file_use list -> (Loc.t * string) list) ->
  ?emit:(Description.obj -> unit) ->
  string ->
  (t, Error.t list) result
(** [load_file path] reads, parses and checks [path]: the whole program's types and the
    fields of each block kind ({!Check}, code that does not run included), then its
    evaluation at time 0; the errors of both, each once, in source order. The language
    reads no image or mesh: [files uses], when given, says what the files the program uses
    have wrong (the renderer's [Compile.check_files]), reported with the program's errors.
    Included files are found relative to the file that includes them. Errors name files as
    the paths were written. The scene and every include must be a regular file of at most
    {!max_source_bytes}: a device, a FIFO or a larger file is refused from its status,
    before it is opened.

    With [emit], a program that writes no [animation] or [physics] block, no body and no
    camera [shutter] anywhere ({!Check.moving}) hands each object of its evaluation at
    time 0 to [emit] as it is made, in the order of a description's [objects], and keeps
    none: it is then {!emitted} (and {!released}). What [emit] got is that scene's objects
    only if the load succeeds. *)

val max_source_bytes : int
(** 64 MiB: the largest scene or included file. *)

val source_problem : string -> string option
(** [source_problem path] is why [path] cannot be read as a scene file (missing, not a
    regular file, larger than {!max_source_bytes}), from its status alone; [None] if it
    can. *)

val load_string :
  ?progress:(string -> unit) ->
  ?files:(Description.file_use list -> (Loc.t * string) list) ->
  ?emit:(Description.obj -> unit) ->
  ?filename:string ->
  string ->
  (t, Error.t list) result
(** [load_string ~filename text] is as {!load_file} for [text], named [filename] (default
    ["<string>"]; includes are relative to its directory). [progress] is told how many
    objects a long check has built so far. *)

type bundle
(** A program's files as it read them: its own text and each include's, with where each
    include was found. Plain data, to send to another process (an MPI rank). *)

val bundle : t -> bundle
(** The texts [t] was loaded from. *)

val load_bundle :
  ?progress:(string -> unit) ->
  ?files:(Description.file_use list -> (Loc.t * string) list) ->
  ?emit:(Description.obj -> unit) ->
  bundle ->
  (t, Error.t list) result
(** The program of a bundle, as {!load_string}, with every include taken from the bundle:
    no file is read, so the program is the one whose texts were bundled, whatever the
    files on this machine's disk say now. *)

type 'a at_instant =
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  ?progress:(string -> unit) ->
  ?cancel:Cancel.t ->
  ?files:(Description.file_use list -> (Loc.t * string) list) ->
  t ->
  time:float ->
  frame:int ->
  ('a, Error.t list) result
(** An evaluation of a program at one instant (see {!describe}). *)

val describe : ?again:bool -> Description.t at_instant
(** [describe p ~time ~frame] is the scene [p] states with [time] (seconds) and [frame]
    bound. [body_state name t] gives (position, velocity) of body [name] at time [t] (the
    simulation's); without it, or where it answers [None], a body sits at its initial
    centre with its initial velocity. A body's sphere is placed at its position. At time
    0, frame 0 without [body_state] it is the evaluation {!load_file} made ({!first}), not
    a new one, until it is {!release}d. The warnings of a description carry their chain of
    includes. Errors at any instant but time 0, frame 0 end with [(at frame K, time T s)].
    When the evaluation fails, [files] (as for {!load_file}) adds what the files it used
    have wrong. [progress], when given, is told how many objects a long evaluation has
    built. [cancel] is polled as the program runs: once it is cancelled, evaluation stops
    with [Sys.Break]. The static statements ({!static}) are not evaluated again, unless
    [again] (default [false]) says to evaluate every statement: the same description, made
    the long way. *)

val describe_parts : (Description.t * Description.part list) at_instant
(** {!describe}, always a new evaluation, with the description's objects given as parts
    ({!Run.run_parts}) and the description left without them: a static statement is
    [Static] its position in {!static}, unless it had to be evaluated again (it started
    with another count of objects than at the load), and the objects of the others are
    [Built]. *)

val first : t -> Description.t
(** The evaluation made when the program was loaded: time 0, frame 0, bodies at their
    initial centres; without its objects once {!release}d. *)

val release : t -> Description.t option
(** [release p] is {!first} [p] with its objects, for the one caller that gets it ([None]
    for any other, or once released), and [p] keeps none of its objects from then on
    (neither in {!first} nor in {!static}), so that a caller that compiles them once can
    let each go as soon as it is compiled. {!describe} at time 0, frame 0 then evaluates
    the program again, every statement: the same description, as new values. *)

val released : t -> bool
(** Whether {!release} was called, or the load's objects were {!emitted}. *)

val emitted : t -> bool
(** Whether the load handed its objects to its [emit] instead of keeping them. *)

val static : t -> Description.static
(** The program's static part: the objects of {!first} built by the top-level statements
    that cannot build anything else at another instant ({!Run.val-plan}), by position
    ([[]] once {!release}d). *)

val named_files : t -> string list
(** Every file any scene of the program may read, at any time or frame: each string the
    program writes (in any statement, branch, function or macro body, run or not), and
    each join [a + b] of one written in [a] and one written in [b], resolved against the
    directory of each of the program's files, sorted. A superset of the images and meshes
    a frame reads, unless the program joins strings that names hold ([let d = "tex/"],
    then [d + "oak.png"]). *)

val source : t -> string -> string option
(** [source p file]: the text of [file], the program's or an include's (for an error's
    caret display). *)

val located : t -> time:float -> frame:int -> Error.t list -> Error.t list
(** [located p ~time ~frame es]: errors at places of [p] (made with {!source}) as
    {!describe} gives its own: with the chain of includes that led to their file, and
    naming the frame when not at time 0, frame 0. *)

val scene_relative : t -> string -> string
(** A path as the evaluator resolved it (relative to the including file), as seen from the
    main file's directory: how the scene itself names it. *)

val animation : t -> (float * int) option
(** (fps, frames) of the [animation] block; [None] without one. *)

val file : t -> string
(** The file name the program was loaded as. *)

val inputs : t -> string list
(** The files the program has read or named so far, sorted: its own, its includes, and the
    images and meshes its scenes name (those named only at some times once a scene at such
    a time was described). Paths are as they were resolved: relative to the scene as it
    was named. *)

val text_digest : t -> string
(** A digest of the program's text and its included files' (each include known by its path
    from the main file's directory), but not of the path the program was loaded as:
    [./a.rts] and [a.rts] have the same digest. *)

(** {1 For the physics engine} *)

type physics_method = Description.physics_method = Exact | Verlet | Euler

type physics = Description.physics = {
  gravity : Vec3.t;  (** m/s²; default (0, −9.81, 0) *)
  method_ : physics_method;  (** default [Exact] *)
  step : float;  (** seconds, for the fixed-step methods; default 1/240 *)
}

type body = Description.body = {
  name : string;
  center : Vec3.t;  (** initial world-space centre (transforms applied) *)
  radius : float;  (** world-space radius *)
  velocity : Vec3.t;  (** initial velocity, m/s; default (0, 0, 0) *)
  mass : float;  (** kg, > 0; default 1 *)
  restitution : float;  (** in [0, 1]; default 0.9; a pair uses the product *)
  loc : Loc.t;  (** where the body is defined *)
}

val bodies : t -> body list
(** The bodies of the program (evaluated at time 0), in program order. In every
    description from {!describe}, the body spheres are the last [List.length (bodies p)]
    objects, in this order; the objects before them are static (obstacles for the
    simulation). *)

val physics : t -> physics option
(** The [physics] block; [None] without one (the engine should then use
    {!default_physics}). *)

val default_physics : physics
(** The physics when the scene has no [physics] block: gravity (0, −9.81, 0), the exact
    method, step 1/240. *)

val empty : t -> bool
(** Whether the program has no statement at all (for [lancer check]'s warning). *)
