(** The operators of expressions: which types each one combines and what it makes of them,
    as the type checker sees them (types) and as a program runs (values). The two agree:
    an operation that {!binop_type} refuses is the one {!binop} refuses, with the same
    message. *)

val binop_type : Ast.binop -> Ty.t -> Ty.t -> Ty.t option
(** The type an arithmetic or comparison operator ([and] and [or] aside) makes of operands
    of these (known) types; [None] when it cannot combine them. *)

val binop : Loc.t -> Ast.binop -> Loc.t -> Value.t -> Value.t -> Value.t
(** [binop loc op bloc a b]: the operator on two values ([loc] the whole expression's
    place, [bloc] the right operand's, where a division by zero is shown). Raises
    {!Value.Fail} with {!Msg.cannot_combine} when their types do not combine, or with the
    mistake the values make (a division by zero, an overflow, a NaN); {!Value.Poisoned}
    for a poisoned operand. *)

(** The arithmetic of two numbers, each as {!binop} computes it: *)

val add : Loc.t -> float -> float -> Value.t
val sub : Loc.t -> float -> float -> Value.t
val mul : Loc.t -> float -> float -> Value.t

val div : Loc.t -> Loc.t -> float -> float -> Value.t
(** [div loc bloc x y]. *)

val neg_type : Ty.t -> Ty.t option
val neg : Loc.t -> Value.t -> Value.t
val not_type : Ty.t -> Ty.t option
val not_ : Loc.t -> Value.t -> Value.t

val equal : Value.t -> Value.t -> bool
(** [==] on two values of a type it compares (numbers, booleans, strings, vectors). *)
