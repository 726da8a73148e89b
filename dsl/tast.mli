(** The typed program: what the type checker ({!Check}) makes of the parsed one, and what
    the compiler ({!Compile}) trusts.

    Every name is resolved to the definition it reads (or to the message of the error it
    is where it does not name one), every expression has its static type, every block its
    kind, and every field of a block the place of the block's field it gives. What the
    checker reported is marked, not left for later phases to find again: an expression
    with a mistake is {!Bad} (it gives up quietly when it runs), a block with one is
    [failed] (it is not built, and its other fields are still read for the mistakes only a
    run can find). *)

type binding = {
  id : int;  (** from 0, in the order the checker meets them *)
  name : string;
  level : int;  (** the functions and macros it is inside: 0 for the program's *)
}
(** A definition: a [let], a function or macro, a parameter, a loop's variable, a body's
    name. *)

type var =
  | Local of binding
  | Maybe of binding * (unit -> string)
      (** a body's name, defined only if its body was built (otherwise it keeps what it
          named before, if anything): the message of the error where it names nothing
          (made when it is needed: it names a definition further down, if any) *)
  | Global of Builtins.t
  | Unbound of (unit -> string)
      (** not a name here: the message of the error, when it runs *)

type expr = { e : desc; ty : Ty.t; loc : Loc.t }

and desc =
  | Const of Value.t  (** a literal *)
  | Var of var
  | Vec of expr * expr * expr
  | Pair of expr * expr
  | Binop of Ast.binop * expr * expr
  | Unop of Ast.unop * expr
  | Dot of expr * Ast.name
  | Call_builtin of Builtins.t * Builtins.fn * expr list
  | Call of expr * Ast.name * expr list  (** the callee's value, its name as written *)
  | If of expr * expr * expr
  | Material of block
  | List of expr list
  | Index of expr * expr
  | Bad  (** a mistake the checker reported *)

and stmt = { s : sdesc; sloc : Loc.t }

and sdesc =
  | Let of binding * expr
  | Fn of binding * fn_def * expr
  | Macro of binding * fn_def * stmt list
  | Poisoned_fn of binding  (** a function or macro whose parameters are wrong *)
  | For of binding * expr * expr * expr option * stmt list
  | For_each of binding * expr * stmt list
  | If_stmt of expr * stmt list * stmt list
  | Call_stmt of expr * Ast.name * expr list  (** a macro call: the callee's value *)
  | Block of block
  | Body of binding * var option * block option
      (** the name, what it named before, the body's block ([None]: a body where none can
          be, reported) *)
  | Nothing  (** a statement the checker refused as a whole: it does nothing *)

and fn_def = { fname : string; params : binding list; level : int }
(** [level]: that of the function's body (its parameters' level). *)

and block = {
  keyword : Ast.name;  (** as written: [sphere], [light], … *)
  kind : Kind.t;  (** its kind (a light's chosen by its fields) *)
  items : item list;  (** in the order written *)
  failed : bool;  (** the checker reported a mistake of the block itself or a field *)
  kind_known : bool;
      (** the checker knew its [kind] (the field left out, or a string literal), and
          checked the fields that depend on it; otherwise the run does *)
  where : where;
}

(** Where a block stands, as far as the checker knows: at top level, inside a group, CSG
    block or body, or in a macro called from either. *)
and where = Top | Inside | Either

and item =
  | Field of field
  | Stmts of stmt list
      (** a [let], a function, a macro; the members of a group (an include's several) *)

and field = {
  name : Ast.name;
  value : expr;  (** {!Bad} where its type is one the field does not take *)
  slot : slot;
  wrong : bool;  (** its value's type is one the field does not take (reported) *)
}

and slot =
  | Slot of int  (** the block's field of that index in [Schema.names_of] *)
  | Step of string
      (** a transform ([translate], [rotate], [scale]), in the order written *)
  | Dropped
      (** a field the block does not take (there, or at all), or given twice: reported,
          not run *)
