(** The type checker: turns a parsed program (includes resolved) into a typed one
    ({!Tast}), and is the one producer of the diagnostics a program's text shows without
    running it, in every statement, both branches of every [if], every loop body, every
    function and macro body (called or not) and every included file.

    It reports: unknown block kinds; unknown fields (with a "did you mean" hint), fields
    given twice, missing required fields and fields the block's kind does not take;
    statements in a block that holds only fields, blocks that cannot stand inside a group;
    parameters named twice; and every value whose type is known and wrong where it is
    used: given to a field, an operator, a built-in function's argument, a condition, a
    loop's bound, a call of what is not a function or a macro, a component of a vector.

    A type is known from literals, the built-ins, operators and [let]s of known types; a
    parameter, what a function returns, and what an operator or a built-in makes of a
    value of unknown type are unknown, never guessed: their checks are the evaluation's,
    with the same messages ({!Msg}). So a mistake is reported once, by one of the two. It
    never refuses what would not be an error if the code ran. *)

type program = {
  stmts : Tast.stmt list;  (** the top-level statements, includes flattened *)
  bindings : int;  (** how many bindings the program defines ({!Tast.binding.id}s) *)
}

val program :
  ?schema:Schema.block list ->
  ?types:bool ->
  sources:(string, string) Hashtbl.t ->
  Ast.stmt list ->
  program * Error.t list
(** [program ~sources stmts] is the typed program and the mistakes found, in the order
    found. [sources] maps each file to its text, for the display. Block kinds and their
    fields are [schema]'s ({!Lancer_dsl.Schema.blocks} unless told). With [~types:false]
    every expression's type is taken as unknown: only what the text of blocks says is
    checked before the run, and every type is checked as the program runs (for testing
    that the two phases agree). *)

(** {1 Statement by statement}

    The same, as a program is read: each top-level statement checked as it comes, so that
    what is read and checked of a large program can go as soon as it is compiled. *)

type state

val start :
  ?schema:Schema.block list ->
  ?types:bool ->
  sources:(string, string) Hashtbl.t ->
  unit ->
  state

val top : state -> Ast.stmt -> Tast.stmt list
(** The next top-level statement, typed (an include's statements, each). *)

val finish : state -> int * Error.t list
(** How many bindings the program defines, and the mistakes found, in the order found. *)

val moving : state -> bool
(** Whether the statements seen so far write, anywhere (in a branch not taken, a macro
    never called), an [animation] or [physics] block, a body or a camera's [shutter]:
    unless they do, the program is a still without bodies and without motion blur. *)
