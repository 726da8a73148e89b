open Ast

(* Anything the reader is not sure of: the Menhir parser decides. *)
exception Give_up

type tok =
  | EOF
  | IDENT
  | NUMBER
  | STRING
  | TRUE
  | FALSE
  | LET
  | FN
  | FOR
  | IN
  | TO
  | STEP
  | IF
  | THEN
  | ELSE
  | INCLUDE
  | BODY
  | MATERIAL
  | AND
  | OR
  | NOT
  | LPAREN
  | RPAREN
  | LBRACE
  | RBRACE
  | LBRACKET
  | RBRACKET
  | COMMA
  | COLON
  | DOT
  | ASSIGN
  | EQ
  | NE
  | LT
  | LE
  | GT
  | GE
  | PLUS
  | MINUS
  | STAR
  | SLASH
  | PERCENT
  | CARET

type t = {
  text : string;
  len : int;
  file : string;
  mutable pos : int;  (** where lexing goes on *)
  mutable line : int;  (** the line at [pos] *)
  mutable bol : int;  (** where that line begins *)
  mutable tok : tok;  (** the current token: *)
  mutable tline : int;
  mutable tcol : int;
  mutable tend : int;  (** its end's column (one past), on its own line *)
  mutable ident : string;
  mutable num : float;
  mutable str : string;
  mutable eline : int;  (** the end of the last token read *)
  mutable ecol : int;
  names : (string * tok) list array;
      (** identifiers read so far, by hash: each made once, with its token *)
  mutable plain : bool;  (** no byte outside ASCII, and no NUL, met so far *)
  cursor : Decimal.cursor;  (** where a number ends *)
}

(* A byte of a comment or a string: ASCII without NUL, or it is noted. *)
let note t c = if c >= '\x80' || c = '\000' then t.plain <- false

(* ---- Lexing ---- *)

let[@inline] is_ident c =
  match c with 'a' .. 'z' | 'A' .. 'Z' | '0' .. '9' | '_' -> true | _ -> false

let[@inline] is_digit c = c >= '0' && c <= '9'

let keyword = function
  | "true" -> TRUE
  | "false" -> FALSE
  | "let" -> LET
  | "fn" -> FN
  | "for" -> FOR
  | "in" -> IN
  | "to" -> TO
  | "step" -> STEP
  | "if" -> IF
  | "then" -> THEN
  | "else" -> ELSE
  | "include" -> INCLUDE
  | "body" -> BODY
  | "material" -> MATERIAL
  | "and" -> AND
  | "or" -> OR
  | "not" -> NOT
  | _ -> IDENT

(* The identifier text.[s, e), made once for all its occurrences. *)
let rec same text s n x i =
  i >= n
  || (String.unsafe_get x i = String.unsafe_get text (s + i) && same text s n x (i + 1))

let rec find text s n = function
  | [] -> raise_notrace Not_found
  | ((x, _) as p) :: rest ->
      if String.length x = n && same text s n x 0 then p else find text s n rest

(* The word text.[s, e), and its token (a keyword's, or [IDENT]). *)
let intern t s e =
  let h = ref 0 in
  for i = s to e - 1 do
    h := (!h * 31) + Char.code (String.unsafe_get t.text i)
  done;
  let b = !h land (Array.length t.names - 1) in
  match find t.text s (e - s) t.names.(b) with
  | p -> p
  | exception Not_found ->
      let x = String.sub t.text s (e - s) in
      let p = (x, keyword x) in
      t.names.(b) <- p :: t.names.(b);
      p

(* White space and comments. *)
let rec blank t =
  if t.pos < t.len then
    match String.unsafe_get t.text t.pos with
    | ' ' | '\t' | '\r' ->
        t.pos <- t.pos + 1;
        blank t
    | '\n' ->
        t.pos <- t.pos + 1;
        t.line <- t.line + 1;
        t.bol <- t.pos;
        blank t
    | '/' when t.pos + 1 < t.len && t.text.[t.pos + 1] = '/' ->
        while t.pos < t.len && String.unsafe_get t.text t.pos <> '\n' do
          note t (String.unsafe_get t.text t.pos);
          t.pos <- t.pos + 1
        done;
        blank t
    | '/' when t.pos + 1 < t.len && t.text.[t.pos + 1] = '*' ->
        t.pos <- t.pos + 2;
        let rec close () =
          if t.pos + 1 >= t.len then raise Give_up
          else
            match String.unsafe_get t.text t.pos with
            | '*' when t.text.[t.pos + 1] = '/' -> t.pos <- t.pos + 2
            | '\n' ->
                t.pos <- t.pos + 1;
                t.line <- t.line + 1;
                t.bol <- t.pos;
                close ()
            | c ->
                note t c;
                t.pos <- t.pos + 1;
                close ()
        in
        close ();
        blank t
    | _ -> ()

(* [digit+ ('.' digit* )? exp? | '.' digit+ exp?], not followed by a letter. *)
let number t s =
  let x = Decimal.scan t.text s t.cursor in
  t.pos <- t.cursor.at;
  if t.pos < t.len && is_ident t.text.[t.pos] then raise Give_up;
  if not (Float.is_finite x) then raise Give_up;
  t.num <- x;
  NUMBER

let string t =
  let s = t.pos in
  let rec plain i =
    if i >= t.len then raise Give_up
    else
      match String.unsafe_get t.text i with
      | '"' -> i
      | '\n' | '\\' -> raise Exit
      | c ->
          note t c;
          plain (i + 1)
  in
  match plain s with
  | e ->
      t.str <- String.sub t.text s (e - s);
      t.pos <- e + 1;
      STRING
  | exception Exit ->
      let b = Buffer.create 16 in
      let rec go i =
        if i >= t.len then raise Give_up
        else
          match String.unsafe_get t.text i with
          | '"' -> i + 1
          | '\n' -> raise Give_up
          | '\\' when i + 1 < t.len && (t.text.[i + 1] = '"' || t.text.[i + 1] = '\\') ->
              Buffer.add_char b t.text.[i + 1];
              go (i + 2)
          | '\\' -> raise Give_up
          | c ->
              note t c;
              Buffer.add_char b c;
              go (i + 1)
      in
      t.pos <- go s;
      t.str <- Buffer.contents b;
      STRING

(* A token of one character, or of two when the second is [next]. *)
let one t s tok =
  t.pos <- s + 1;
  tok

let two t s next tok other =
  if s + 1 < t.len && t.text.[s + 1] = next then (
    t.pos <- s + 2;
    tok)
  else one t s other

let lex t =
  let s = t.pos in
  if s >= t.len then EOF
  else
    match String.unsafe_get t.text s with
    | 'a' .. 'z' | 'A' .. 'Z' | '_' ->
        let e = ref (s + 1) in
        while !e < t.len && is_ident (String.unsafe_get t.text !e) do
          incr e
        done;
        t.pos <- !e;
        let x, k = intern t s !e in
        if k = IDENT then t.ident <- x;
        k
    | '0' .. '9' -> number t s
    | '.' when s + 1 < t.len && is_digit t.text.[s + 1] -> number t s
    | '"' ->
        t.pos <- s + 1;
        string t
    | '(' -> one t s LPAREN
    | ')' -> one t s RPAREN
    | '{' -> one t s LBRACE
    | '}' -> one t s RBRACE
    | '[' -> one t s LBRACKET
    | ']' -> one t s RBRACKET
    | ',' -> one t s COMMA
    | ':' -> one t s COLON
    | '.' -> one t s DOT
    | '=' -> two t s '=' EQ ASSIGN
    | '<' -> two t s '=' LE LT
    | '>' -> two t s '=' GE GT
    | '!' when s + 1 < t.len && t.text.[s + 1] = '=' -> two t s '=' NE NE
    | '+' -> one t s PLUS
    | '-' -> one t s MINUS
    | '*' -> one t s STAR
    | '/' -> one t s SLASH
    | '%' -> one t s PERCENT
    | '^' -> one t s CARET
    | _ -> raise Give_up

(* The next token; the one it replaces ends where the last one read ends. *)
let advance t =
  t.eline <- t.tline;
  t.ecol <- t.tend;
  blank t;
  t.tline <- t.line;
  t.tcol <- t.pos - t.bol + 1;
  t.tok <- lex t;
  t.tend <- t.pos - t.bol + 1

(* ---- Locations ---- *)

(* From a start to the end of the last token read. *)
let loc t line col : Loc.t =
  { file = t.file; line; col; end_line = t.eline; end_col = t.ecol }

let here t : Loc.t =
  { file = t.file; line = t.tline; col = t.tcol; end_line = t.tline; end_col = t.tend }

let expect t tok = if t.tok = tok then advance t else raise Give_up

let name t =
  if t.tok <> IDENT then raise Give_up;
  let n = { id = t.ident; nloc = here t } in
  advance t;
  n

let mk t line col e = { e; loc = loc t line col }
let from t (a : expr) e = { e; loc = loc t a.loc.line a.loc.col }

(* [( x, x, … )] or [()], each [x] read by [one]. *)
let parenthesized t one =
  expect t LPAREN;
  if t.tok = RPAREN then (
    advance t;
    [])
  else
    let rec more acc =
      let x = one t in
      match t.tok with
      | COMMA ->
          advance t;
          more (x :: acc)
      | RPAREN ->
          advance t;
          List.rev (x :: acc)
      | _ -> raise Give_up
    in
    more []

(* ---- Expressions, loosest first ---- *)

let rec expr t =
  if t.tok = IF then (
    let l = t.tline and c = t.tcol in
    advance t;
    let cond = expr t in
    expect t THEN;
    let a = expr t in
    expect t ELSE;
    let b = expr t in
    mk t l c (If (cond, a, b)))
  else if t.tok = NOT || t.tok = MINUS then or_expr t
  else
    (* Most often an operand alone: read without going down the levels one by one. *)
    let a = postfix t in
    match t.tok with
    | CARET | STAR | SLASH | PERCENT | PLUS | MINUS | EQ | NE | LT | LE | GT | GE | AND
    | OR ->
        or_more t (and_more t (cmp_more t (add_more t (mul_more t (pow_more t a)))))
    | _ -> a

(* Each level of the precedence, then the operators of that level that follow (functions
   of [t] of their own: a local function would be a closure made at every expression). *)
and or_expr t = or_more t (and_expr t)

and or_more t a =
  if t.tok = OR then (
    advance t;
    let b = and_expr t in
    or_more t (from t a (Binop (Or, a, b))))
  else a

and and_expr t = and_more t (not_expr t)

and and_more t a =
  if t.tok = AND then (
    advance t;
    let b = not_expr t in
    and_more t (from t a (Binop (And, a, b))))
  else a

and not_expr t =
  if t.tok = NOT then (
    let l = t.tline and c = t.tcol in
    advance t;
    let a = not_expr t in
    mk t l c (Unop (Not, a)))
  else cmp_expr t

and cmp_expr t = cmp_more t (add_expr t)

and cmp_more t a =
  let op =
    match t.tok with
    | EQ -> Some Eq
    | NE -> Some Ne
    | LT -> Some Lt
    | LE -> Some Le
    | GT -> Some Gt
    | GE -> Some Ge
    | _ -> None
  in
  match op with
  | None -> a
  | Some op -> (
      advance t;
      let b = add_expr t in
      match t.tok with
      | EQ | NE | LT | LE | GT | GE -> raise Give_up (* comparisons do not chain *)
      | _ -> from t a (Binop (op, a, b)))

and add_expr t = add_more t (mul_expr t)

and add_more t a =
  match t.tok with
  | PLUS | MINUS ->
      let op = if t.tok = PLUS then Add else Sub in
      advance t;
      let b = mul_expr t in
      add_more t (from t a (Binop (op, a, b)))
  | _ -> a

and mul_expr t = mul_more t (unary t)

and mul_more t a =
  match t.tok with
  | STAR | SLASH | PERCENT ->
      let op = match t.tok with STAR -> Mul | SLASH -> Div | _ -> Mod in
      advance t;
      let b = unary t in
      mul_more t (from t a (Binop (op, a, b)))
  | _ -> a

and unary t =
  if t.tok = MINUS then (
    let l = t.tline and c = t.tcol in
    advance t;
    let a = unary t in
    mk t l c (Unop (Neg, a)))
  else pow_more t (postfix t)

and pow_more t a =
  if t.tok = CARET then (
    advance t;
    let b = unary t in
    from t a (Binop (Pow, a, b)))
  else a

and postfix t = postfix_more t (atom t)

and postfix_more t a =
  match t.tok with
  | DOT ->
      advance t;
      let f = name t in
      postfix_more t (from t a (Dot (a, f)))
  | LBRACKET ->
      advance t;
      let i = expr t in
      expect t RBRACKET;
      postfix_more t (from t a (Index (a, i)))
  | _ -> a

and atom t =
  let l = t.tline and c = t.tcol in
  match t.tok with
  | NUMBER ->
      let x = t.num in
      advance t;
      mk t l c (Num x)
  | STRING ->
      let s = t.str in
      advance t;
      mk t l c (Str s)
  | TRUE | FALSE ->
      let b = t.tok = TRUE in
      advance t;
      mk t l c (Bool b)
  | IDENT ->
      let f = name t in
      if t.tok = LPAREN then
        let a = args t in
        mk t l c (Call (f, a))
      else { e = Var f.id; loc = f.nloc }
  | LPAREN -> (
      advance t;
      let a = expr t in
      match t.tok with
      | RPAREN ->
          advance t;
          { a with loc = loc t l c }
      | COMMA -> (
          advance t;
          let b = expr t in
          match t.tok with
          | RPAREN ->
              advance t;
              mk t l c (Pair (a, b))
          | COMMA ->
              advance t;
              let z = expr t in
              expect t RPAREN;
              mk t l c (Vec (a, b, z))
          | _ -> raise Give_up)
      | _ -> raise Give_up)
  | MATERIAL ->
      advance t;
      expect t LBRACE;
      let its = items t in
      expect t RBRACE;
      mk t l c (Material its)
  | LBRACKET ->
      advance t;
      let rec more acc =
        if t.tok = RBRACKET then (
          advance t;
          List.rev acc)
        else
          let x = expr t in
          match t.tok with
          | COMMA ->
              advance t;
              more (x :: acc)
          | RBRACKET ->
              advance t;
              List.rev (x :: acc)
          | _ -> raise Give_up
      in
      let es = more [] in
      mk t l c (List es)
  | _ -> raise Give_up

and args t = parenthesized t expr

(* ---- Statements and blocks ---- *)

and items t = items_more t []

and items_more t acc =
  if t.tok = RBRACE then List.rev acc
  else
    let i = item t in
    if t.tok = COMMA then advance t;
    items_more t (i :: acc)

and item t =
  match t.tok with
  | IDENT ->
      let n = name t in
      if t.tok = COLON then (
        advance t;
        Field (n, expr t))
      else Stmt (named t n)
  | MATERIAL | STEP ->
      let n = { id = (if t.tok = STEP then "step" else "material"); nloc = here t } in
      advance t;
      expect t COLON;
      Field (n, expr t)
  | _ -> Stmt (stmt t)

(* A statement that starts with a name: a block, or a macro call. *)
and named t (k : name) =
  match t.tok with
  | LBRACE ->
      advance t;
      let its = items t in
      expect t RBRACE;
      { s = Block (k, its); sloc = loc t k.nloc.line k.nloc.col }
  | LPAREN ->
      let a = args t in
      { s = Call_stmt (k, a); sloc = loc t k.nloc.line k.nloc.col }
  | _ -> raise Give_up

and body t =
  expect t LBRACE;
  let rec more acc =
    if t.tok = RBRACE then (
      advance t;
      List.rev acc)
    else more (stmt t :: acc)
  in
  more []

and if_stmt t =
  let l = t.tline and c = t.tcol in
  expect t IF;
  let cond = expr t in
  let th = body t in
  let el =
    if t.tok = ELSE then (
      advance t;
      match t.tok with LBRACE -> body t | IF -> [ if_stmt t ] | _ -> raise Give_up)
    else []
  in
  { s = If_stmt (cond, th, el); sloc = loc t l c }

and stmt t =
  let l = t.tline and c = t.tcol in
  let st s = { s; sloc = loc t l c } in
  match t.tok with
  | LET ->
      advance t;
      let x = name t in
      expect t ASSIGN;
      let e = expr t in
      st (Let (x, e))
  | FN -> (
      advance t;
      let f = name t in
      let ps = params t in
      match t.tok with
      | ASSIGN ->
          advance t;
          let e = expr t in
          st (Fn (f, ps, e))
      | LBRACE ->
          let b = body t in
          st (Macro (f, ps, b))
      | _ -> raise Give_up)
  | FOR ->
      advance t;
      let x = name t in
      expect t IN;
      let a = expr t in
      if t.tok = LBRACE then st (For_each (x, a, body t))
      else (
        expect t TO;
        let b = expr t in
        let s =
          if t.tok = STEP then (
            advance t;
            Some (expr t))
          else None
        in
        let b2 = body t in
        st (For (x, a, b, s, b2)))
  | IF -> if_stmt t
  | INCLUDE ->
      advance t;
      if t.tok <> STRING then raise Give_up;
      let p = t.str and ploc = here t in
      advance t;
      st (Include (p, ploc))
  | BODY ->
      advance t;
      let n = name t in
      expect t LBRACE;
      let its = items t in
      expect t RBRACE;
      st (Body (n, its))
  | IDENT -> named t (name t)
  | _ -> raise Give_up

and params t = parenthesized t name

let start ~file text =
  let t =
    {
      text;
      len = String.length text;
      file;
      pos = 0;
      line = 1;
      bol = 0;
      tok = EOF;
      tline = 1;
      tcol = 1;
      tend = 1;
      ident = "";
      num = 0.;
      str = "";
      eline = 1;
      ecol = 1;
      names = Array.make 1024 [];
      plain = true;
      cursor = { at = 0 };
    }
  in
  advance t;
  t

let next t = if t.tok = EOF then None else Some (stmt t)
let plain t = t.plain

let program ~file text =
  match
    let t = start ~file text in
    let rec more acc =
      match next t with None -> List.rev acc | Some s -> more (s :: acc)
    in
    let stmts = more [] in
    (stmts, t.plain)
  with
  | r -> Some r
  | exception (Give_up | Failure _ | Invalid_argument _ | Stack_overflow) -> None
