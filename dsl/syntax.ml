module I = Parser.MenhirInterpreter

let not_text file text =
  if String.contains text '\000' then
    Some
      (Error.file_error file
         "this is not a text file (it contains NUL bytes); a scene is UTF-8 text")
  else if not (String.is_valid_utf_8 text) then
    Some (Error.file_error file "this is not UTF-8 text; a scene is UTF-8 text")
  else None

let bom = "\xEF\xBB\xBF"

let without_bom text =
  if String.starts_with ~prefix:bom text then String.sub text 3 (String.length text - 3)
  else text

(* The offending token as written (shortened), or "end of file". *)
let what text tok (s : Lexing.position) (e : Lexing.position) =
  match tok with
  | Parser.EOF -> "end of file"
  | _ ->
      let n = e.pos_cnum - s.pos_cnum in
      if s.pos_cnum < 0 || n <= 0 || s.pos_cnum + n > String.length text then
        Lexer.describe tok
      else if n > 30 then "`" ^ String.sub text s.pos_cnum 27 ^ "...`"
      else "`" ^ String.sub text s.pos_cnum n ^ "`"

(* What a `{` opens, named from the tokens before it: `sphere {`, `body b {`,
   `material {`, `else {`, or the `for`, `if` or `fn` whose statement it belongs to. *)
let opener ~prev ~prev2 ~keyword =
  match (prev2, prev) with
  | Parser.BODY, Parser.IDENT x -> Printf.sprintf "body %s {" x
  | _, Parser.IDENT x -> x ^ " {"
  | _, Parser.MATERIAL -> "material {"
  | _, Parser.ELSE -> "else {"
  | _ -> ( match keyword with Some k -> k ^ " … {" | None -> "{")

type bracket = { label : string; at : Lexing.position; stop : Lexing.position }

(* The Menhir parser, on text: the program, or its first error. *)
let grammar ~file text =
  let lexbuf = Lexing.from_string text in
  Lexing.set_filename lexbuf file;
  let last = ref (Parser.EOF, lexbuf.lex_start_p, lexbuf.lex_curr_p) in
  (* The brackets open so far, innermost first, so that a missing `}` or `)` is
         reported where its block was opened rather than at the end of the file. *)
  let open_ = ref []
  and prev = ref Parser.EOF
  and prev2 = ref Parser.EOF
  and keyword = ref [ None ] in
  let track tok s e =
    (match tok with
    | Parser.LBRACE ->
        let label = opener ~prev:!prev ~prev2:!prev2 ~keyword:(List.hd !keyword) in
        open_ := { label; at = s; stop = e } :: !open_;
        keyword := None :: !keyword
    | Parser.LPAREN -> open_ := { label = "("; at = s; stop = e } :: !open_
    | Parser.LBRACKET -> open_ := { label = "["; at = s; stop = e } :: !open_
    | Parser.RBRACE | Parser.RPAREN | Parser.RBRACKET -> (
        (match (tok, !keyword) with
        | Parser.RBRACE, _ :: (_ :: _ as rest) -> keyword := rest
        | _ -> ());
        match !open_ with _ :: rest -> open_ := rest | [] -> ())
    | Parser.FOR -> keyword := Some "for" :: List.tl !keyword
    | Parser.IF -> keyword := Some "if" :: List.tl !keyword
    | Parser.FN -> keyword := Some "fn" :: List.tl !keyword
    | _ -> ());
    prev2 := !prev;
    prev := tok
  in
  let rec loop checkpoint =
    match checkpoint with
    | I.InputNeeded _ ->
        let tok = Lexer.token lexbuf in
        last := (tok, lexbuf.lex_start_p, lexbuf.lex_curr_p);
        track tok lexbuf.lex_start_p lexbuf.lex_curr_p;
        loop (I.offer checkpoint !last)
    | I.Shifting _ | I.AboutToReduce _ -> loop (I.resume checkpoint)
    | I.HandlingError env -> (
        let state = I.current_state_number env in
        let msg =
          try String.trim (Parser_messages.message state)
          with Not_found -> "this is not valid here"
        in
        let tok, s, e = !last in
        match (tok, !open_) with
        | Parser.EOF, b :: _ ->
            let closer = match b.label with "(" -> ")" | "[" -> "]" | _ -> "}" in
            let where =
              Printf.sprintf "%d:%d" b.at.pos_lnum (b.at.pos_cnum - b.at.pos_bol + 1)
            in
            Error
              (Error.make ~source:text
                 (Loc.of_positions b.at b.stop)
                 (Printf.sprintf
                    "the %s opened at %s is not closed: a `%s` is missing before the end \
                     of the file"
                    b.label where closer))
        | _ ->
            (* A habit from another language, or a keyword where a name was meant. *)
            let msg =
              match (tok, Lexer.keyword_name tok, !prev2) with
              | _, Some k, (Parser.LET | Parser.FN | Parser.FOR | Parser.BODY) ->
                  Hints.keyword_as_name k
              | Parser.LT, _, _ -> msg ^ " " ^ Hints.angle_vector
              | Parser.STEP, Some k, _ -> msg ^ " " ^ Hints.keyword_as_name k
              | _ -> msg
            in
            Error
              (Error.make ~source:text (Loc.of_positions s e)
                 (Printf.sprintf "unexpected %s: %s" (what text tok s e) msg)))
    | I.Accepted v -> Ok v
    | I.Rejected -> Error (Error.make ~source:text (Loc.whole_file file) "syntax error")
  in
  try loop (Parser.Incremental.program lexbuf.lex_curr_p)
  with Lexer.Lex_error (loc, msg) -> Error (Error.make ~source:text loc msg)

(* The text is read by [Reader]; where it gives up, by the Menhir parser, which says what
   is wrong. *)
let parse ~file text =
  match Reader.program ~file text with
  | Some (stmts, true) -> Ok stmts
  | Some (stmts, false) -> (
      match not_text file text with Some e -> Error e | None -> Ok stmts)
  | None -> (
      match not_text file text with Some e -> Error e | None -> grammar ~file text)
