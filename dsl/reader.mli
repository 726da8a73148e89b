(** A fast reader of the grammar (dsl/parser.mly) for programs without a mistake: a
    recursive descent over the text, lexing as it goes, that builds the very syntax tree
    the Menhir parser builds (locations included) at a fraction of the time and memory
    (scenes that exporters write are large: 100 000 sphere blocks is 12 MB).

    It gives up on anything it is not sure of: a syntax or lexical error, a number too
    large, a character outside ASCII outside a comment or a string. {!Syntax} then hands
    the text to the Menhir parser, which explains the first error with the message of its
    state. *)

val program : file:string -> string -> (Ast.stmt list * bool) option
(** [program ~file text]: the program, and whether the text is plain ASCII without a NUL
    byte (what it holds outside comments and strings is: otherwise it gives up); or [None]
    where the Menhir parser must decide. *)

(** {1 Statement by statement} *)

type t

exception Give_up
(** Where the reader gives up (also [Failure], [Invalid_argument] and [Stack_overflow],
    for a number it cannot read or a program nested too deeply). *)

val start : file:string -> string -> t

val next : t -> Ast.stmt option
(** The next top-level statement; [None] at the end of the text. *)

val plain : t -> bool
(** Whether the text read so far is plain ASCII without a NUL byte. *)
