type binding = { id : int; name : string; level : int }

type var =
  | Local of binding
  | Maybe of binding * (unit -> string)
  | Global of Builtins.t
  | Unbound of (unit -> string)

type expr = { e : desc; ty : Ty.t; loc : Loc.t }

and desc =
  | Const of Value.t
  | Var of var
  | Vec of expr * expr * expr
  | Pair of expr * expr
  | Binop of Ast.binop * expr * expr
  | Unop of Ast.unop * expr
  | Dot of expr * Ast.name
  | Call_builtin of Builtins.t * Builtins.fn * expr list
  | Call of expr * Ast.name * expr list
  | If of expr * expr * expr
  | Material of block
  | List of expr list
  | Index of expr * expr
  | Bad

and stmt = { s : sdesc; sloc : Loc.t }

and sdesc =
  | Let of binding * expr
  | Fn of binding * fn_def * expr
  | Macro of binding * fn_def * stmt list
  | Poisoned_fn of binding
  | For of binding * expr * expr * expr option * stmt list
  | For_each of binding * expr * stmt list
  | If_stmt of expr * stmt list * stmt list
  | Call_stmt of expr * Ast.name * expr list
  | Block of block
  | Body of binding * var option * block option
  | Nothing

and fn_def = { fname : string; params : binding list; level : int }

and block = {
  keyword : Ast.name;
  kind : Kind.t;
  items : item list;
  failed : bool;
  kind_known : bool;
  where : where;
}

and where = Top | Inside | Either
and item = Field of field | Stmts of stmt list
and field = { name : Ast.name; value : expr; slot : slot; wrong : bool }
and slot = Slot of int | Step of string | Dropped
