type name = { id : string; nloc : Loc.t }
type binop = Add | Sub | Mul | Div | Mod | Pow | Eq | Ne | Lt | Le | Gt | Ge | And | Or
type unop = Neg | Not

type expr = { e : expr_desc; loc : Loc.t }

and expr_desc =
  | Num of float
  | Str of string
  | Bool of bool
  | Var of string
  | Vec of expr * expr * expr
  | Pair of expr * expr
  | Binop of binop * expr * expr
  | Unop of unop * expr
  | Dot of expr * name
  | Call of name * expr list
  | If of expr * expr * expr
  | Material of item list
  | List of expr list
  | Index of expr * expr

and item = Field of name * expr | Stmt of stmt
and stmt = { s : stmt_desc; sloc : Loc.t }

and stmt_desc =
  | Let of name * expr
  | Fn of name * name list * expr
  | Macro of name * name list * stmt list
  | For of name * expr * expr * expr option * stmt list
  | For_each of name * expr * stmt list
  | If_stmt of expr * stmt list * stmt list
  | Include of string * Loc.t
  | Included of string * stmt list
  | Block of name * item list
  | Body of name * item list
  | Call_stmt of name * expr list

let binop_name = function
  | Add -> "+"
  | Sub -> "-"
  | Mul -> "*"
  | Div -> "/"
  | Mod -> "%"
  | Pow -> "^"
  | Eq -> "=="
  | Ne -> "!="
  | Lt -> "<"
  | Le -> "<="
  | Gt -> ">"
  | Ge -> ">="
  | And -> "and"
  | Or -> "or"
