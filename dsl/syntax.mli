(** Text to syntax tree: {!Reader} reads a program without a mistake; the lexer and the
    Menhir parser (table back-end, incremental API) read any other, and turn its first
    lexical or syntax error into a located {!Lancer_dsl.Error.t}, whose message comes from
    [parser.messages] for the error state the parser is in. *)

val parse : file:string -> string -> (Ast.stmt list, Error.t) result
(** [parse ~file text] parses [text]; [file] names it in locations. Text with a NUL byte
    or invalid UTF-8 is rejected as not text. *)

val grammar : file:string -> string -> (Ast.stmt list, Error.t) result
(** The lexer and the Menhir parser alone, on text (not checked for NUL bytes and UTF-8):
    what {!Reader} reads must be what they read. *)

val without_bom : string -> string
(** [without_bom text] is [text] without the UTF-8 byte-order mark some editors write at
    its start (Windows Notepad), so that positions count from the first character seen. *)

val not_text : string -> string -> Error.t option
(** [not_text file text]: why [text] is not a scene's text (a NUL byte, invalid UTF-8). *)
