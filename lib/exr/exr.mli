(** OpenEXR files of a linear RGB framebuffer: the bytes of a scanline EXR image (ZIP
    compressed, channels R, G, B and, when given, A), made by OpenEXR's own library. *)

val available : (unit, string) result
(** Whether this build can write EXR files, or why not (the statically linked lancer
    cannot). *)

val encode :
  ?record:string ->
  width:int ->
  height:int ->
  half:bool ->
  rgb:Float.Array.t ->
  alpha:Float.Array.t option ->
  unit ->
  (string, string) result
(** [encode ~width ~height ~half ~rgb ~alpha] is the EXR file of the image whose pixel (i,
    j) (row j from the top) has linear colour [rgb.(3(j·width + i) + c)], as 16-bit half
    floats ([half]) or 32-bit floats, and alpha [alpha.(j·width + i)] when given. Values
    are stored as they are (no clamping, no curve), rounded to the nearest half or float.
    A non-empty [record] (no NUL) is the header's string attribute [lancer]. [Error] says
    why the library refused. *)
