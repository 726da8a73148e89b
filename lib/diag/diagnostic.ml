type kind = Error | Warning

type t = {
  kind : kind;
  file : string;
  line : int;
  col : int;
  end_col : int;
  message : string;
  source_line : string option;
  included_from : Loc.t list;
}

let nth_line text n =
  (* Line [n] (from 1) of [text], without its newline (or carriage return). *)
  let len = String.length text in
  let rec start i k =
    if k = n then Some i
    else
      match String.index_from_opt text i '\n' with
      | Some j when j + 1 <= len -> start (j + 1) (k + 1)
      | _ -> None
  in
  match start 0 1 with
  | None -> None
  | Some i ->
      let j = match String.index_from_opt text i '\n' with Some j -> j | None -> len in
      let j = if j > i && text.[j - 1] = '\r' then j - 1 else j in
      Some (String.sub text i (j - i))

let make ?(kind = Error) ?source (loc : Loc.t) message =
  let source_line = Option.bind source (fun s -> nth_line s loc.line) in
  let end_col =
    if loc.end_line = loc.line && loc.end_col > loc.col then loc.end_col
    else
      match source_line with
      | Some l when String.length l + 1 > loc.col -> String.length l + 1
      | _ -> loc.col + 1
  in
  {
    kind;
    file = loc.file;
    line = loc.line;
    col = loc.col;
    end_col;
    message;
    source_line;
    included_from = [];
  }

let warning ?source loc message = make ~kind:Warning ?source loc message

let file_error ?(kind = Error) file message =
  {
    kind;
    file;
    line = 0;
    col = 0;
    end_col = 0;
    message;
    source_line = None;
    included_from = [];
  }

let with_includes chain e =
  if e.included_from <> [] then e else { e with included_from = chain e.file }

let unreadable path =
  if not (Sys.file_exists path) then Some "no such file"
  else if Sys.is_directory path then Some "it is a directory"
  else
    match open_in_bin path with
    | ic ->
        close_in_noerr ic;
        None
    | exception Sys_error _ -> Some "it cannot be opened (permissions?)"

let cannot_read_because ~what ~written path r =
  if String.equal written path then
    Printf.sprintf "cannot read the %s \"%s\": %s" what written r
  else Printf.sprintf "cannot read the %s \"%s\": %s (looked for %s)" what written r path

let cannot_read ~what ~written path =
  Option.map (cannot_read_because ~what ~written path) (unreadable path)

(* Display width of the first [n] bytes of [s]: UTF-8 continuation bytes take no
   column, tabs are kept so the caret lines up under them. *)
let prefix s n =
  let b = Buffer.create n in
  String.iteri
    (fun i c ->
      if i < n then
        if c = '\t' then Buffer.add_char b '\t'
        else if Char.code c land 0xC0 <> 0x80 then Buffer.add_char b ' ')
    s;
  Buffer.contents b

let width s a b =
  let n = ref 0 in
  for i = a to min b (String.length s) - 1 do
    if Char.code s.[i] land 0xC0 <> 0x80 then incr n
  done;
  max 1 !n

let pp_chain ppf e =
  List.iter
    (fun (l : Loc.t) ->
      Format.fprintf ppf "  included from %s:%d:%d@." l.file l.line l.col)
    e.included_from

let rec pp ppf e =
  pp_diagnostic ppf e;
  pp_chain ppf e

and pp_diagnostic ppf e =
  let message =
    match e.kind with Error -> e.message | Warning -> "warning: " ^ e.message
  in
  let e = { e with message } in
  if e.line = 0 then Format.fprintf ppf "%s: %s@." e.file e.message
  else (
    Format.fprintf ppf "%s:%d:%d: %s@." e.file e.line e.col e.message;
    match e.source_line with
    | None -> ()
    | Some l when String.length l <= 160 ->
        let c0 = e.col - 1 in
        let caret = String.make (width l c0 (e.end_col - 1)) '^' in
        Format.fprintf ppf "%s@.%s%s@." l (prefix l c0) caret
    | Some l ->
        (* A very long line: about 60 bytes either side of the column, cut at UTF-8
           character boundaries and marked with "…". *)
        let n = String.length l in
        let rec back i =
          if i > 0 && i < n && Char.code l.[i] land 0xC0 = 0x80 then back (i - 1) else i
        in
        let c0 = max 0 (min (e.col - 1) n) in
        let a = back (max 0 (c0 - 60)) and b = back (min n (c0 + 60)) in
        let window = String.sub l a (b - a) in
        let lead = if a > 0 then "…" else "" and tail = if b < n then "…" else "" in
        let caret = String.make (width window (c0 - a) (min (e.end_col - 1) b - a)) '^' in
        Format.fprintf ppf "%s%s%s@.%s%s%s@." lead window tail
          (if a > 0 then " " else "")
          (prefix window (c0 - a))
          caret)

let to_string e = Format.asprintf "%a" pp e
