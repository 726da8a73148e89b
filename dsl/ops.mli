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

(** {1 Lists} *)

val is_list : Ty.t -> bool

val element : Ty.t -> Ty.t
(** The type of a list's elements; {!Ty.Unknown} for any other type. *)

val list_type : (Ty.t * Loc.t) list -> (Ty.t, Loc.t * string) result
(** The type of a list literal whose elements have these types (and places): [Error] at
    the first element whose type its first element's cannot share ({!Ty.join}), with
    {!Msg.list_element}. *)

val list : (Value.t * Loc.t) array -> Value.t
(** The list of these values, refused as {!list_type} refuses their types. *)

val index : Loc.t -> Loc.t -> Value.t -> Value.t -> Value.t
(** [index aloc iloc l i]: element [i] of list [l], from 0. Raises {!Value.Fail} at [aloc]
    when [l] is not a list, at [iloc] when [i] is not a whole number in range. *)
