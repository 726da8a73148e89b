(** Typed expressions to closures: each name resolved to a slot of its function's frame or
    to a value the function captured, each built-in call to its implementation, each
    operator to its code for the operands' types. Where the checker knew a type, the code
    trusts it; where it did not, the code checks the value as it runs, with the checker's
    messages ({!Msg}). *)

type code = Value.frame -> Value.t

(** Where a definition's value is, seen from the function being compiled: a slot of its
    frame, or a value it captured when it was defined. *)
type access = Slot of int | Cap of int

type fn = {
  level : int;
  mutable nslots : int;
  mutable caps : (int * int * access) list;
  mutable ncaps : int;
  parent : fn option;
}
(** The function (or the program) being compiled: its frame's slots, and what it captures
    from around its definition (newest first, with each one's index and where it is in the
    function around). *)

type slots

type t = { slots : slots; fn : fn }
(** What compiling a program keeps: the slot of each binding (by id, in its own function's
    frame), and the function being compiled. *)

val create : unit -> t
(** Compiling a program's top level. *)

val set_slot : t -> Tast.binding -> int -> unit
(** Where a binding is in its function's frame. *)

val inner : t -> level:int -> nparams:int -> t
(** Compiling a function's body, at that level, its parameters its first slots. *)

val new_slot : t -> Tast.binding -> int
(** The slot of a new definition in the function being compiled. *)

val resolve : t -> Tast.binding -> access

val raw : access -> code
(** The value as it is (poisoned or not). *)

val var : t -> Tast.var -> Loc.t -> code
(** The code that reads a name: one poisoned gives up quietly; one that names nothing, its
    error. *)

val const : Tast.expr -> Value.t option
(** The value of an expression written as a constant: a literal, a negative number, a
    vector of those. *)

val expr : block:(t -> Tast.block -> code) -> t -> Tast.expr -> code
(** [block] compiles a material block. *)

val number : Tast.expr -> (Ty.t -> string) -> code -> Value.frame -> float
(** [number e msg c]: the number [c] (the code of [e]) computes; where [e]'s type was not
    known, one of another type is refused with [msg]. *)

val boolean : Tast.expr -> (Ty.t -> string) -> code -> Value.frame -> bool
(** [boolean e msg c]: the boolean [c] computes; where [e]'s type was not known, one of
    another type is refused with [msg]. *)

val call_fun : Value.closure -> code array -> Loc.t -> code
val call_macro : Value.macro -> code array -> Loc.t -> Value.frame -> Value.scope -> unit
