(** A run's state as the program runs: the limits it counts against (steps, call depth,
    objects, the address space), its cancellation, and what it reports (each mistake and
    warning once). With {!Run}, the runner of a compiled program.

    Limits, so that a runaway scene stops with a located error: {!max_objects} objects,
    {!max_steps} loop iterations and calls in all, calls nested {!max_depth} deep. Under a
    limit on the address space (ulimit -v), a scene whose objects would need more than it
    ({!bytes_per_object} each) is refused: at the loop that would build them, when its
    body builds them directly, or else at the object that crosses the limit. *)

module D = Description

val max_objects : int
(** 10 000 000 objects built (members of groups included). *)

val max_steps : int
(** 20 000 000 loop iterations and function or macro calls. *)

val max_depth : int
(** 1000 nested function or macro calls. *)

val bytes_per_object : int
(** 2560: the address space one object is counted as needing (measured: 2.3 KB a sphere at
    the peak of building and rendering 200 000). *)

val create :
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  ?on_objects:(int -> unit) ->
  ?cancel:Cancel.t ->
  on_file:(D.file_use -> unit) ->
  sources:(string, string) Hashtbl.t ->
  time:float ->
  frame:int ->
  unit ->
  Value.state

val report : Value.state -> Loc.t -> string -> unit
(** A mistake, unless the same was reported at the same place. *)

val warn : Value.state -> Loc.t -> string -> unit

val use : Value.state -> D.file_use -> unit
(** A file a scene names: recorded, and told to the run's [on_file]. *)

val limit : Value.state -> Loc.t -> string -> 'a
(** Reports a limit reached, and stops the evaluation ({!Value.Abort}). *)

val step : Value.state -> Loc.t -> unit
(** One loop iteration or call; polls the cancellation every 4096. *)

val enter : Value.state -> Loc.t -> unit
(** A call: a step, one level deeper. *)

val leave : Value.state -> unit

val put : Value.scope -> D.obj -> unit
(** An object into a scope: handed over where the scope emits them, else into its sink. *)

val add_object : Value.state -> Value.scope -> Loc.t -> D.obj -> unit
(** A new object of a block into [scope] ({!put}), counted against the limits. *)

val loop :
  Value.state ->
  Loc.t ->
  range:(float * float * float) option ->
  count:float ->
  per_iteration:float ->
  unit
(** The checks before a loop of [count] iterations, each building at least [per_iteration]
    objects, runs: refused when, run inside the loops around it, it would go past the step
    limit, the object limit or the memory; a loop over a [range] (start, stop, step) is
    warned of when it runs zero times. *)

val body_at : Value.state -> string -> Vec3.t * Vec3.t
(** The position and velocity of a body defined so far, at the run's time. *)
