(** The located abstract syntax tree of an [.rts] program, as the parser builds it.

    Every expression, statement, name and field carries its {!Loc.t}, so that the
    evaluator can point at the exact text of an error. [Include] statements are replaced
    by [Included] (the parsed statements of the included file) when a program is loaded.
*)

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
  | Pair of expr * expr  (** [(t, c)]: an entry of a colour map *)
  | Binop of binop * expr * expr
  | Unop of unop * expr
  | Dot of expr * name  (** [e.x], [ball.position] *)
  | Call of name * expr list
  | If of expr * expr * expr
  | Material of item list  (** [material { … }] *)
  | List of expr list  (** [[a, b, c]] *)
  | Index of expr * expr  (** [l[i]], from 0 *)

and item =
  | Field of name * expr  (** [name: value] *)
  | Stmt of stmt  (** a statement inside a block ([let], objects of a group, …) *)

and stmt = { s : stmt_desc; sloc : Loc.t }

and stmt_desc =
  | Let of name * expr
  | Fn of name * name list * expr  (** [fn f(a, b) = e] *)
  | Macro of name * name list * stmt list  (** [fn f(a, b) { … }] *)
  | For of name * expr * expr * expr option * stmt list
      (** [for i in a to b step s { … }] *)
  | For_each of name * expr * stmt list  (** [for x in LIST { … }] *)
  | If_stmt of expr * stmt list * stmt list
  | Include of string * Loc.t
  | Included of string * stmt list  (** the file and its statements, after loading *)
  | Block of name * item list  (** [settings { … }], [sphere { … }], [group { … }], … *)
  | Body of name * item list  (** [body NAME { … }] *)
  | Call_stmt of name * expr list  (** a macro call *)

val binop_name : binop -> string
(** The operator as written ("+", "and", …). *)
