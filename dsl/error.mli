(** Located errors of the scene language, printed as [file:line:col: message], the source
    line and a caret under the span.

    Every error a scene can cause (lexical, syntax, type, name, range, limits, includes)
    is one of these; no exception escapes {!Dsl}. *)

type t = {
  file : string;
  line : int;  (** from 1; 0 when the error is about the file as a whole *)
  col : int;  (** from 1 *)
  end_col : int;  (** one past the span's last column on [line] *)
  message : string;
  source_line : string option;  (** the text of [line], for the caret display *)
}

val make : ?source:string -> Loc.t -> string -> t
(** [make ~source loc msg] is the error [msg] at [loc]; [source] is the whole text of
    [loc.file], from which the line is taken. A span over several lines is underlined to
    the end of its first line. *)

val file_error : string -> string -> t
(** [file_error file msg] is an error about [file] as a whole (unreadable, not text):
    printed as [file: msg]. *)

val pp : Format.formatter -> t -> unit
(** [file:line:col: message], then (when known) the source line and a caret line, each
    followed by a newline. *)

val to_string : t -> string
(** The text {!pp} prints. *)
