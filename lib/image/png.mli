(** PNG files, written and read by lancer itself over zlib (camlzip's [Zlib]).

    The writer makes plain (non-interlaced) images of gray, gray+alpha, RGB or RGBA
    samples at 8 or 16 bits, each row with the filter that makes it smallest (the sum of
    absolute differences, as libpng chooses). The reader takes every standard PNG: colour
    types gray, gray+alpha, RGB, RGBA and palette, bit depths 1 to 16, interlaced (Adam7)
    or not; every chunk's CRC is checked. Palette images become RGB (RGBA when they have a
    transparency chunk); gray at 1, 2 or 4 bits is scaled to 8. Nothing is printed. *)

val encode :
  ?level:int -> ?text:(string * string) list -> Raster.t -> (string -> unit) -> unit
(** [encode r write] passes the bytes of a PNG file of [r] to [write], in order, a chunk
    at a time (so that a file is written as it is compressed). [level] is zlib's, 0–9
    (default 6). Each [(keyword, text)] of [text] becomes an uncompressed iTXt chunk after
    the header (keyword: 1 to 79 Latin-1 bytes without NUL; text: UTF-8). Exceptions
    raised by [write] (a full disk) propagate. *)

val texts : string -> ((string * string) list, string) result
(** [texts contents] is every (keyword, text) of a PNG file's tEXt chunks and uncompressed
    iTXt chunks, in file order; chunks whose CRC is wrong are left out. [Error] only for a
    file that is not a PNG. *)

val finally : (unit -> unit) -> (unit -> 'a) -> 'a
(** [finally release body] is [body ()], with [release ()] run after it also when [body]
    raises; an exception from [release] never replaces [body]'s own (as
    [Fun.Finally_raised] would). *)

val decode : ?max_pixels:int -> string -> (Raster.t, string) result
(** [decode contents] is the image of a PNG file's contents. [Error] says plainly what is
    wrong or unsupported (not a PNG, a bad CRC in chunk IDAT, truncated data, an
    unsupported bit depth, an image larger than [max_pixels] pixels (default
    {!Raster.max_pixels}), …). Never raises. *)
