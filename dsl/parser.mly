/* The grammar of .rts scene scripts (doc/reference/language.md). Operator precedence is
   encoded in the levels of [expr], loosest first: if-then-else, or, and, not, comparisons (not
   associative), + -, * / %, unary -, ^ (right-associative), field access, indexing and
   calls. */

%{
open Ast
let loc (s, e) = Loc.of_positions s e
let mk d l = { e = d; loc = loc l }
let st d l = { s = d; sloc = loc l }
%}

%token <float> NUMBER
%token <string> STRING
%token <string> IDENT
%token TRUE FALSE LET FN FOR IN TO STEP IF THEN ELSE INCLUDE BODY MATERIAL AND OR NOT
%token LPAREN RPAREN LBRACE RBRACE LBRACKET RBRACKET COMMA COLON DOT ASSIGN
%token EQ NE LT LE GT GE PLUS MINUS STAR SLASH PERCENT CARET
%token EOF

%start <Ast.stmt list> program

%%

program:
  | ss = stmt* EOF { ss }

name:
  | x = IDENT { { id = x; nloc = loc $loc } }

params:
  | LPAREN ps = separated_list(COMMA, name) RPAREN { ps }

args:
  | LPAREN a = separated_list(COMMA, expr) RPAREN { a }

body:
  | LBRACE ss = stmt* RBRACE { ss }

stmt:
  | LET x = name ASSIGN e = expr { st (Let (x, e)) $loc }
  | FN f = name ps = params ASSIGN e = expr { st (Fn (f, ps, e)) $loc }
  | FN f = name ps = params b = body { st (Macro (f, ps, b)) $loc }
  | FOR x = name IN a = expr TO b = expr s = step b2 = body { st (For (x, a, b, s, b2)) $loc }
  | FOR x = name IN l = expr b = body { st (For_each (x, l, b)) $loc }
  | s = if_stmt { s }
  | INCLUDE p = STRING { st (Include (p, loc $loc(p))) $loc }
  | k = name LBRACE its = items RBRACE { st (Block (k, its)) $loc }
  | BODY n = name LBRACE its = items RBRACE { st (Body (n, its)) $loc }
  | f = name a = args { st (Call_stmt (f, a)) $loc }

step:
  | { None }
  | STEP e = expr { Some e }

if_stmt:
  | IF c = expr t = body e = else_part { st (If_stmt (c, t, e)) $loc }

else_part:
  | { [] }
  | ELSE b = body { b }
  | ELSE s = if_stmt { [ s ] }

items:
  | { [] }
  | i = item its = items { i :: its }
  | i = item COMMA its = items { i :: its }

item:
  | f = field_name COLON e = expr { Field (f, e) }
  | s = stmt { Stmt s }

field_name:
  | x = IDENT { { id = x; nloc = loc $loc } }
  | MATERIAL { { id = "material"; nloc = loc $loc } }
  | STEP { { id = "step"; nloc = loc $loc } }

expr:
  | IF c = expr THEN a = expr ELSE b = expr { mk (If (c, a, b)) $loc }
  | e = or_expr { e }

or_expr:
  | a = or_expr OR b = and_expr { mk (Binop (Or, a, b)) $loc }
  | e = and_expr { e }

and_expr:
  | a = and_expr AND b = not_expr { mk (Binop (And, a, b)) $loc }
  | e = not_expr { e }

not_expr:
  | NOT a = not_expr { mk (Unop (Not, a)) $loc }
  | e = cmp_expr { e }

cmp_expr:
  | a = add_expr op = cmp_op b = add_expr { mk (Binop (op, a, b)) $loc }
  | e = add_expr { e }

%inline cmp_op:
  | EQ { Eq } | NE { Ne } | LT { Lt } | LE { Le } | GT { Gt } | GE { Ge }

add_expr:
  | a = add_expr PLUS b = mul_expr { mk (Binop (Add, a, b)) $loc }
  | a = add_expr MINUS b = mul_expr { mk (Binop (Sub, a, b)) $loc }
  | e = mul_expr { e }

mul_expr:
  | a = mul_expr STAR b = unary_expr { mk (Binop (Mul, a, b)) $loc }
  | a = mul_expr SLASH b = unary_expr { mk (Binop (Div, a, b)) $loc }
  | a = mul_expr PERCENT b = unary_expr { mk (Binop (Mod, a, b)) $loc }
  | e = unary_expr { e }

unary_expr:
  | MINUS a = unary_expr { mk (Unop (Neg, a)) $loc }
  | e = pow_expr { e }

pow_expr:
  | a = postfix_expr CARET b = unary_expr { mk (Binop (Pow, a, b)) $loc }
  | e = postfix_expr { e }

postfix_expr:
  | a = postfix_expr DOT f = name { mk (Dot (a, f)) $loc }
  | a = postfix_expr LBRACKET i = expr RBRACKET { mk (Index (a, i)) $loc }
  | e = atom { e }

atom:
  | n = NUMBER { mk (Num n) $loc }
  | s = STRING { mk (Str s) $loc }
  | TRUE { mk (Bool true) $loc }
  | FALSE { mk (Bool false) $loc }
  | x = IDENT { mk (Var x) $loc }
  | f = name a = args { mk (Call (f, a)) $loc }
  | LPAREN e = expr RPAREN { { e with loc = loc $loc } }
  | LPAREN a = expr COMMA b = expr RPAREN { mk (Pair (a, b)) $loc }
  | LPAREN a = expr COMMA b = expr COMMA c = expr RPAREN { mk (Vec (a, b, c)) $loc }
  | MATERIAL LBRACE its = items RBRACE { mk (Material its) $loc }
  | LBRACKET l = elements RBRACKET { mk (List l) $loc }

/* A list's elements, separated by commas; one may follow the last. */
elements:
  | { [] }
  | e = expr { [ e ] }
  | e = expr COMMA l = elements { e :: l }
