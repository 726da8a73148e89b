(* The documentation as a test. Every fenced block of README.md, CHANGES.md, doc/**/*.md
   and the READMEs of scenes/gallery/ and test/example-user/ is read by what its info
   string says it is (doc/README.md, "How the examples are checked", is the authors' side
   of this):

   - ```rts: a whole scene, which `lancer check` must accept with no warning (`rts warns`
     allows warnings); ```rts fragment: statements shown alone, checked after the two
     library includes, warnings allowed; ```rts fragment each: alternatives, each
     statement (from a line that is not indented to the next) checked alone as a fragment;
   - ```console: a transcript. Each `$ COMMAND` line (continued by a final `\`) is run by
     sh, and what it writes to stdout and stderr must be the lines under it; a line `...`
     stands for any number of lines, and `...` inside a line for any text. A command that
     fails ends its output with `[STATUS]`;
   - ```sh and ```bash: commands shown, not run: every option given to `lancer` or
     `lancer-mpi` must be one its command's --help lists, and every `make TARGET` a target
     of the Makefile;
   - a block with `file=NAME` is also written to NAME, for the blocks after it in the same
     page; a block with `from=PATH` must be an excerpt of PATH (its lines in order);
   - other languages (ocaml, dune, text, json, ply) are shown as they are; a fence without
     a language is refused.

   The blocks of one page run in order in one temporary directory, where `scenes` is the
   project's scenes/ and `lancer` is the lancer under test. Relative links and images
   must name files that exist, and a link's #anchor a heading of its page.

   Usage: docs_check LANCER [FILE.md ...], from the project's root; without files, every
   page above. *)

let failures = ref 0
let count_rts = ref 0
let count_commands = ref 0
let count_sh = ref 0
let count_links = ref 0

let fail ~file ~line fmt =
  Printf.ksprintf
    (fun m ->
      incr failures;
      Printf.printf "%s:%d: %s\n%!" file line m)
    fmt

let read_file p = In_channel.with_open_bin p In_channel.input_all
let write_file p s = Out_channel.with_open_bin p (fun oc -> output_string oc s)

let starts_with ~prefix s =
  String.length s >= String.length prefix
  && String.sub s 0 (String.length prefix) = prefix

let ends_with ~suffix s =
  let n = String.length s and k = String.length suffix in
  n >= k && String.sub s (n - k) k = suffix

let rec mkdir_p d =
  if not (Sys.file_exists d) then (
    mkdir_p (Filename.dirname d);
    Unix.mkdir d 0o755)

let rec rm_rf p =
  match (Unix.lstat p).st_kind with
  | Unix.S_DIR ->
      Array.iter (fun e -> rm_rf (Filename.concat p e)) (Sys.readdir p);
      Unix.rmdir p
  | _ -> Sys.remove p
  | exception Unix.Unix_error _ -> ()

(* [find_from s pos sub]: the first index at or after [pos] where [sub] occurs. *)
let find_from s pos sub =
  let n = String.length s and m = String.length sub in
  let rec go i =
    if i + m > n then None else if String.sub s i m = sub then Some i else go (i + 1)
  in
  go pos

let contains s sub = find_from s 0 sub <> None

(* [split_on s sep]: the pieces of [s] between occurrences of [sep]. *)
let split_on s sep =
  let m = String.length sep in
  let rec go pos acc =
    match find_from s pos sep with
    | Some k -> go (k + m) (String.sub s pos (k - pos) :: acc)
    | None -> List.rev (String.sub s pos (String.length s - pos) :: acc)
  in
  go 0 []

let absolute p = if Filename.is_relative p then Filename.concat (Sys.getcwd ()) p else p

let rstrip s =
  let n = ref (String.length s) in
  while !n > 0 && (s.[!n - 1] = ' ' || s.[!n - 1] = '\t' || s.[!n - 1] = '\r') do
    decr n
  done;
  String.sub s 0 !n

let lines_of s =
  let l = String.split_on_char '\n' s in
  match List.rev l with "" :: r -> List.rev r | _ -> l

(* ---- Markdown: fenced blocks ---------------------------------------------------------- *)

type block = {
  line : int;  (** the line of the opening fence *)
  lang : string;
  attrs : (string * string) list;  (** flag → "", key=value → value *)
  body : string list;
}

let indent_of s =
  let n = String.length s in
  let rec go i = if i < n && s.[i] = ' ' then go (i + 1) else i in
  go 0

(* Fences are ``` lines at any indentation (inside list items too); a block's lines lose
   the indentation of its opening fence. *)
let blocks_of ~file text =
  let lines = Array.of_list (lines_of text) in
  let n = Array.length lines in
  let rec scan i acc =
    if i >= n then List.rev acc
    else
      let l = lines.(i) in
      let ind = indent_of l in
      let t = String.sub l ind (String.length l - ind) in
      if starts_with ~prefix:"```" t then
        let info = String.trim (String.sub t 3 (String.length t - 3)) in
        let words = String.split_on_char ' ' info |> List.filter (( <> ) "") in
        let lang, rest = match words with [] -> ("", []) | w :: r -> (w, r) in
        let attrs =
          List.map
            (fun w ->
              match String.index_opt w '=' with
              | Some k ->
                  (String.sub w 0 k, String.sub w (k + 1) (String.length w - k - 1))
              | None -> (w, ""))
            rest
        in
        let rec body j acc =
          if j >= n then (
            fail ~file ~line:(i + 1) "this block is never closed";
            (j, List.rev acc))
          else
            let b = lines.(j) in
            let bi = indent_of b in
            if String.trim b = "```" then (j + 1, List.rev acc)
            else
              let cut = min bi ind in
              body (j + 1) (String.sub b cut (String.length b - cut) :: acc)
        in
        let next, body = body (i + 1) [] in
        scan next ({ line = i + 1; lang; attrs; body } :: acc)
      else scan (i + 1) acc
  in
  scan 0 []

(* The text outside fenced blocks, line by line (None inside a block). *)
let prose_lines text =
  let inside = ref false in
  List.map
    (fun l ->
      let t = String.trim l in
      if starts_with ~prefix:"```" t then (
        inside := not !inside;
        None)
      else if !inside then None
      else Some l)
    (lines_of text)

(* ---- Running commands ----------------------------------------------------------------- *)

type env = { root : string; bindir : string }

(* [run env ~dir cmd]: sh -c cmd in dir, stdin from /dev/null, stdout and stderr into one
   pipe: (status, output). *)
let run env ~dir cmd =
  let path =
    env.bindir ^ ":" ^ Option.value (Sys.getenv_opt "PATH") ~default:"/usr/bin:/bin"
  in
  let environment =
    Unix.environment () |> Array.to_list
    |> List.filter (fun kv ->
           not
             (starts_with ~prefix:"PATH=" kv
             || starts_with ~prefix:"LANCER_" kv
             || starts_with ~prefix:"OCAMLRUNPARAM=" kv))
    |> List.cons ("PATH=" ^ path)
    (* Progress lines come with time (a line every few seconds when stderr is not a
       terminal): a transcript shows what a command prints whatever its speed. *)
    |> List.cons "LANCER_PROGRESS_INTERVAL=off"
    |> Array.of_list
  in
  let rd, wr = Unix.pipe ~cloexec:true () in
  let null = Unix.openfile "/dev/null" [ Unix.O_RDONLY; Unix.O_CLOEXEC ] 0 in
  let cwd = Sys.getcwd () in
  Sys.chdir dir;
  let pid =
    Fun.protect
      ~finally:(fun () -> Sys.chdir cwd)
      (fun () ->
        Unix.create_process_env "timeout"
          [| "timeout"; "300"; "sh"; "-c"; cmd |]
          environment null wr wr)
  in
  Unix.close wr;
  Unix.close null;
  let ic = Unix.in_channel_of_descr rd in
  let out = In_channel.input_all ic in
  close_in ic;
  let status =
    match snd (Unix.waitpid [] pid) with
    | Unix.WEXITED n -> n
    | Unix.WSIGNALED n | Unix.WSTOPPED n -> 128 + n
  in
  (status, out)

(* ---- ```rts ----------------------------------------------------------------------------- *)

let has_warning out = List.exists (fun l -> contains l "warning:") (lines_of out)

(* A block's statements one by one, for ```rts fragment each: a statement starts at a line
   that is not indented (nor blank, a comment or a closing brace) and runs to the next;
   each comes with the line it starts at in the block. *)
let statements body =
  let starts l =
    l <> "" && l.[0] <> ' ' && l.[0] <> '}' && not (starts_with ~prefix:"//" l)
  in
  let rec go i cur acc = function
    | [] ->
        List.rev (match cur with Some (k, ls) -> (k, List.rev ls) :: acc | None -> acc)
    | l :: rest when starts l ->
        let acc =
          match cur with Some (k, ls) -> (k, List.rev ls) :: acc | None -> acc
        in
        go (i + 1) (Some (i, [ l ])) acc rest
    | l :: rest -> (
        match cur with
        | Some (k, ls) -> go (i + 1) (Some (k, l :: ls)) acc rest
        | None -> go (i + 1) None acc rest)
  in
  go 0 None [] body

let check_rts env ~file ~dir b =
  incr count_rts;
  let fragment = List.mem_assoc "fragment" b.attrs in
  let check ~line ~what body =
    let text = String.concat "\n" body ^ "\n" in
    let name =
      match List.assoc_opt "file" b.attrs with
      | Some n when not fragment -> n
      | _ ->
          let n = Printf.sprintf ".block-%d.rts" line in
          write_file (Filename.concat dir n)
            (if fragment then
               "include \"lancer/materials.rts\"\ninclude \"lancer/colors.rts\"\n" ^ text
             else text);
          n
    in
    let status, out = run env ~dir ("lancer check " ^ Filename.quote name) in
    if status <> 0 then
      fail ~file ~line "lancer check refuses this %s (exit %d):\n%s" what status out
    else if (not fragment) && (not (List.mem_assoc "warns" b.attrs)) && has_warning out
    then
      fail ~file ~line
        "lancer check warns about this scene (mark it `rts warns` if that is its point):\n\
         %s"
        out
  in
  if fragment && List.mem_assoc "each" b.attrs then
    List.iter
      (fun (k, body) ->
        check
          ~line:(b.line + 1 + k)
          ~what:"statement (alone, after the two library includes)" body)
      (statements b.body)
  else
    check ~line:b.line
      ~what:(if fragment then "fragment (after the two library includes)" else "scene")
      b.body

(* ---- ```console --------------------------------------------------------------------------- *)

(* [glob pat s]: [pat] with "..." matching any text. *)
let glob pat s =
  let parts = split_on pat "..." in
  match parts with
  | [ only ] -> only = s
  | first :: rest ->
      starts_with ~prefix:first s
      &&
      let rec go pos = function
        | [] -> true
        | [ last ] ->
            String.length s - String.length last >= pos && ends_with ~suffix:last s
        | p :: ps -> (
            match find_from s pos p with
            | Some k -> go (k + String.length p) ps
            | None -> false)
      in
      go (String.length first) rest
  | [] -> s = ""

(* Expected lines against actual lines; a line "..." takes any number of lines. *)
let rec matches exp act =
  match (exp, act) with
  | [], [] -> true
  | "..." :: e, _ -> (
      matches e act || match act with [] -> false | _ :: a -> matches exp a)
  | [], _ :: _ -> false
  | _ :: _, [] -> false
  | e :: es, a :: as_ -> glob e a && matches es as_

type command = { cline : int; cmd : string; expected : string list }

let commands_of ~file b =
  let rec go i lines acc =
    match lines with
    | [] -> List.rev acc
    | l :: rest when starts_with ~prefix:"$ " l ->
        let rec continued cmd k rest =
          if ends_with ~suffix:"\\" cmd then
            match rest with
            | c :: r ->
                continued (String.sub cmd 0 (String.length cmd - 1) ^ "\n" ^ c) (k + 1) r
            | [] -> (cmd, k, [])
          else (cmd, k, rest)
        in
        let cmd, k, rest = continued (String.sub l 2 (String.length l - 2)) 0 rest in
        let rec output acc = function
          | o :: r when not (starts_with ~prefix:"$ " o) -> output (rstrip o :: acc) r
          | r -> (List.rev acc, r)
        in
        let expected, rest' = output [] rest in
        let c = { cline = b.line + i + 1; cmd; expected } in
        go (i + 1 + k + List.length expected) rest' (c :: acc)
    | l :: rest ->
        if String.trim l <> "" then
          fail ~file
            ~line:(b.line + i + 1)
            "a transcript's lines start with a command (`$ lancer …`): %S" l;
        go (i + 1) rest acc
  in
  go 0 b.body []

let check_console env ~file ~dir b =
  List.iter
    (fun c ->
      incr count_commands;
      let status, out = run env ~dir c.cmd in
      let actual =
        List.map rstrip (lines_of out)
        @ if status <> 0 then [ Printf.sprintf "[%d]" status ] else []
      in
      if not (matches c.expected actual) then
        fail ~file ~line:c.cline
          "`%s` does not print what the page says.\n--- the page:\n%s\n--- lancer:\n%s"
          c.cmd
          (String.concat "\n" c.expected)
          (String.concat "\n" actual))
    (commands_of ~file b)

(* ---- ```sh: options and make targets --------------------------------------------------- *)

(* Shell words, quotes removed; an unquoted # starts a comment. *)
let words_of s =
  let b = Buffer.create 16
  and acc = ref []
  and quote = ref None
  and in_word = ref false in
  let flush () =
    if !in_word then acc := Buffer.contents b :: !acc;
    Buffer.clear b;
    in_word := false
  in
  (try
     String.iter
       (fun ch ->
         match (!quote, ch) with
         | Some q, c when c = q -> quote := None
         | Some _, c -> Buffer.add_char b c
         | None, ('"' | '\'') ->
             quote := Some ch;
             in_word := true
         | None, '#' when not !in_word -> raise Exit
         | None, (' ' | '\t' | '\n') -> flush ()
         | None, c ->
             Buffer.add_char b c;
             in_word := true)
       s
   with Exit -> ());
  flush ();
  List.rev !acc

let help_cache = Hashtbl.create 8

(* The options a command's --help lists: every --long and lone -x. *)
let options_of env sub =
  match Hashtbl.find_opt help_cache sub with
  | Some o -> o
  | None ->
      let status, out =
        run env ~dir:env.root ("lancer " ^ String.concat " " sub ^ " --help=plain")
      in
      let opts =
        if status <> 0 then None
        else
          let set = Hashtbl.create 32 in
          let n = String.length out in
          let is_name c = (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c = '-' in
          let is_letter c = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') in
          for i = 0 to n - 2 do
            let before = if i = 0 then ' ' else out.[i - 1] in
            if
              out.[i] = '-'
              && (before = ' ' || before = ',' || before = '(' || before = '[')
            then
              if out.[i + 1] = '-' then (
                let j = ref (i + 2) in
                while !j < n && is_name out.[!j] do
                  incr j
                done;
                Hashtbl.replace set (String.sub out i (!j - i)) ())
              else if is_letter out.[i + 1] && (i + 2 >= n || not (is_letter out.[i + 2]))
              then Hashtbl.replace set (String.sub out i 2) ()
          done;
          Some set
      in
      Hashtbl.add help_cache sub opts;
      opts

let subcommands = [ "render"; "animate"; "check"; "diff"; "golden"; "watch"; "bench" ]
let operators = [ "|"; "||"; "&&"; ";"; "&"; ">"; ">>"; "<"; "2>"; "2>&1"; ">&-" ]
let is_lancer w = List.mem (Filename.basename w) [ "lancer"; "lancer-mpi" ]

let make_targets root =
  let t = Hashtbl.create 32 in
  List.iter
    (fun l ->
      match String.index_opt l ':' with
      | Some k
        when k > 0
             && l.[0] <> '\t'
             && l.[0] <> '#'
             && (k + 1 >= String.length l || l.[k + 1] <> '=')
             && not (String.contains (String.sub l 0 k) '=') ->
          List.iter
            (fun w -> if w <> "" then Hashtbl.replace t w ())
            (String.split_on_char ' ' (String.sub l 0 k))
      | _ -> ())
    (lines_of (read_file (Filename.concat root "Makefile")));
  t

let check_command_words env ~file ~line targets words =
  let rec go = function
    | [] -> ()
    | w :: rest when is_lancer w ->
        let sub, rest =
          match rest with
          | "bench" :: s :: r when not (starts_with ~prefix:"-" s) -> ([ "bench"; s ], r)
          | s :: r when List.mem s subcommands -> ([ s ], r)
          | r -> ([], r)
        in
        let rec opts = function
          | [] -> ()
          | o :: _ when List.mem o operators -> ()
          | o :: r ->
              (if String.length o > 1 && o.[0] = '-' && not (o.[1] >= '0' && o.[1] <= '9')
               then
                 let name =
                   match String.index_opt o '=' with
                   | Some k -> String.sub o 0 k
                   | None -> o
                 in
                 match options_of env sub with
                 | None ->
                     fail ~file ~line "`lancer %s` is not a command"
                       (String.concat " " sub)
                 | Some set ->
                     if not (Hashtbl.mem set name) then
                       fail ~file ~line "`lancer %s` has no option %s"
                         (String.concat " " sub) name);
              opts r
        in
        opts rest;
        go rest
    | "make" :: rest ->
        let rec tg = function
          | t :: r
            when (not (List.mem t operators))
                 && (not (starts_with ~prefix:"-" t))
                 && not (String.contains t '=') ->
              if not (Hashtbl.mem targets t) then
                fail ~file ~line "`make %s`: the Makefile has no such target" t;
              tg r
          | _ -> ()
        in
        tg rest;
        go rest
    | _ :: rest -> go rest
  in
  go words

let check_sh env ~file targets b =
  incr count_sh;
  let rec go i = function
    | [] -> ()
    | l :: rest ->
        let l =
          if starts_with ~prefix:"$ " l then String.sub l 2 (String.length l - 2) else l
        in
        let rec join l k rest =
          if ends_with ~suffix:"\\" (rstrip l) then
            match rest with
            | c :: r ->
                join
                  (String.sub (rstrip l) 0 (String.length (rstrip l) - 1) ^ " " ^ c)
                  (k + 1) r
            | [] -> (l, k, [])
          else (l, k, rest)
        in
        let l, k, rest = join l 0 rest in
        check_command_words env ~file ~line:(b.line + i + 1) targets (words_of l);
        go (i + 1 + k) rest
  in
  go 0 b.body

(* ---- from=PATH ---------------------------------------------------------------------------- *)

let check_excerpt env ~file b path =
  let p = Filename.concat env.root path in
  if not (Sys.file_exists p) then fail ~file ~line:b.line "from=%s: no such file" path
  else
    let norm l = String.trim l in
    let src = List.map norm (lines_of (read_file p)) in
    let rec go src = function
      | [] -> ()
      | "" :: rest -> go src rest
      | l :: rest -> (
          let rec find = function
            | [] -> None
            | s :: r -> if s = l then Some r else find r
          in
          match find src with
          | Some src' -> go src' rest
          | None ->
              fail ~file ~line:b.line
                "this block is not an excerpt of %s: %S is not in it (in order)" path l)
    in
    go src (List.map norm b.body)

(* ---- Links ----------------------------------------------------------------------------- *)

(* GitHub's heading anchors: lower case, punctuation and symbols dropped, spaces to
   hyphens, a repeated anchor numbered -1, -2, … *)
let slug heading =
  let b = Buffer.create (String.length heading) in
  let n = String.length heading in
  let i = ref 0 in
  while !i < n do
    let c = heading.[!i] in
    let len =
      if Char.code c < 0x80 then 1
      else if Char.code c < 0xE0 then 2
      else if Char.code c < 0xF0 then 3
      else 4
    in
    let len = min len (n - !i) in
    (if len = 1 then
       match c with
       | 'A' .. 'Z' -> Buffer.add_char b (Char.lowercase_ascii c)
       | 'a' .. 'z' | '0' .. '9' | '_' | '-' -> Buffer.add_char b c
       | ' ' -> Buffer.add_char b '-'
       | _ -> ()
     else
       let u = String.sub heading !i len in
       (* Symbols and punctuation outside ASCII that headings here use; letters stay. *)
       if not (List.mem u [ "×"; "—"; "–"; "→"; "’"; "“"; "”"; "…"; "·"; "±"; "≤"; "≥" ])
       then Buffer.add_string b u);
    i := !i + len
  done;
  Buffer.contents b

let anchors_cache = Hashtbl.create 8

let anchors_of path =
  match Hashtbl.find_opt anchors_cache path with
  | Some a -> a
  | None ->
      let seen = Hashtbl.create 32 and set = Hashtbl.create 32 in
      List.iter
        (function
          | Some l when starts_with ~prefix:"#" l ->
              let k = ref 0 in
              while !k < String.length l && l.[!k] = '#' do
                incr k
              done;
              let text = String.trim (String.sub l !k (String.length l - !k)) in
              let text = String.concat "" (String.split_on_char '`' text) in
              let s = slug text in
              let s =
                match Hashtbl.find_opt seen s with
                | None ->
                    Hashtbl.replace seen s 1;
                    s
                | Some k ->
                    Hashtbl.replace seen s (k + 1);
                    Printf.sprintf "%s-%d" s k
              in
              Hashtbl.replace set s ()
          | _ -> ())
        (prose_lines (read_file path));
      Hashtbl.add anchors_cache path set;
      set

(* Inline code spans removed, so that `[a](b)` shown as code is not a link. *)
let without_code l =
  let b = Buffer.create (String.length l) in
  let inside = ref false in
  String.iter
    (fun c ->
      if c = '`' then inside := not !inside else if not !inside then Buffer.add_char b c)
    l;
  Buffer.contents b

let check_links env ~file text =
  let dir = Filename.dirname file in
  List.iteri
    (fun i -> function
      | None -> ()
      | Some l ->
          let l = without_code l in
          let n = String.length l in
          let rec scan k =
            match find_from l k "](" with
            | None -> ()
            | Some p -> (
                match String.index_from_opt l (p + 2) ')' with
                | None -> ()
                | Some q ->
                    let target = String.sub l (p + 2) (q - p - 2) in
                    let target =
                      match String.index_opt target ' ' with
                      | Some s -> String.sub target 0 s
                      | None -> target
                    in
                    if
                      target <> ""
                      && not
                           (starts_with ~prefix:"http://" target
                           || starts_with ~prefix:"https://" target
                           || starts_with ~prefix:"mailto:" target)
                    then (
                      incr count_links;
                      let path, anchor =
                        match String.index_opt target '#' with
                        | Some h ->
                            ( String.sub target 0 h,
                              Some
                                (String.sub target (h + 1) (String.length target - h - 1))
                            )
                        | None -> (target, None)
                      in
                      let resolved =
                        if path = "" then file else Filename.concat dir path
                      in
                      let full = Filename.concat env.root resolved in
                      if not (Sys.file_exists full) then
                        fail ~file ~line:(i + 1) "the link %s names no file (%s)" target
                          resolved
                      else
                        match anchor with
                        | Some a when Filename.check_suffix full ".md" ->
                            if not (Hashtbl.mem (anchors_of full) a) then
                              fail ~file ~line:(i + 1)
                                "the link %s: %s has no heading #%s" target resolved a
                        | _ -> ());
                    if q + 1 < n then scan (q + 1))
          in
          scan 0)
    (prose_lines text)

(* ---- Pages ------------------------------------------------------------------------------ *)

let shown_only = [ "ocaml"; "dune"; "text"; "json"; "ply"; "obj" ]

let check_page env targets ~tmp ~index file =
  let text = read_file (Filename.concat env.root file) in
  let dir = Filename.concat tmp (Printf.sprintf "page-%d" index) in
  Unix.mkdir dir 0o755;
  Unix.symlink (Filename.concat env.root "scenes") (Filename.concat dir "scenes");
  List.iter
    (fun b ->
      (match List.assoc_opt "file" b.attrs with
      | Some name when name <> "" ->
          let p = Filename.concat dir name in
          mkdir_p (Filename.dirname p);
          write_file p (String.concat "\n" b.body ^ "\n")
      | _ -> ());
      (match List.assoc_opt "from" b.attrs with
      | Some path -> check_excerpt env ~file b path
      | None -> ());
      match b.lang with
      | "rts" -> check_rts env ~file ~dir b
      | "console" -> check_console env ~file ~dir b
      | "sh" | "bash" -> check_sh env ~file targets b
      | "" ->
          fail ~file ~line:b.line
            "a block without a language: say what it is (rts, console, sh, ocaml, dune, \
             text, …)"
      | l when List.mem l shown_only -> ()
      | l -> fail ~file ~line:b.line "unknown block language %S" l)
    (blocks_of ~file text);
  check_links env ~file text

let rec md_files dir =
  Sys.readdir dir |> Array.to_list |> List.sort compare
  |> List.concat_map (fun e ->
         let p = Filename.concat dir e in
         if Sys.is_directory p then md_files p
         else if Filename.check_suffix e ".md" then [ p ]
         else [])

let () =
  match Array.to_list Sys.argv with
  | _ :: lancer :: files ->
      let root = Sys.getcwd () in
      let files =
        if files <> [] then files
        else
          [ "README.md"; "CHANGES.md" ] @ md_files "doc"
          @ [ "scenes/gallery/README.md"; "test/example-user/README.md" ]
          |> List.filter Sys.file_exists
      in
      let tmp =
        Filename.concat
          (Filename.get_temp_dir_name ())
          (Printf.sprintf "lancer-docs-%d" (Unix.getpid ()))
      in
      Unix.mkdir tmp 0o755;
      let bindir = Filename.concat tmp "bin" in
      Unix.mkdir bindir 0o755;
      Unix.symlink (absolute lancer) (Filename.concat bindir "lancer");
      let env = { root; bindir } in
      let targets = make_targets root in
      Fun.protect
        ~finally:(fun () -> rm_rf tmp)
        (fun () -> List.iteri (fun index f -> check_page env targets ~tmp ~index f) files);
      Printf.printf
        "docs: %d pages, %d scenes, %d commands of transcripts, %d shell blocks, %d \
         links: %s\n"
        (List.length files) !count_rts !count_commands !count_sh !count_links
        (if !failures = 0 then "all as the pages say"
         else Printf.sprintf "%d failures" !failures);
      exit (if !failures = 0 then 0 else 1)
  | _ ->
      prerr_endline "usage: docs_check LANCER [FILE.md ...]";
      exit 2
