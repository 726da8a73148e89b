{
open Parser

exception Lex_error of Loc.t * string

let error lexbuf msg =
  raise (Lex_error (Loc.of_positions (Lexing.lexeme_start_p lexbuf) (Lexing.lexeme_end_p lexbuf), msg))

let span (p : Lexing.position) n = Loc.of_positions p { p with pos_cnum = p.pos_cnum + n }

let keywords =
  [ ("true", TRUE); ("false", FALSE); ("let", LET); ("fn", FN); ("for", FOR); ("in", IN);
    ("to", TO); ("step", STEP); ("if", IF); ("then", THEN); ("else", ELSE);
    ("include", INCLUDE); ("body", BODY); ("material", MATERIAL); ("and", AND); ("or", OR);
    ("not", NOT) ]

let keyword_name tok = List.find_map (fun (k, t) -> if t = tok then Some k else None) keywords

let describe = function
  | NUMBER n -> Printf.sprintf "the number %g" n
  | STRING s -> Printf.sprintf "the string %S" s
  | IDENT x -> Printf.sprintf "`%s`" x
  | TRUE -> "`true`" | FALSE -> "`false`" | LET -> "`let`" | FN -> "`fn`" | FOR -> "`for`"
  | IN -> "`in`" | TO -> "`to`" | STEP -> "`step`" | IF -> "`if`" | THEN -> "`then`"
  | ELSE -> "`else`" | INCLUDE -> "`include`" | BODY -> "`body`" | MATERIAL -> "`material`"
  | AND -> "`and`" | OR -> "`or`" | NOT -> "`not`" | LPAREN -> "`(`" | RPAREN -> "`)`"
  | LBRACE -> "`{`" | RBRACE -> "`}`" | LBRACKET -> "`[`" | RBRACKET -> "`]`" | COMMA -> "`,`" | COLON -> "`:`" | DOT -> "`.`"
  | ASSIGN -> "`=`" | EQ -> "`==`" | NE -> "`!=`" | LT -> "`<`" | LE -> "`<=`" | GT -> "`>`"
  | GE -> "`>=`" | PLUS -> "`+`" | MINUS -> "`-`" | STAR -> "`*`" | SLASH -> "`/`"
  | PERCENT -> "`%`" | CARET -> "`^`" | EOF -> "the end of the file"
}

let digit = ['0'-'9']
let exp = ['e' 'E'] ['+' '-']? digit+
let number = digit+ ('.' digit*)? exp? | '.' digit+ exp?
let ident = ['A'-'Z' 'a'-'z' '_'] ['A'-'Z' 'a'-'z' '0'-'9' '_']*

rule token = parse
  | [' ' '\t' '\r']+ { token lexbuf }
  | '\n' { Lexing.new_line lexbuf; token lexbuf }
  | "//" [^ '\n']* { token lexbuf }
  | "/*" { comment (Lexing.lexeme_start_p lexbuf) lexbuf; token lexbuf }
  | number as n
      { let v = float_of_string n in
        if Float.is_finite v then NUMBER v
        else error lexbuf (Printf.sprintf "the number %s is too large (at most about 1.8e308)" n) }
  | number ident
      { error lexbuf (Printf.sprintf "`%s` is not a number: a name cannot start with a digit" (Lexing.lexeme lexbuf)) }
  | ident as x { match List.assoc_opt x keywords with Some k -> k | None -> IDENT x }
  | '"'
      { let start = Lexing.lexeme_start_p lexbuf in
        let s = string start (Buffer.create 16) lexbuf in
        (* the sub-lexer moved the token's start: put it back on the opening quote *)
        lexbuf.lex_start_p <- start;
        STRING s }
  | '(' { LPAREN } | ')' { RPAREN } | '{' { LBRACE } | '}' { RBRACE }
  | '[' { LBRACKET } | ']' { RBRACKET }
  | ',' { COMMA } | ':' { COLON } | '.' { DOT }
  | "==" { EQ } | "!=" { NE } | "<=" { LE } | ">=" { GE } | '<' { LT } | '>' { GT }
  | '=' { ASSIGN }
  | '+' { PLUS } | '-' { MINUS } | '*' { STAR } | '/' { SLASH } | '%' { PERCENT } | '^' { CARET }
  | "&&" { error lexbuf "`&&` is not an operator; write `and`" }
  | "||" { error lexbuf "`||` is not an operator; write `or`" }
  | '!' { error lexbuf "`!` is not an operator; write `not`" }
  | '#' (ident as d) { error lexbuf (Hints.directive d) }
  | ';' { error lexbuf "`;` is not used in .rts scripts: separate fields with commas or new lines" }
  | eof { EOF }
  | "\xE2\x80\x9C" | "\xE2\x80\x9D" | "\xE2\x80\x98" | "\xE2\x80\x99" as q
      { error lexbuf (Printf.sprintf "a typographic quote %s; write \" (strings are in straight double quotes: \"like this\")" q) }
  | ['\x80'-'\xff']+ { error lexbuf "non-ASCII characters are allowed only in comments and strings" }
  | _ as c { error lexbuf (Printf.sprintf "unexpected character `%s`" (Char.escaped c)) }

and comment start = parse
  | "*/" { () }
  | '\n' { Lexing.new_line lexbuf; comment start lexbuf }
  | eof { raise (Lex_error (span start 2, "this comment is not closed: `*/` is missing")) }
  | _ { comment start lexbuf }

and string start buf = parse
  | '"' { Buffer.contents buf }
  | "\\\"" { Buffer.add_char buf '"'; string start buf lexbuf }
  | "\\\\" { Buffer.add_char buf '\\'; string start buf lexbuf }
  | '\\' { error lexbuf "unknown escape in a string: only \\\" and \\\\ are allowed" }
  | '\n' | eof { raise (Lex_error (span start 1, "this string is not closed: `\"` is missing before the end of the line")) }
  | _ as c { Buffer.add_char buf c; string start buf lexbuf }
