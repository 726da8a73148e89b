(** Work units: how a job of frames is cut into pieces that a worker (a rank of
    lancer-mpi, or this process alone) renders, and the one way a unit is rendered.

    A job is a list of frames, each known by a key (the frame number of an animation, 0
    for a still). A unit is a set of tiles ({!Lancer_render.Render.tiles}) of one frame:
    whole frames when there are at least as many frames as ranks (and more than one),
    otherwise chunks of a few tiles, about four per domain of the rank that asks, never
    fewer than its domains. Units are cut in order, frame by frame. *)

type work_unit = { key : int; tiles : int array }

val render_unit :
  ?cancel:Cancel.t ->
  ?on_tile:(unit -> unit) ->
  pool:Pool.t option ->
  Scene.t ->
  Framebuffer.t ->
  int array ->
  Counters.t
(** [render_unit ~pool scene fb tiles] renders the tiles of [scene] numbered [tiles] into
    [fb] over [pool] through {!Lancer_render.Render.render_tiles}, the tile loop of every
    render, and is their summed counters. [on_tile] is called after each tile, from
    whichever domain rendered it; [cancel] as for {!Lancer_render.Render.render_tiles}. *)

val plan : ranks:int -> domains:int -> int list -> (int * int) list
(** [plan ~ranks ~domains tiles] is the units a {!type-cutter} cuts, in the order it hands
    them out, when every rank has [domains] domains and frame k (counted from 0) of the
    job has the k-th element of [tiles] tiles: a list of (frame index, tiles in the unit).
    For predicting the scheme's speed without running it. *)

(** {1 Cutting a job as it runs} *)

type frame = {
  sc : Scene.t;
  all : (int * int * int * int) array;  (** its tiles *)
  todo : int array;  (** the tiles to render: all of them, or those a checkpoint lacks *)
  fb : Framebuffer.t;
  mutable left : int;  (** tiles still to come back *)
  mutable st : Counters.t;  (** the counters of the tiles back so far *)
}
(** A frame whose units are being handed out. *)

type cutter

val cutter :
  ?start:(int -> (Framebuffer.t * int array) option) ->
  ranks:int ->
  (int * (unit -> Scene.t)) list ->
  cutter
(** The units of a job for [ranks] workers: the frames in order with the scene of each
    (asked for once, when its first unit is cut; the first one at once when frames are cut
    in chunks, since the chunk size follows its tile count). [start key], when it answers,
    gives a frame's framebuffer with some tiles already in it and the tiles still to
    render (a resumed still). *)

val next : cutter -> domains:int -> work_unit option
(** The next unit for a worker of [domains] domains, or [None] when every frame is handed
    out. *)

val frame : cutter -> int -> frame
(** A frame of the job that has units out, by key. *)

val deposit : cutter -> int -> int array -> Counters.t -> frame option
(** [deposit c key tiles stats]: that unit's pixels are in the frame's framebuffer; its
    counters are added. The frame, when it is now complete (it is then forgotten). *)
