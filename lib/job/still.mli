(** A still: one scene's image rendered over a pool of domains through the one tile loop
    ({!Lancer_render.Render.render_tiles}), optionally kept tile by tile in a
    {!Checkpoint} so that an interrupted render continues where it stopped, with the same
    bytes. *)

val render :
  ?cancel:Cancel.t ->
  ?checkpoint:Checkpoint.t ->
  ?region:Image.region ->
  ?alpha:Float.Array.t ->
  domains:int ->
  on_tile:(int -> int -> unit) ->
  Scene.t ->
  Framebuffer.t * Counters.t
(** [render ~domains ~on_tile scene] is the linear image and its counters;
    [on_tile done_ rays] after each tile ([done_] tiles finished so far, checkpointed ones
    included; that tile cast [rays] rays). With [checkpoint] only the tiles it lacks are
    rendered, each recorded as it finishes, and the counters are those of every tile; an
    interrupt saves it before [Sys.Break] goes on (a save that fails raises
    {!Job_error.Interrupted} saying so). [region] and [alpha] as for
    {!Lancer_render.Render.render}, without a checkpoint. *)
