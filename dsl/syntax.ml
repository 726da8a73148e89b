module I = Parser.MenhirInterpreter

let not_text file text =
  if String.contains text '\000' then
    Some (Error.file_error file "this is not a text file (it contains NUL bytes); a scene is UTF-8 text")
  else if not (String.is_valid_utf_8 text) then
    Some (Error.file_error file "this is not UTF-8 text; a scene is UTF-8 text")
  else None

(* The offending token as written (shortened), or "end of file". *)
let what text tok (s : Lexing.position) (e : Lexing.position) =
  match tok with
  | Parser.EOF -> "end of file"
  | _ ->
      let n = e.pos_cnum - s.pos_cnum in
      if s.pos_cnum < 0 || n <= 0 || s.pos_cnum + n > String.length text then Lexer.describe tok
      else if n > 30 then "`" ^ String.sub text s.pos_cnum 27 ^ "...`"
      else "`" ^ String.sub text s.pos_cnum n ^ "`"

let parse ~file text =
  match not_text file text with
  | Some e -> Error e
  | None -> (
      let lexbuf = Lexing.from_string text in
      Lexing.set_filename lexbuf file;
      let last = ref (Parser.EOF, lexbuf.lex_start_p, lexbuf.lex_curr_p) in
      let rec loop checkpoint =
        match checkpoint with
        | I.InputNeeded _ ->
            let tok = Lexer.token lexbuf in
            last := (tok, lexbuf.lex_start_p, lexbuf.lex_curr_p);
            loop (I.offer checkpoint !last)
        | I.Shifting _ | I.AboutToReduce _ -> loop (I.resume checkpoint)
        | I.HandlingError env ->
            let state = I.current_state_number env in
            let msg = try String.trim (Parser_messages.message state) with Not_found -> "this is not valid here" in
            let tok, s, e = !last in
            Error (Error.make ~source:text (Loc.of_positions s e) (Printf.sprintf "unexpected %s: %s" (what text tok s e) msg))
        | I.Accepted v -> Ok v
        | I.Rejected -> Error (Error.make ~source:text (Loc.whole_file file) "syntax error")
      in
      try loop (Parser.Incremental.program lexbuf.lex_curr_p)
      with Lexer.Lex_error (loc, msg) -> Error (Error.make ~source:text loc msg))
