(** Source locations of the scene language: a file and a span of one or more lines.

    Lines and columns count from 1; [end_col] is one past the last character of the span
    on [end_line], so a one-character span has [end_col = col + 1]. *)

type t = { file : string; line : int; col : int; end_line : int; end_col : int }

val of_positions : Lexing.position -> Lexing.position -> t
(** [of_positions start stop] is the span from [start] to [stop] (as the lexer gives
    them). *)

val whole_file : string -> t
(** The location 1:1 of a file, for errors about the file as a whole. *)

val relative_to : string -> string -> string
(** [relative_to file p] is path [p] as written in [file]: relative paths are found in
    [file]'s directory (includes, images, meshes). *)
