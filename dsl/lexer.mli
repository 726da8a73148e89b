(** The lexer of [.rts] scripts: comments, numbers, strings, identifiers and keywords,
    operators. Raises {!Lex_error} on a character or literal it cannot read. *)

exception Lex_error of Loc.t * string

val token : Lexing.lexbuf -> Parser.token
(** The next token of the buffer, skipping white space and comments; [EOF] at the end. *)

val describe : Parser.token -> string
(** The token as a user would write it, for syntax error messages ("`\{`", "a number"). *)

val keyword_name : Parser.token -> string option
(** The keyword a token is, as written ("step"); [None] for other tokens. *)
