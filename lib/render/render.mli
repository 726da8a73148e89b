(** Turning a scene into a linear framebuffer, in parallel tiles over a pool of domains
    ({!Pool}).

    The image is cut into 32×32 tiles handed out dynamically; each task writes only its
    own pixels and keeps its own counters, so the result is bit-identical whatever the
    number of domains. Each pixel averages, in linear colour, the n×n points (i + (p+½)/n,
    j + (q+½)/n) (doc/reference/shading.md, section 2); [jitter] moves each inside its
    sub-cell by a hash of (frame, pixel, sample). With [adaptive = θ > 0] a pixel first
    takes the 2×2 grid and refines to max(n, 4)×max(n, 4) only where those four samples
    differ by more than θ in some channel. Samples that are NaN or infinite are counted
    and replaced by the background. A scene with {!Scene.moments} (an open shutter) is
    motion-blurred: each sample of an n×n grid sees one of them, the grid's n² samples
    spread evenly over the shutter (every row and column of the grid spans it) and placed
    by a hash of (frame, pixel, sample). *)

val tile_size : int
(** The side of a square tile in pixels (32); the last row and column of tiles may be
    smaller. *)

val strided_tile_size : int
(** The side of a tile of a strided image (8): it has few pixels, and smaller tiles spread
    them over the domains. *)

val pixel : Scene.t -> Task.t -> int -> int -> Color.t
(** [pixel scene task i j] is the linear colour of column [i], row [j]. *)

val coverage : Scene.t -> int -> int -> float
(** [coverage scene i j] is the share, in [0, 1], of pixel (i, j)'s sample points whose
    primary ray hits a surface: the n×n points of [samples] (jittered like the colour's);
    with adaptive sampling the refined max(n, 4)×max(n, 4) points, in every pixel. *)

(** What a render may take from another: a scene whose pixels untouched by a box are the
    same as another's (an animation's frames where only what lies in the box moves)
    renders those pixels once ({!Watch}) and copies them into the others ({!Only}). *)
type reuse =
  | Watch of { box : Float.Array.t; mask : Bytes.t }
      (** render every pixel, and set [mask]'s byte of pixel (i, j) (at j·width + i) to
          ['\001'] where one of its queries may have met [box] (min x y z, max x y z; see
          {!Lancer_render.Accel.watch}), ['\000'] elsewhere *)
  | Only of { mask : Bytes.t; base : Framebuffer.t }
      (** render the pixels whose [mask] byte is ['\001'] and take the others from [base]
      *)

val noise_estimated : Scene.t -> bool
(** Whether a render of the scene estimates its noise ({!Counters.noise}): it has soft
    shadows, or jittered, motion-blurred or depth-of-field samples and at least two of
    them per pixel (or two lens rays per sample). Each pixel's standard error is then that
    of two interleaved halves of its camera samples (of its lens rays when it has one)
    where those are random draws, and of the area lights' shadow rays at each shading
    point ({!Shade.half_diff_into}), the two variances added. *)

val render_tile :
  ?alpha:Float.Array.t ->
  ?reuse:reuse ->
  ?stride:int ->
  Scene.t ->
  Task.t ->
  Framebuffer.t ->
  int ->
  int ->
  int ->
  int ->
  unit
(** [render_tile scene task fb x0 y0 x1 y1] renders columns \[x0, x1) of rows \[y0, y1);
    with [alpha] it also stores each pixel's {!coverage} there (row-major); with [reuse]
    as {!reuse} says. Its rays and the tests inside CSG objects that they make count into
    [task] ({!Task.with_current}), polling its token; so does each pixel's estimated noise
    where {!noise_estimated}. With [stride = k] (default 1; neither [alpha] nor [reuse]
    then), [fb] is the image of one sample per k×k block of the scene's image,
    ⌈width/k⌉×⌈height/k⌉ pixels, and its pixel (i, j) is the scene's pixel (min(width−1,
    i·k + k/2), min(height−1, j·k + k/2)), computed as a whole render computes it; the
    coordinates above are [fb]'s. *)

val tiles :
  ?region:Image.region -> ?stride:int -> Scene.t -> (int * int * int * int) array
(** The tiles (x0, y0, x1, y1) of the scene's image ({!tile_size} square; of its image of
    one sample per [stride]×[stride] block, {!strided_tile_size} square), row-major; with
    [region] only those that meet it, clipped to it. *)

val tile_count : ?region:Image.region -> ?stride:int -> Scene.t -> int
(** The number of {!tiles}, without making them. *)

val tile : ?region:Image.region -> ?stride:int -> Scene.t -> int -> int * int * int * int
(** [tile scene k] is [(tiles scene).(k)], found by arithmetic alone. *)

val render_tiles :
  ?cancel:Cancel.t ->
  ?pool:Pool.t ->
  ?on_tile:(int -> int -> Counters.t -> unit) ->
  ?region:Image.region ->
  ?alpha:Float.Array.t ->
  ?reuse:reuse ->
  ?stride:int ->
  Scene.t ->
  Framebuffer.t ->
  int array ->
  Counters.t
(** [render_tiles scene fb idxs] renders the tiles of {!tiles}[ ?region scene] numbered
    [idxs] into [fb] (the one tile loop: {!render}, [lancer-mpi], the animation and a
    resumed still all use it) and is their summed counters. Without [pool] it runs on the
    calling domain. [on_tile done_ k stats] is called after each tile, from whichever
    domain rendered it: [done_] of the tiles are finished, the last being tile [k] with
    its own counters [stats]. [cancel] is polled before each tile, every
    {!Lancer_diag.Cancel.check_every} units of work inside one (rays, tests inside CSG
    objects: {!Task.spend}), and once all are done: when it is cancelled the call raises
    [Sys.Break] within a few thousand units per domain, and [fb] is not to be used.
    [alpha] and [stride] (not with [region]) as for {!render_tile}. *)

val render :
  ?cancel:Cancel.t ->
  ?pool:Pool.t ->
  ?on_tile:(int -> int -> int -> unit) ->
  ?region:Image.region ->
  ?alpha:Float.Array.t ->
  ?reuse:reuse ->
  ?stride:int ->
  Scene.t ->
  Framebuffer.t * Counters.t
(** [render scene] renders the whole image through {!render_tiles}.
    [on_tile done_ total rays]: [done_] tiles of [total] are finished, and that tile cast
    [rays] rays. With [region] only its pixels are rendered, each exactly as in a whole
    render; the others are the background. With [alpha] (width·height values) each
    rendered pixel's {!coverage} is stored there, 0 elsewhere. With [stride = k] the image
    is the ⌈width/k⌉×⌈height/k⌉ one of one sample per k×k block ({!render_tile}): a
    complete picture, with the camera of the full image, at about 1/k² of its cost. *)

val with_pool : ?cancel:Cancel.t -> int -> (Pool.t option -> 'a) -> 'a
(** [with_pool n f] runs [f] with a pool of [n] domains in all (none when n = 1), and
    tears it down afterwards, also on an exception. While the pool lives,
    {!Lancer_diag.Cancel.signal} on [cancel] does not raise (it could land inside the
    pool's own synchronisation): pass the token the signal handler cancels, and the same
    to the work done in [f]; if it was cancelled, [with_pool] raises [Sys.Break] on its
    way out. With more than one domain it first raises the minor heap to
    {!parallel_minor_heap_words} words per domain (never lowers it): fewer minor
    collections, each of which stops every domain. Under a limit on the address space
    (ulimit -v) it raises it only as far as {!minor_heap_words_for} allows, since the
    runtime reserves the minor heaps of all the domains it could run at once. *)

val parallel_minor_heap_words : int
(** 2M words (16 MB) per domain. *)

val address_space_limit : unit -> int option
(** The soft limit on this process's address space in bytes (ulimit -v), read from
    /proc/self/limits; [None] when there is none or it cannot be read. *)

val minor_heap_words_for : int option -> int
(** [minor_heap_words_for limit] is the minor heap, in words per domain, that a pool may
    ask for under an address-space limit of [limit] bytes: {!parallel_minor_heap_words}
    without a limit, otherwise at most the size whose reservation for the runtime's 128
    domains takes an eighth of it (187 500 words under 1.5 GB). *)
