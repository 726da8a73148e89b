(** The check of a whole program before it runs, against {!Schema}: every statement, both
    branches of every [if], every loop body, every function and macro body (called or not)
    and every included file.

    It reports what is a mistake wherever the code stands, whether or not an evaluation
    would reach it: unknown block kinds, unknown fields (with a "did you mean" hint),
    fields given twice, missing required fields, statements in a block that holds only
    fields, blocks that cannot stand inside a group, and values of a type known without
    running them (literals, and operators and built-in functions on them) given where the
    field takes another type. Names bound by [let] to such values are known too;
    parameters, and what a function returns, are not.

    Each message and location is the evaluator's for the same mistake, so that a mistake
    in code that also runs is reported once. It never rejects what would not be an error
    if the code ran. *)

val run : sources:(string, string) Hashtbl.t -> Ast.stmt list -> Error.t list
(** [run ~sources program] is the mistakes of [program] (includes already resolved), in
    the order they were found. [sources] maps each file to its text, for the display. *)
