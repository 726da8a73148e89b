(** The checkpoint of a still rendered with [--resume]: the tiles finished so far, kept in
    a file next to the output ([OUT.checkpoint]) so that an interrupted render (Ctrl-C, a
    kill, a lost node) continues where it stopped.

    The file holds a key (a digest of the scene's text and includes, the images and meshes
    it reads, the time and frame, and the options that change pixels), which tiles are
    done, their linear pixels bit for bit and their counters, and an MD5 of all that. It
    is rewritten atomically (a temporary file, then a rename) at most every second, and
    never more often than ten times the time the last write took, so that writing it costs
    at most about a tenth of the render. A checkpoint with another key, or damaged, is
    ignored and replaced. Pixels are rendered by {!Render.render_tile} either way, so the
    finished image is the same bytes as an uninterrupted render. *)

type t

val path_for : string -> string
(** [path_for out] is [out ^ ".checkpoint"]. *)

val key :
  Source.t ->
  Overrides.t ->
  time:float ->
  frame:int ->
  files:string list ->
  string
(** The key of a still: what its pixels depend on (the scene's text digest, the files it
    read, the time and frame, the overrides). *)

val start : out:string -> key:string -> Scene.t -> t
(** Load the checkpoint of [out] if it has this key, or start an empty one. Raises
    {!Job_error.User} when the checkpoint's place cannot be written. *)

val resumed : t -> int
(** How many tiles the checkpoint held when it was loaded (0 for a new one). *)

val tiles : t -> int
(** How many tiles the image has. *)

val framebuffer : t -> Image.t
(** The image being rendered, with the finished tiles' pixels already in. *)

val todo : t -> int array
(** The tiles ({!Render.tiles} numbers) still to render, in order. *)

val finished : t -> int
(** How many tiles are done. *)

val tiles_done : t -> int array -> Stats.t -> unit
(** [tiles_done t tiles stats]: those tiles' pixels are in the framebuffer, with their
    counters summed in [stats]; rewrites the checkpoint when due. Safe from several
    domains at once. Raises {!Job_error.User} if the checkpoint cannot be written. *)

val save : t -> unit
(** Write the checkpoint now (on an interrupt). *)

val stats : t -> Stats.t
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
    {!Render.render_tiles}, recording each one; [on_tile finished rays] after each. Raises
    [Sys.Break] within a few thousand rays once [cancel] is cancelled; the tiles finished
    by then are recorded. *)
