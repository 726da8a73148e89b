(** Substring search (no dependency on Str). *)

val find : string -> string -> int option
(** [find s sub] is the index of the first occurrence of [sub] in [s]. *)
