(** Turning a scene into a linear framebuffer, in parallel tiles over a pool of domains ({!Pool}).

    The image is cut into 32×32 tiles handed out dynamically; each task writes only its
    own pixels and keeps its own counters, so the result is bit-identical whatever the
    number of domains. Each pixel averages, in linear colour, the n×n points
    (i + (p+½)/n, j + (q+½)/n) (doc/shading.md, section 2); [jitter] moves each inside its sub-cell by a hash
    of (frame, pixel, sample). With [adaptive = θ > 0] a pixel first takes the 2×2 grid and
    refines to max(n, 4)×max(n, 4) only where those four samples differ by more than θ in
    some channel. Samples that are NaN or infinite are counted and replaced by the
    background. *)

val tile_size : int
(** The side of a square tile in pixels (32); the last row and column of tiles may be
    smaller. *)

val pixel : Scene.t -> Stats.t -> int -> int -> Color.t
(** [pixel scene stats i j] is the linear colour of column [i], row [j]. *)

val coverage : Scene.t -> int -> int -> float
(** [coverage scene i j] is the share, in [0, 1], of pixel (i, j)'s sample points whose
    primary ray hits a surface: the n×n points of [samples] (jittered like the colour's);
    with adaptive sampling the refined max(n, 4)×max(n, 4) points, in every pixel. *)

val render_tile : ?alpha:Float.Array.t -> Scene.t -> Stats.t -> Image.t -> int -> int -> int -> int -> unit
(** [render_tile scene stats fb x0 y0 x1 y1] renders columns \[x0, x1) of rows \[y0, y1);
    with [alpha] it also stores each pixel's {!coverage} there (row-major). *)

val tiles : ?region:Image.region -> Scene.t -> (int * int * int * int) array
(** The tiles (x0, y0, x1, y1) of the scene's image, row-major; with [region] only those
    that meet it, clipped to it. *)

val render :
  ?pool:Pool.t -> ?on_tile:(int -> int -> int -> unit) -> ?region:Image.region -> ?alpha:Float.Array.t -> Scene.t ->
  Image.t * Stats.t
(** [render scene] renders the whole image. Without [pool] it runs on the calling domain.
    [on_tile done_ total rays] is called after each tile, from whichever domain rendered
    it: [done_] tiles of [total] are finished, and that tile cast [rays] rays. With
    [region] only its pixels are rendered, each exactly as in a whole render; the others
    are the background. With [alpha] (width·height values) each rendered pixel's
    {!coverage} is stored there, 0 elsewhere. *)

val interrupt : unit -> unit
(** Ask every render in progress to stop: from then on each tile that starts raises
    [Sys.Break] instead, so an interrupted render ends within one tile per domain.
    Meant for a SIGINT/SIGTERM handler; there is no way back. *)

val interrupt_requested : unit -> bool
(** Whether {!interrupt} was called: for loops over tiles of their own, which should then
    raise [Sys.Break] before starting the next one. *)

val in_pool : unit -> bool
(** Whether a pool of {!with_pool} is running. A signal handler must then only call
    {!interrupt} (the next tile raises [Sys.Break]); raising itself could land inside the
    pool's own synchronisation. {!with_pool} raises [Sys.Break] on its way out if an
    interrupt came after the last tile started. *)

val with_pool : int -> (Pool.t option -> 'a) -> 'a
(** [with_pool n f] runs [f] with a pool of [n] domains in all (none when n = 1), and tears
    it down afterwards, also on an exception. With more than one domain it first raises
    the minor heap to {!parallel_minor_heap_words} words per domain (never lowers it):
    fewer minor collections, each of which stops every domain. *)

val parallel_minor_heap_words : int
(** 2M words (16 MB) per domain. *)
