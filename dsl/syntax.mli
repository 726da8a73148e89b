(** Text to syntax tree: runs the lexer and the Menhir parser (table back-end, incremental
    API) and turns the first lexical or syntax error into a located {!Error.t}, whose
    message comes from [parser.messages] for the error state the parser is in. *)

val parse : file:string -> string -> (Ast.stmt list, Error.t) result
(** [parse ~file text] parses [text]; [file] names it in locations. Text with a NUL byte
    or invalid UTF-8 is rejected as not text. *)
