(** Located diagnostics of the scene language (errors, and the warnings of
    [lancer check]), printed as [file:line:col: message], the source line, a caret under
    the span and, for a file that was included, the chain of includes that led to it.

    Every error a scene can cause (lexical, syntax, type, name, range, limits, includes)
    is one of these; no exception escapes {!Lancer_dsl.Dsl}. *)

type kind = Error | Warning

type t = {
  kind : kind;  (** a warning is printed with "warning: " before its message *)
  file : string;
  line : int;  (** from 1; 0 when the error is about the file as a whole *)
  col : int;  (** from 1 *)
  end_col : int;  (** one past the span's last column on [line] *)
  message : string;
  source_line : string option;  (** the text of [line], for the caret display *)
  included_from : Loc.t list;
      (** where [file] was included, innermost first: each [include] statement that led to
          it; empty for the main file *)
}

val make : ?kind:kind -> ?source:string -> Loc.t -> string -> t
(** [make ~source loc msg] is the error [msg] at [loc]; [source] is the whole text of
    [loc.file], from which the line is taken. A span over several lines is underlined to
    the end of its first line. *)

val warning : ?source:string -> Loc.t -> string -> t
(** [warning ~source loc msg] is [make ~kind:Warning ~source loc msg]. *)

val file_error : ?kind:kind -> string -> string -> t
(** [file_error file msg] is an error about [file] as a whole (unreadable, not text):
    printed as [file: msg]. *)

val with_includes : (string -> Loc.t list) -> t -> t
(** [with_includes chain e] is [e] with [included_from = chain e.file] (kept when [e]
    already has a chain). *)

val cannot_read : what:string -> written:string -> string -> string option
(** [cannot_read ~what ~written path] is the message for a file that a scene names and
    that cannot be read (missing, a directory, not readable):
    [cannot read the WHAT "WRITTEN": REASON (looked for PATH)]; [None] when [path] is a
    readable file. Includes, images and meshes all say it this way. *)

val unreadable : string -> string option
(** Why the file at a path cannot be read (missing, a directory, not readable), the reason
    {!cannot_read} words; [None] when it is a readable file. *)

val cannot_read_because : what:string -> written:string -> string -> string -> string
(** [cannot_read_because ~what ~written path reason] is {!cannot_read}'s message for
    [reason] (from {!unreadable}): for a cache that keeps the reason and names the file as
    each place wrote it. *)

val pp : Format.formatter -> t -> unit
(** [file:line:col: message] ([warning: message] for a warning), then (when known) the
    source line and a caret line, then one [  included from FILE:LINE:COL] line per
    include, each followed by a newline. *)

val to_string : t -> string
(** The text {!pp} prints. *)
