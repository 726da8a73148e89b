(** Encoded images: the integer samples a PNG or PPM file holds, before or after the file.

    A raster has [channels] samples per pixel (1 gray, 2 gray and alpha, 3 RGB, 4 RGBA) of
    [depth] bits (8 or 16), row-major from the top-left pixel. Samples of 8 bits take one
    byte each; samples of 16 bits take two, most significant first (the byte order of both
    PNG and PPM). *)

val max_pixels : int
(** The largest image lancer makes or reads: width × height ≤ this (268 435 456 = 16384²,
    6 GiB of linear framebuffer). *)

type t = { width : int; height : int; channels : int; depth : int; samples : Bytes.t }

val make : width:int -> height:int -> channels:int -> depth:int -> Bytes.t -> t
(** [make ~width ~height ~channels ~depth samples]; raises [Invalid_argument] when
    [samples] has not width·height·channels·(depth/8) bytes, or channels or depth are out
    of range. *)

val get : t -> int -> int -> int -> int
(** [get r i j c] is sample [c] of column [i], row [j]: 0–255 or 0–65535. *)

val max_value : t -> int
(** 255 or 65535. *)

val to_rgb8 : t -> Bytes.t
(** 3·width·height bytes of 8-bit RGB: gray is repeated into the three channels, alpha is
    dropped, 16-bit samples are rounded to the nearest 8-bit value (v·255/65535). *)
