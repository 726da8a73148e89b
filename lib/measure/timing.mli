(** Timings the measurements share: medians, a render's wall time, a whole process's. *)

val median : float list -> float
(** The median (the mean of the two middle values of an even count); NaN for none. *)

val render :
  ?pool:Lancer.Pool.t ->
  ?on_tile:(int -> int -> int -> unit) ->
  Lancer.Scene.t ->
  float * Lancer.Framebuffer.t * Lancer.Counters.t
(** The wall time of {!Lancer.Render.render}, and its image and counters; [on_tile] as
    there. *)

val child : string -> string list -> (float, int) result
(** [child exe args]: the wall time of the program [exe] run with [args] (its output
    thrown away), from its start to its exit; [Error status] when it fails. *)
