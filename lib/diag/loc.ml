type t = { file : string; line : int; col : int; end_line : int; end_col : int }

let of_positions (s : Lexing.position) (e : Lexing.position) =
  {
    file = s.pos_fname;
    line = s.pos_lnum;
    col = s.pos_cnum - s.pos_bol + 1;
    end_line = e.pos_lnum;
    end_col = e.pos_cnum - e.pos_bol + 1;
  }

let whole_file file = { file; line = 1; col = 1; end_line = 1; end_col = 1 }

let relative_to file p =
  let dir = Filename.dirname file in
  if Filename.is_relative p && dir <> "." then Filename.concat dir p else p
