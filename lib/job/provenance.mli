(** What an image lancer renders says of where it came from, kept in the file itself (a
    PNG's text chunk, keyword ["lancer"]): the version that rendered it, the scene (from
    the image's directory) and the digest of its text, the MD5 of every file the scene
    read, the options that change pixels, the frame and time, how the image was encoded,
    and a digest of each 32×32 block of the pixels as written. Nothing in it depends on
    the number of domains, ranks or shards, nor on the working directory or where the
    project lies: the same scene and options, written to the same place beside the scene,
    give the same bytes. [lancer verify] reads it back to render some blocks again and
    compare ({!Lancer_run.Verify_run}). *)

type budget = { metric : string; limit : float; values : (string * float) list }
(** What [--max-error] chose, for an image rendered with it: the limit, in a metric's name
    (["flip"], ["rmse"], ["psnr"]), and the value of each setting it chose, by name. *)

type t = {
  version : string;  (** lancer's, as [lancer --version] prints it *)
  scene : string option;
      (** the scene file, as a path from the image's directory; [None] for the built-in
          showcase *)
  scene_digest : string;  (** the digest of the scene's text and includes, as read *)
  files : (string * string) list;
      (** each file the scene read (includes, images, meshes) by the path the scene names
          it with (from the scene's directory), and its MD5 *)
  options : Overrides.t;
  frame : int;
  time : float;
  region : Image.region option;  (** [--region]: only these pixels were rendered *)
  crop : bool;  (** [--crop]: the image is the region alone *)
  alpha : bool;  (** [--alpha]: a fourth channel of coverage *)
  bits : int;  (** 8 or 16 *)
  max_error : budget option;
      (** with [--max-error], what it chose: the image is the scene with [options] at
          these settings *)
  blocks : string;
      (** 8 hexadecimal digits a block (a 32-bit digest of its samples,
          {!Lancer_image.Image.block_digests}), blocks of {!block_size} pixels row-major
          over the image as written *)
}

val keyword : string
(** ["lancer"]: the PNG text chunk that holds the record. *)

val block_size : int
(** 32: the side of a block, in the image's own pixels. *)

val make :
  ?max_error:budget ->
  image:string ->
  Scenes.t ->
  Overrides.t ->
  files:(string * string) list ->
  time:float ->
  frame:int ->
  region:Image.region option ->
  crop:bool ->
  alpha:bool ->
  bits:int ->
  t
(** The record of the image about to be written to [image] from the scene at [time] and
    [frame] ([files]: the images and meshes that scene read, as {!Scenes.t.evaluate} names
    them, each with its MD5 from {!Scenes.t.input_digest}), without its blocks. *)

val blocks : Raster.t -> string
(** The digests of the raster's blocks, as {!t.blocks} holds them. *)

val block_count : Raster.t -> int * int
(** The blocks across and down. *)

val text : t -> Raster.t option -> (string * string) list
(** The text of the record with the blocks of the raster about to be written (a PNG's), or
    none (an EXR's header: its values are floats). *)

val of_text : string -> (t, string) result
(** A record read back: [Error] says what is wrong with it (a file lancer reads is input
    like any other). *)
