(** Output encoding and image files: a {!Framebuffer} encoded into a {!Raster} and
    written, and image files read back.

    Encoding (doc/reference/shading.md, section 9): clamp to [0, 1]; sRGB (v ≤ 0.0031308 →
    12.92·v, else 1.055·v^(1/2.4) − 0.055) or v^(1/g); byte = ⌊255·v + 0.5⌋. Files are PNG
    ({!module-Png}, plain, 8-bit RGB by default) or binary PPM by extension, always
    written atomically: a temporary file in the same directory, then a rename. *)

(** How linear values are encoded into an image's samples. *)
type gamma = Srgb  (** the sRGB transfer curve *) | Power of float  (** v^(1/g) *)

val max_pixels : int
(** {!Raster.max_pixels}. *)

val curve : gamma -> float -> float
(** The encoding curve, in \[0, 1\], of a linear value clamped to \[0, 1\] (NaN as 0). *)

val encode_channel : gamma -> float -> int
(** One linear channel value to a byte (NaN encodes as 0). *)

val encode_channel16 : gamma -> float -> int
(** The same curve quantised to 16 bits: ⌊65535·v + 0.5⌋ (NaN encodes as 0). *)

val to_bytes : gamma -> Framebuffer.t -> Bytes.t
(** 3·width·height encoded bytes, row-major RGB. *)

type format =
  | Png
  | Ppm
  | Exr  (** OpenEXR: linear half or float RGB(A), {!Lancer_exr.Exr} *)
  | Hdr  (** Radiance RGBE: linear, an 8-bit mantissa per channel and a shared exponent *)
  | Pfm  (** portable float map: linear 32-bit float RGB *)

val format_of_path : string -> (format, string) result
(** By extension: [.png], [.ppm], [.exr], [.hdr] or [.pfm] (case-insensitive); anything
    else is an error. *)

val linear : format -> bool
(** Whether the format holds the framebuffer's linear values themselves (EXR, HDR, PFM)
    rather than samples encoded by the curve (PNG, PPM). *)

val keeps_record : format -> bool
(** Whether an image of the format holds lancer's record of where it came from (PNG, in a
    text chunk, and EXR, in a header attribute); PPM, HDR and PFM hold none. *)

val format_name : format -> string
(** ["png"], ["exr"], …, as the extension and [--format] write it. *)

val check_writable : string -> (unit, string) result
(** {!Safe_file.check_writable}, and for an [.exr] path whether this build writes EXR:
    callers use it to refuse before working. *)

val write_atomic : string -> (out_channel -> unit) -> (unit, string) result
(** {!Safe_file.write}: [write_atomic path f] writes [path] through [f] into a temporary
    file beside it and renames it into place once every write, the flush, the [fsync] and
    the close succeeded; on any failure [path] is untouched and no temporary file stays.
*)

val write_rgb8 : string -> int -> int -> Bytes.t -> (unit, string) result
(** [write_rgb8 path w h bytes] writes encoded pixels as PNG or PPM by [path]'s extension,
    atomically. *)

type region = { x0 : int; y0 : int; x1 : int; y1 : int }
(** The pixels x0 ≤ i < x1, y0 ≤ j < y1. *)

val encode :
  ?gamma:gamma ->
  ?bits:int ->
  ?alpha:Float.Array.t ->
  ?crop:region ->
  Framebuffer.t ->
  Raster.t
(** [encode fb] is [fb]'s RGB samples at [bits] (8, the default, or 16) through
    {!encode_channel} or {!encode_channel16}; with [alpha] (one linear value per pixel,
    row-major) a fourth channel ⌊max·a + 0.5⌋, not gamma-encoded; with [crop] only that
    region. Raises [Invalid_argument] on a bad size, bit count or region. *)

val write_raster : string -> Raster.t -> (unit, string) result
(** Write samples as PNG (any channels, 8 or 16 bits) or PPM (RGB only, maximum value 255
    or 65535) by [path]'s extension, atomically. *)

val output_raster : format -> out_channel -> Raster.t -> unit
(** [output_raster fmt oc r] writes the file's bytes to [oc] (standard output, a pipe);
    errors raise [Sys_error] as the channel's do. A PPM of other than 3 channels raises
    [Invalid_argument]. *)

val save :
  ?gamma:gamma ->
  ?bits:int ->
  ?alpha:Float.Array.t ->
  ?crop:region ->
  string ->
  Framebuffer.t ->
  (unit, string) result
(** [save path fb] is {!write_raster} of {!encode} (default sRGB, 8-bit RGB, the whole
    image). *)

val read_raster : string -> (Raster.t, string) result
(** [read_raster path] is the samples of a PNG (any colour type, 1 to 16 bits, interlaced
    or not) or binary PPM (maximum value 255 or 65535) file. A PNG's size is checked
    before its pixels are allocated: larger than {!max_pixels} is an error. Never raises;
    the message starts with [path]. *)

val file_of :
  format ->
  ?gamma:gamma ->
  ?bits:int ->
  ?alpha:Float.Array.t ->
  ?crop:region ->
  ?text:(Raster.t option -> (string * string) list) ->
  Framebuffer.t ->
  (string, string) result
(** [file_of format fb] is the bytes of the file of that format holding [fb], as
    {!save_written} writes them (for standard output, or a file written another way).
    [bits]: 8 or 16 for PNG and PPM (default 8), 16 or 32 for EXR (half or single floats,
    default 16), none for HDR and PFM. [text]: a PNG's text chunks ({!Png.encode}), made
    from the encoded image ([Some]); an EXR keeps the text of keyword ["lancer"], made
    without an encoded image ([None]), as a header attribute; other formats keep none. *)

val block_digests : size:int -> Raster.t -> string
(** A 32-bit digest (FNV-1a over 4-byte words) of each [size]×[size] block of the raster's
    samples (the last row and column of blocks may be smaller), row-major, 8 hexadecimal
    digits a block. *)

val bits_problem : format -> int option -> string option
(** Why [bits] does not fit the format ({!file_of}); [None] when it does. *)

type written = { size : int; md5 : string Lazy.t }
(** What was written to a file: its size in bytes and the MD5 (hex) of those bytes,
    computed from them when it is first forced: by one domain (a lazy value forced by two
    at once raises). *)

val save_written :
  ?gamma:gamma ->
  ?bits:int ->
  ?alpha:Float.Array.t ->
  ?crop:region ->
  ?text:(Raster.t option -> (string * string) list) ->
  string ->
  Framebuffer.t ->
  (written, string) result
(** {!save}, and the size and MD5 of the bytes it wrote, digested from those bytes (not
    read back from the file): what the file held when this write ended, even if another
    process replaces it right after. A linear format ({!linear}) takes the framebuffer's
    values as they are, before the encoding curve and without clamping: EXR as half
    floats, or 32-bit floats with [~bits:32], with [alpha] as its A channel; HDR and PFM
    without alpha. [gamma] is then unused. *)

val read_bytes : string -> (string, string) result
(** [read_bytes path] is the whole content of the image file at [path], read once, after
    the checks {!read_raster} makes from its name and status (a known extension, a regular
    file, not larger than the largest PNG lancer decodes). Never raises; the message
    starts with [path]. *)

val raster_of_string : path:string -> string -> (Raster.t, string) result
(** [raster_of_string ~path bytes] decodes [bytes], the content of the file [path] (whose
    extension gives the format), as {!read_raster} does. Never raises. *)

val read_rgb8 : string -> (int * int * Bytes.t, string) result
(** [read_rgb8 path] is (width, height, bytes) of a PNG or PPM file converted to 8-bit RGB
    as {!Raster.to_rgb8} does. Never raises. *)

val of_raster : Raster.t -> Framebuffer.t
(** The linear framebuffer of sRGB-encoded samples, at their full precision (8 or 16
    bits); gray is repeated into the three channels, alpha is dropped. *)

val read_linear : string -> (Framebuffer.t, string) result
(** [read_linear path] decodes an sRGB image file to a linear framebuffer (for image
    textures and bump maps). *)

val linear_of_string : path:string -> string -> (Framebuffer.t, string) result
(** [linear_of_string ~path bytes] is {!read_linear} of the file [path] whose content is
    [bytes]. *)
