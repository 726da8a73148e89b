(** The PNG writer's row filter written the plain way, one byte at a time with the
    textbook Paeth predictor (branches on the distances): the reference that the filtered
    rows inside the files {!Lancer.Png.encode} writes are compared with. *)

val filter_row : bpp:int -> bytes -> bytes -> bytes -> unit
(** [filter_row ~bpp row prev out] writes into [out] (length [Bytes.length row + 1]) the
    filter type, then [row] filtered with it: the type (None, Sub, Up, Average, Paeth)
    whose filtered bytes, read as signed, have the least sum of absolute values, the first
    on a tie. [prev] is the row above (zeros for the first), [bpp] the bytes per pixel. *)
