(** The client-server scheme over MPI: rank 0 hands out work units on demand, gathers
    their pixels and hands each finished frame to its caller; every rank, rank 0 too,
    renders the units it is given with its own pool of domains.

    A job is a list of frames, each known by a key (the frame number of an animation, 0
    for a still), cut into work units by {!Lancer_job.Work}: whole frames when there are
    at least as many frames as ranks (and more than one), otherwise chunks of a few tiles.
    Every rank renders units, rank 0 included: its main domain serves (only it may call
    MPI) while another domain renders rank 0's units over its pool. Each tile is rendered
    by {!Lancer_render.Render.render_tile} from the same scene, and its floats travel bit
    for bit, so the pixels are identical to a local render whatever the number of ranks
    and domains. When rank 0 is alone it renders the units itself, a whole frame at a time
    over its pool.

    Failures: a worker that cannot evaluate the scene or render a unit reports it; rank 0
    then stops handing out work, lets every worker finish, and raises {!Worker_failed}, so
    nothing more is written. A rank that dies is MPI's business: the default error handler
    ends the whole job. Anything else unexpected while workers are active also ends the
    job (MPI_Abort), since they would otherwise wait for ever. *)

exception Worker_failed of int * string
(** [Worker_failed (rank, message)]: that rank could not do its unit. *)

type report = {
  units : int array;  (** per rank: the units it rendered *)
  tiles : int array;  (** per rank: the tiles of those units *)
  waits : float list array;
      (** per rank: each time it handed in a unit (or, first, said it was ready) and then
          waited for its next one, the seconds it waited, most recent first. For rank 0
          that is its own serving loop's reaction; for the others it includes sending the
          unit's floats. *)
}
(** What rank 0 saw of the scheme itself during {!serve}. *)

val percentile : float -> float list -> float
(** [percentile p l] is the smallest element of [l] with at least a share [p] (in \[0,
    1\]) of [l] at or below it; NaN for an empty [l]. *)

val report_json : report -> Yojson.Safe.t
(** What [--stats] adds under [lancer-mpi]: per rank, the units and tiles it rendered and
    how long it waited for each next unit (milliseconds: median, 90th percentile,
    largest), and the waits of all ranks but 0 together. *)

type renderer = pool:Pool.t option -> Scene.t -> Framebuffer.t -> int array -> Counters.t
(** How a unit is rendered: {!Lancer_job.Work.render_unit} without progress, unless a
    measurement of the scheme's own cost replaces it (e.g. by one that renders nothing).
*)

val plan : ranks:int -> domains:int -> int list -> (int * int) list
(** {!Lancer_job.Work.plan}: the units {!serve} cuts, in the order it hands them out. *)

val serve :
  ?start:(int -> (Framebuffer.t * int array) option) ->
  ?on_unit:(int -> int array -> Counters.t -> unit) ->
  ?inputs:(int -> (string * string) list option) ->
  ?render:renderer ->
  ?local:bool ->
  ?cancel:Cancel.t ->
  fatal:(exn -> int) ->
  pool:Pool.t option ->
  domains:int ->
  on_tiles:(int -> unit) ->
  on_frame:(int -> Scene.t -> Framebuffer.t -> Counters.t -> unit) ->
  (int * (unit -> Scene.t)) list ->
  report
(** [serve ~fatal ~pool ~domains ~on_tiles ~on_frame frames] runs on rank 0 and is what it
    saw. [start key], when it answers, gives a frame's framebuffer with some tiles already
    in it and the tiles still to render (a resumed still); [on_unit key tiles stats] is
    called as each unit's pixels are in the framebuffer (to keep a checkpoint).
    [inputs key], when it answers, is the files (with their digests) rank 0's scene of
    that frame was made of: a worker whose scene was made of other bytes (a texture or
    mesh replaced while the job ran) has its unit refused and the job fails with
    {!Worker_failed}, instead of mixing two versions in one image. [frames] lists the keys
    to render in order, with the scene of each (asked for once, when its first unit is
    cut). [on_tiles n] is called as tiles finish, with the count so far over all frames,
    from any domain; [on_frame key scene fb stats] as each frame is complete (in any
    order), from the calling domain. Rank 0's own units are rendered over [pool]
    ([domains] domains) by a domain it starts, one unit at a time (cut as for any other
    rank), while the calling domain serves; with [~local:false] (for measuring the serving
    alone) rank 0 only serves. Raises what [on_frame] raises, or {!Worker_failed}, once
    every worker has stopped. [fatal e] reports an unexpected exception and is the status
    the job is then aborted with. [cancel] stops rank 0's own rendering as
    {!Lancer_render.Render.render_tiles} does, and the serving loop at its next round (the
    job is then aborted with [fatal Sys.Break]). *)

val work :
  ?cancel:Cancel.t ->
  ?render:renderer ->
  ?prepare:(unit -> unit) ->
  describe:(exn -> string) ->
  pool:Pool.t option ->
  domains:int ->
  (int -> Scene.t * (string * string) list) ->
  unit
(** [work ~describe ~pool ~domains scene_of] runs on every other rank until rank 0 says
    stop; [prepare ()] runs first (loading the program): what it raises is sent to rank 0
    as the rank's first message, so the job fails whatever the other ranks have done;
    [scene_of key] evaluates the scene of a frame, and the files it was made of with their
    digests (sent back with each unit, see [serve]'s [inputs]). An exception from it or
    from rendering is sent to rank 0 as [describe e]; [cancel] stops the rendering with
    [Sys.Break], which ends the job. *)
