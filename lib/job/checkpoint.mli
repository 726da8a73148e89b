(** The checkpoint of a still rendered with [--resume]: the tiles finished so far, kept in
    a file next to the output ([OUT.checkpoint]) so that an interrupted render (Ctrl-C, a
    kill, a lost node) continues where it stopped.

    The file holds which tiles are done, the linear pixels bit for bit and the finished
    tiles' counters, sealed with the job's key (a digest of the scene's text and includes,
    the images and meshes it reads, the time and frame, and the options that change
    pixels). It is rewritten atomically (a temporary file, then a rename) at most every
    second, and never more often than ten times the time the last write took, so that
    writing it costs at most about a tenth of the render. Pixels are rendered by
    {!Lancer_render.Render.render_tile} either way, so the finished image is the same
    bytes as an uninterrupted render.

    {2 The file}

    Every number is a word of 8 bytes, little-endian: integers in two's complement, pixels
    as IEEE 754 binary64. In order:
    - the line [lancer-checkpoint-3\n] (20 bytes), which names this layout;
    - the seal (32 bytes), {!seal} of the key and the body, the rest of the file;
    - the image's width, height and number of tiles ({!Lancer_render.Render.tiles}), three
      words;
    - per tile, in {!Lancer_render.Render.tiles} order, 57 bytes: a flag byte, 1 when the
      tile is finished and 0 when not, then seven words: its primary, shadow, reflected
      and refracted rays, its bad samples, and the column and row of its first bad sample
      ((−1, −1) when none). Tiles rendered together as one unit keep their counters on the
      first of them, zero on the others;
    - the number of pixel values, 3·width·height, one word;
    - the framebuffer's values, one word each, row-major RGB from the top-left pixel
      (those of unfinished tiles are not used).

    The key itself is not in the file: it is computed again from the scene, its inputs and
    the options, so a file of another job, or one changed and sealed again without the
    key, fails the seal.

    {2 What is read}

    A checkpoint is read only if it is a regular file of exactly the size this image's
    checkpoint has (checked before reading it), begins with this layout's line and carries
    the seal of this job's key and its body. Then every field is checked: the width,
    height and tile count are the scene's; each flag is 0 or 1; an unfinished tile's
    counters are zero and its first bad sample (−1, −1); a finished tile's counters are
    non-negative, with no more bad samples than primary rays (every sample that can go bad
    cast at least one primary ray), a first bad sample exactly when there are bad samples
    and then on a pixel of a finished tile, and each counter's sum over the tiles fits an
    integer; the pixel count is 3·width·height; and every value is finite, as the
    renderer's are (a sample that came out NaN or infinite is counted as bad and replaced
    by the background). A value may be negative: colours, intensities and weights are not,
    but a material whose reflection and transparency sum to 1 up to rounding gives its own
    shading a weight a hair below zero, and the renderer writes such pixels.

    A file failing any of these is ignored and replaced, the render starting over; nothing
    in it is used, and reading it never raises. A file the reader accepts is one the
    writer could have written: saved again, it is the same bytes. *)

type t

val path_for : string -> string
(** [path_for out] is [out ^ ".checkpoint"]. *)

val key :
  Scenes.t -> Overrides.t -> time:float -> frame:int -> files:string list -> string
(** The key of a still: what its pixels depend on (the scene's text digest, the files it
    read, the time and frame, the overrides). *)

val seal : key:string -> string -> string
(** [seal ~key body] is the seal of a checkpoint of the job [key] whose body (what follows
    the seal) is [body]: the BLAKE2b-256 digest (32 bytes, [Digest.BLAKE256]) of the key's
    length in one word, the key, and [body]. Made by the writer and checked by the reader;
    without the key it cannot be made again. *)

val start : out:string -> key:string -> Scene.t -> t
(** Load the checkpoint of [out] if it is sealed with this key and passes every check
    above, or start an empty one. Raises {!Job_error.User} when the checkpoint's place
    cannot be written. *)

val resumed : t -> int
(** How many tiles the checkpoint held when it was loaded (0 for a new one). *)

val resumed_rays : t -> int
(** The rays of the tiles the checkpoint held when it was loaded: those a resumed render
    did not cast itself. *)

val tiles : t -> int
(** How many tiles the image has. *)

val framebuffer : t -> Framebuffer.t
(** The image being rendered, with the finished tiles' pixels already in. *)

val todo : t -> int array
(** The tiles ({!Lancer_render.Render.tiles} numbers) still to render, in order. *)

val finished : t -> int
(** How many tiles are done. *)

val tiles_done : t -> int array -> Counters.t -> unit
(** [tiles_done t tiles stats]: those tiles' pixels are in the framebuffer, with their
    counters summed in [stats]; rewrites the checkpoint when due. Safe from several
    domains at once. Raises {!Job_error.User} if the checkpoint cannot be written. *)

val save : t -> unit
(** Write the checkpoint now (on an interrupt). *)

val stats : t -> Counters.t
(** The counters of every finished tile, loaded ones included, summed in tile order. *)

val remove : t -> unit
(** Delete the checkpoint: the image is written. *)

val render :
  ?cancel:Cancel.t ->
  ?pool:Pool.t ->
  ?on_tile:(int -> int -> unit) ->
  t ->
  Scene.t ->
  unit
(** Render the tiles still to do into the framebuffer over [pool] with
    {!Lancer_render.Render.render_tiles}, recording each one; [on_tile finished rays]
    after each. Raises [Sys.Break] within a few thousand rays once [cancel] is cancelled;
    the tiles finished by then are recorded. *)
