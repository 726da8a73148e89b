(** [lancer check] as a library function: a scene parsed and evaluated, and what it holds
    printed (or its evaluated scene as JSON), or every frame of a range evaluated. *)

val runs : int list -> string
(** Frame numbers (ascending) as runs: ["12..20, 30"]. *)

val frames : Program.t -> string -> float * int * int
(** The (fps, first, last) that [--frames] names: ["all"], [A..B] or [K], within the
    animation (a still has frame 0 only); raises {!Lancer_job.Job_error.User}. *)

val run :
  ?width:int ->
  ?height:int ->
  scene:string ->
  json:bool ->
  time:float option ->
  frames:string option ->
  unit ->
  unit
(** [lancer check SCENE]: at [time] (default 0) the summary and the estimated rays (at
    [width] × [height] where given, as [--width] and [--height] render it), or with [json]
    the evaluated scene as JSON; with [frames] every frame of the range is evaluated, the
    errors of the first that fails raised ({!Lancer_job.Job_error.Scene}, its note listing
    every failing frame) or the first frame's summary printed. *)
