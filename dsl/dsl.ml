module D = Description

type physics_method = D.physics_method = Exact | Verlet | Euler
type physics = D.physics = { gravity : Vec3.t; method_ : physics_method; step : float }

type body = D.body = {
  name : string;
  center : Vec3.t;
  radius : float;
  velocity : Vec3.t;
  mass : float;
  restitution : float;
  loc : Loc.t;
}

type t = {
  file : string;
  code : Compile.t;  (** the program, compiled once *)
  strings : string list;  (** every string literal the program writes *)
  empty : bool;  (** no statement at all *)
  sources : (string, string) Hashtbl.t;
  resolved : (string * string, string) Hashtbl.t;
      (** for each (including file, name written), the path the include was found at *)
  includes : (string, Loc.t list) Hashtbl.t;
      (** for each included file, where it was included *)
  header : D.t;  (** the evaluation at time 0, frame 0, without its objects *)
  kept : (D.t * Run.static) option Atomic.t;
      (** that evaluation whole, and what it did in the static statements, until
          {!release}d *)
  named : (string, unit) Hashtbl.t;
      (** the image and mesh files the descriptions made so far name *)
  named_lock : Mutex.t;
  emitted : bool;  (** the load's objects went to its [emit], not into [kept] *)
}

let default_physics = D.default_physics

let inputs t =
  let named =
    Mutex.protect t.named_lock (fun () ->
        Hashtbl.fold (fun file () acc -> file :: acc) t.named [])
  in
  List.sort_uniq compare
    (Hashtbl.fold (fun file _ acc -> file :: acc) t.sources [] @ named)

let note t (d : D.t) =
  Mutex.protect t.named_lock (fun () ->
      List.iter (fun f -> Hashtbl.replace t.named f ()) d.files)

(* A path the evaluator resolved (relative to the including file), as seen from the main
   file's directory: how the scene itself names it, whatever path the scene was typed as. *)
let scene_relative t p =
  let d = Filename.dirname t.file in
  let prefix = Filename.concat d "" in
  if d <> "." && String.starts_with ~prefix p then
    String.sub p (String.length prefix) (String.length p - String.length prefix)
  else p

let text_digest t =
  let entry f text =
    (if f = t.file then "" else scene_relative t f)
    ^ " "
    ^ Digest.to_hex (Digest.string text)
  in
  let lines =
    List.sort String.compare
      (Hashtbl.fold (fun f text acc -> entry f text :: acc) t.sources [])
  in
  Digest.to_hex (Digest.string (String.concat "\n" lines))

let file t = t.file
let first t = match Atomic.get t.kept with Some (d, _) -> d | None -> t.header
let released t = Option.is_none (Atomic.get t.kept)
let emitted t = t.emitted

(* The objects are let go from the program: what the load recorded of them (the
   description and the static statements' objects) is forgotten, and the next
   description at time 0 is evaluated again. One caller gets them. *)
let release t = Option.map fst (Atomic.exchange t.kept None)
let static t = match Atomic.get t.kept with Some (_, st) -> Run.objects st | None -> []
let recorded t = Option.map snd (Atomic.get t.kept)
let animation t = t.header.animation
let bodies t = t.header.bodies
let physics t = t.header.physics
let empty t = t.empty

(* The one boundary: nothing raised below reaches the caller but an interrupt (Ctrl-C
   while a scene is evaluated), which is the command's to answer. *)
let guard file f =
  try f () with
  | Sys.Break -> raise Sys.Break
  | Stack_overflow ->
      Error
        [
          Error.file_error file
            "the scene is nested too deeply (the evaluator's stack overflowed)";
        ]
  | Out_of_memory ->
      Error [ Error.file_error file "the scene needs more memory than is available" ]
  | e ->
      Error
        [
          Error.file_error file
            ("internal error: " ^ Printexc.to_string e ^ " (please report it)");
        ]

let max_source_bytes = 64 * 1024 * 1024

(* Only a regular file of a sensible size is read: a device (/dev/zero) or a huge file
   would be read in full before being refused, and a FIFO would block. Checked from the
   file's status, before it is opened. *)
let source_problem path =
  match Unix.stat path with
  | exception Unix.Unix_error (e, _, _) -> Some (Unix.error_message e)
  | st -> (
      match st.st_kind with
      | Unix.S_REG when st.st_size > max_source_bytes ->
          Some
            (Printf.sprintf "it is %d MB; a scene file may be at most %d MB"
               (st.st_size / 1_000_000)
               (max_source_bytes / 1024 / 1024))
      | Unix.S_REG -> None
      | Unix.S_DIR -> Some "it is a directory"
      | Unix.S_FIFO -> Some "it is a pipe (FIFO), not a regular file"
      | Unix.S_CHR | Unix.S_BLK -> Some "it is a device, not a regular file"
      | Unix.S_SOCK -> Some "it is a socket, not a regular file"
      | Unix.S_LNK -> None)

let read_file path =
  match source_problem path with
  | Some m -> Error m
  | None -> (
      try Ok (In_channel.with_open_bin path In_channel.input_all)
      with Sys_error m -> Error m)

let canonical path = try Unix.realpath path with _ -> path

(* Replace every [include] by the parsed statements of the file it names, relative to the
   including file. [stack] holds the files being included, outermost last. *)
(* From the disk, or lancer's own library: a file's status is checked before it is opened
   (a device or a FIFO would be read for ever or block, a huge file read in full). *)
let from_disk ~including p =
  let path = Library.locate ~including p in
  let text () =
    match
      Option.bind (if Sys.file_exists path then Some path else None) source_problem
    with
    | Some m -> Error (`Status m)
    | None -> ( match Library.read path with Ok t -> Ok t | Error m -> Error (`Read m))
  in
  (path, text)

(* An error in a file that did not parse shows its line only if the file is named as a
   scene: an include that names any other file ("../../etc/shadow") must not print that
   file's lines. *)
let unquoted path (e : Error.t) =
  if String.lowercase_ascii (Filename.extension path) = ".rts" then e
  else
    {
      e with
      source_line = None;
      message =
        "this file does not parse as a scene (a syntax error here); it is not named \
         .rts, so nothing of it is shown";
    }

(* The most included files a program may expand to, counting every inclusion: a file
   included twice by each of 22 others in a chain would otherwise expand 4 million
   times. *)
let max_inclusions = 10_000

(* Replace every [include] by the parsed statements of the file it names, relative to the
   including file. [stack] holds the files being included, outermost last. Each file is
   read and parsed once, however often it is included; [resolved] keeps, for each
   (including file, name written), the path it was found at. [resolver] gives the function
   that resolves the includes of a top-level statement. *)
let resolver ~read sources resolved includes errors main =
  let err loc msg =
    errors :=
      Error.make ?source:(Hashtbl.find_opt sources loc.Loc.file) loc msg :: !errors
  in
  let parsed = Hashtbl.create 4 and inclusions = ref 0 in
  let chain file = Option.value (Hashtbl.find_opt includes file) ~default:[] in
  (* Whether a statement holds an include, anywhere inside: only then is it made anew. *)
  let rec includes_in (s : Ast.stmt) =
    match s.s with
    | Include _ -> true
    | Macro (_, _, b) | For (_, _, _, _, b) | For_each (_, _, b) ->
        List.exists includes_in b
    | If_stmt (_, t, e) -> List.exists includes_in t || List.exists includes_in e
    | Block (_, its) | Body (_, its) ->
        List.exists (function Ast.Stmt s -> includes_in s | Field _ -> false) its
    | Let _ | Fn _ | Included _ | Call_stmt _ -> false
  in
  let rec stmts_ stack file ss = List.map (stmt stack file) ss
  and items stack file its =
    List.map
      (function Ast.Field _ as f -> f | Ast.Stmt s -> Ast.Stmt (stmt stack file s))
      its
  and stmt stack file (s : Ast.stmt) = if includes_in s then resolve stack file s else s
  and resolve stack file (s : Ast.stmt) =
    let d =
      match s.s with
      | Include (p, loc) -> (
          let path, read_text =
            match Hashtbl.find_opt resolved (file, p) with
            | Some path -> (path, fun () -> Ok (Hashtbl.find sources path))
            | None -> read ~including:file p
          in
          (* Each file is read once: the text the program keeps is the one it parsed. *)
          let text () =
            match Hashtbl.find_opt sources path with
            | Some t -> Ok t
            | None -> read_text ()
          in
          let key = canonical path in
          incr inclusions;
          match List.find_opt (fun (k, _) -> k = key) stack with
          | Some _ ->
              let chain = List.rev_map snd stack @ [ path ] in
              let rec cut = function
                | [] -> []
                | x :: rest as l -> if canonical x = key then l else cut rest
              in
              err loc
                (Printf.sprintf "include cycle: %s"
                   (String.concat " includes " (cut chain)));
              Ast.Included (path, [])
          | None when List.length stack > 64 ->
              err loc "includes are nested more than 64 deep";
              Ast.Included (path, [])
          | None when !inclusions > max_inclusions ->
              if !inclusions = max_inclusions + 1 then
                err s.sloc
                  (Printf.sprintf
                     "the includes expand to more than %d files (\"%s\" and the files it \
                      includes are included over and over): include each file once, from \
                      one place"
                     max_inclusions p);
              Ast.Included (path, [])
          | None -> (
              match text () with
              | Error (`Status m) ->
                  err s.sloc
                    (Printf.sprintf "cannot read the included file \"%s\": %s" p m);
                  Ast.Included (path, [])
              | Error (`Read m) ->
                  let msg =
                    match Error.cannot_read ~what:"included file" ~written:p path with
                    | Some msg -> msg
                    | None ->
                        Printf.sprintf "cannot read the included file \"%s\": %s" p m
                  in
                  err s.sloc msg;
                  Ast.Included (path, [])
              | Ok text -> (
                  let text = Syntax.without_bom text in
                  Hashtbl.replace resolved (file, p) path;
                  Hashtbl.replace sources path text;
                  (* The first include of a file gives the chain its errors show. *)
                  if key <> canonical main && not (Hashtbl.mem includes path) then
                    Hashtbl.replace includes path (s.sloc :: chain file);
                  let ss =
                    match Hashtbl.find_opt parsed path with
                    | Some r -> r
                    | None ->
                        let r = Syntax.parse ~file:path text in
                        Result.iter_error
                          (fun e -> errors := unquoted path e :: !errors)
                          r;
                        Hashtbl.replace parsed path r;
                        r
                  in
                  match ss with
                  | Error _ -> Ast.Included (path, [])
                  | Ok ss -> Ast.Included (path, stmts_ ((key, path) :: stack) path ss))))
      | Macro (f, ps, b) -> Macro (f, ps, stmts_ stack file b)
      | For (x, a, b, st, body) -> For (x, a, b, st, stmts_ stack file body)
      | For_each (x, l, body) -> For_each (x, l, stmts_ stack file body)
      | If_stmt (c, t, e) -> If_stmt (c, stmts_ stack file t, stmts_ stack file e)
      | Block (k, its) -> Block (k, items stack file its)
      | Body (n, its) -> Body (n, items stack file its)
      | (Let _ | Fn _ | Included _ | Call_stmt _) as d -> d
    in
    { s with s = d }
  in
  stmt [ (canonical main, main) ] main

(* Every error of a file that was included gets the chain of includes that led to it. *)
let chained includes r =
  Result.map_error
    (List.map
       (Error.with_includes (fun file ->
            Option.value (Hashtbl.find_opt includes file) ~default:[])))
    r

let chained_list includes es =
  match chained includes (Error es) with Error es -> es | Ok () -> []

(* What the files a run met have wrong (the caller reads them), as errors of the program. *)
let file_errors files sources uses =
  match files with
  | None -> []
  | Some f ->
      List.map
        (fun ((loc : Loc.t), msg) ->
          Error.make ?source:(Hashtbl.find_opt sources loc.file) loc msg)
        (f (List.rev uses))

(* Every string the program writes, in any statement, branch, function or macro, run or
   not, and each join [a + b] of a string written in [a] and one written in [b]: a file
   any frame can read is named by one of these, unless the program joins strings held by
   names. *)
let strings ~acc stmts =
  let acc = ref acc in
  let rec expr (e : Ast.expr) =
    match e.e with
    | Str s -> if s <> "" then acc := s :: !acc
    | Num _ | Bool _ | Var _ -> ()
    | Vec (a, b, c) | If (a, b, c) ->
        expr a;
        expr b;
        expr c
    | Binop (Add, a, b) ->
        let before = !acc in
        expr a;
        let after_a = !acc in
        expr b;
        (* The strings put in front of [stop]. *)
        let rec since stop l =
          if l == stop then [] else match l with x :: r -> x :: since stop r | [] -> []
        in
        let ys = since after_a !acc in
        List.iter
          (fun x -> List.iter (fun y -> acc := (x ^ y) :: !acc) ys)
          (since before after_a)
    | Pair (a, b) | Binop (_, a, b) | Index (a, b) ->
        expr a;
        expr b
    | Unop (_, a) | Dot (a, _) -> expr a
    | Call (_, es) | List es -> List.iter expr es
    | Material its -> List.iter item its
  and item = function Ast.Field (_, e) -> expr e | Ast.Stmt s -> stmt s
  and stmt (s : Ast.stmt) =
    match s.s with
    | Let (_, e) | Fn (_, _, e) -> expr e
    | Macro (_, _, b) | Included (_, b) -> List.iter stmt b
    | For (_, a, b, st, body) ->
        expr a;
        expr b;
        Option.iter expr st;
        List.iter stmt body
    | For_each (_, l, body) ->
        expr l;
        List.iter stmt body
    | If_stmt (c, th, el) ->
        expr c;
        List.iter stmt th;
        List.iter stmt el
    | Include _ -> ()
    | Block (_, its) | Body (_, its) -> List.iter item its
    | Call_stmt (_, es) -> List.iter expr es
  in
  List.iter stmt stmts;
  !acc

(* What loading a program makes of it, statement by statement: each top-level statement's
   includes resolved, then checked, compiled and looked at for the plan of static
   statements as it comes, so that what is read of a large program goes as soon as it is
   compiled. *)
type loading = {
  sources : (string, string) Hashtbl.t;
  resolved : (string * string, string) Hashtbl.t;
  includes : (string, Loc.t list) Hashtbl.t;
  errors : Error.t list ref;  (** of the includes, reversed *)
  resolve : Ast.stmt -> Ast.stmt;
  check : Check.state;
  compile : Compile.state;
  analysis : Run.analysis;
  mutable strings : string list;
  mutable count : int;  (** top-level statements *)
}

let loading ~read file text =
  let sources = Hashtbl.create 4 and includes = Hashtbl.create 4 in
  let resolved = Hashtbl.create 4 and errors = ref [] in
  Hashtbl.replace sources file text;
  {
    sources;
    resolved;
    includes;
    errors;
    resolve = resolver ~read sources resolved includes errors file;
    check = Check.start ~sources ();
    compile = Compile.start ();
    analysis = Run.analysis ();
    strings = [];
    count = 0;
  }

let feed l s =
  let s = l.resolve s in
  l.count <- l.count + 1;
  l.strings <- strings ~acc:l.strings [ s ];
  Run.analyse l.analysis s;
  List.iter (Compile.top l.compile) (Check.top l.check s)

(* The program read as it comes; where the reader gives up (a mistake it leaves to the
   grammar to explain), read whole, and [Error] for a syntax error. *)
let read_program ~read file text =
  match
    let r = Reader.start ~file text in
    let l = loading ~read file text in
    let rec go () =
      match Reader.next r with
      | Some s ->
          feed l s;
          go ()
      | None -> ()
    in
    go ();
    if Reader.plain r || Option.is_none (Syntax.not_text file text) then Some l else None
  with
  | Some l -> Ok l
  | None | (exception (Reader.Give_up | Failure _ | Invalid_argument _ | Stack_overflow))
    -> (
      match Syntax.parse ~file text with
      | Error e -> Error [ e ]
      | Ok stmts ->
          let l = loading ~read file text in
          List.iter (feed l) stmts;
          Ok l)

let load_text ?progress ?files ?emit ?(read = from_disk) file text =
  let text = Syntax.without_bom text in
  match read_program ~read file text with
  | Error es -> Error es
  | Ok l when !(l.errors) <> [] -> chained l.includes (Error (List.rev !(l.errors)))
  | Ok l -> (
      let sources = l.sources and includes = l.includes in
      chained includes
      @@
      let on_objects n =
        Option.iter
          (fun f -> f (Printf.sprintf "checking the scene: %d objects so far" n))
          progress
      in
      (* The checker's mistakes, with those of the run at time 0 and of the files it
         uses, in source order (the checker's first at the same place). *)
      let _, static = Check.finish l.check in
      let code = Compile.finish l.compile in
      let merged es = Run.sort_errors (static @ es) in
      let uses = ref [] in
      let on_file u = uses := u :: !uses in
      let plan = Run.plan_of l.analysis in
      (* A still without bodies or motion blur has one scene: its objects may go to
         [emit] as they are made. *)
      let emit = if Check.moving l.check then None else emit in
      let run =
        Run.record ?emit plan ~on_objects ~on_file ~file ~sources ~time:0. ~frame:0 code
      in
      match (run, file_errors files sources !uses) with
      | Error es, fes -> Error (merged (es @ fes))
      | Ok _, fes when static <> [] || fes <> [] -> Error (merged fes)
      | Ok (first, static), _ ->
          let first = { first with warnings = chained_list includes first.warnings } in
          Ok
            {
              file;
              code;
              strings = l.strings;
              empty = l.count = 0;
              sources;
              resolved = l.resolved;
              includes;
              header = { first with objects = [] };
              kept =
                Atomic.make (if Option.is_some emit then None else Some (first, static));
              named =
                (let h = Hashtbl.create 4 in
                 List.iter (fun f -> Hashtbl.replace h f ()) first.files;
                 h);
              named_lock = Mutex.create ();
              emitted = Option.is_some emit;
            })

let load_string ?progress ?files ?emit ?(filename = "<string>") text =
  guard filename (fun () -> load_text ?progress ?files ?emit filename text)

type bundle = {
  b_file : string;
  b_text : string;
  b_includes : ((string * string) * (string * string)) list;
}

let bundle (t : t) =
  {
    b_file = t.file;
    b_text = Hashtbl.find t.sources t.file;
    b_includes =
      List.sort compare
        (Hashtbl.fold
           (fun key path acc -> (key, (path, Hashtbl.find t.sources path)) :: acc)
           t.resolved []);
  }

(* Includes from the bundle alone: none is looked for on this machine's disk. *)
let load_bundle ?progress ?files ?emit b =
  let read ~including p =
    match List.assoc_opt (including, p) b.b_includes with
    | Some (path, text) -> (path, fun () -> Ok text)
    | None ->
        ( Loc.relative_to including p,
          fun () -> Error (`Status "it is not among the files the program was sent with")
        )
  in
  guard b.b_file (fun () -> load_text ?progress ?files ?emit ~read b.b_file b.b_text)

let load_file ?files ?emit path =
  guard path (fun () ->
      match read_file path with
      | Error m -> Error [ Error.file_error path ("cannot read the scene: " ^ m) ]
      | Ok text -> load_text ?files ?emit path text)

(* [parts]: the objects as parts ({!Run.run_parts}), else whole. *)
let eval ?(again = false) ~parts ?body_state ?on_objects ?on_file ?cancel (t : t) ~time
    ~frame =
  if not (Float.is_finite time) then
    Error [ Error.file_error t.file "the time must be a finite number" ]
  else
    let static = if again then None else recorded t in
    if parts then
      Run.run_parts ?static ?body_state ?on_objects ?on_file ?cancel ~file:t.file
        ~sources:t.sources ~time ~frame t.code
    else
      Result.map
        (fun d -> (d, []))
        (Run.run ?static ?body_state ?on_objects ?on_file ?cancel ~file:t.file
           ~sources:t.sources ~time ~frame t.code)

(* An error that only some frames have names the frame: frame 0 was checked when the
   program was loaded, so an error at another instant is one of those. *)
let at_frame ~time ~frame r =
  if Float.equal time 0. && frame = 0 then r
  else
    Result.map_error
      (List.map (fun (e : Error.t) ->
           {
             e with
             message = Printf.sprintf "%s (at frame %d, time %g s)" e.message frame time;
           }))
      r

let named_files (t : t) =
  let files = Hashtbl.fold (fun f _ acc -> f :: acc) t.sources [] in
  List.sort_uniq String.compare
    (List.concat_map
       (fun s -> List.map (fun f -> Loc.relative_to f s) files)
       (List.sort_uniq String.compare t.strings))

let source (t : t) file = Hashtbl.find_opt t.sources file

let located (t : t) ~time ~frame es =
  match at_frame ~time ~frame (chained t.includes (Error es)) with
  | Error es -> es
  | Ok () -> []

(* An evaluation at [time] and [frame], its objects whole or as parts. *)
let evaluate ?again ~parts ?body_state ?progress ?cancel ?files (t : t) ~time ~frame =
  let say fmt = Printf.ksprintf (fun m -> Option.iter (fun f -> f m) progress) fmt in
  at_frame ~time ~frame @@ chained t.includes
  @@ guard t.file (fun () ->
         let on_objects n = say "evaluating the scene: %d objects so far" n in
         let uses = ref [] in
         let on_file u = uses := u :: !uses in
         match
           eval ?again ~parts ?body_state ~on_objects ~on_file ?cancel t ~time ~frame
         with
         | Error es -> Error (Run.sort_errors (es @ file_errors files t.sources !uses))
         | Ok (d, ps) ->
             note t d;
             Ok ({ d with warnings = chained_list t.includes d.warnings }, ps))

type 'a at_instant =
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  ?progress:(string -> unit) ->
  ?cancel:Cancel.t ->
  ?files:(D.file_use list -> (Loc.t * string) list) ->
  t ->
  time:float ->
  frame:int ->
  ('a, Error.t list) result

(* The evaluation at time 0, frame 0 is the one made when the program was loaded, until
   it is released. *)
let describe ?again ?body_state ?progress ?cancel ?files (t : t) ~time ~frame =
  match Atomic.get t.kept with
  | Some (first, _) when Float.equal time 0. && frame = 0 && body_state = None -> Ok first
  | _ ->
      Result.map fst
        (evaluate ?again ~parts:false ?body_state ?progress ?cancel ?files t ~time ~frame)

let describe_parts ?body_state ?progress ?cancel ?files t ~time ~frame =
  evaluate ~parts:true ?body_state ?progress ?cancel ?files t ~time ~frame

(* ---------------------------------------------------------------------------------- *)
(* lancer check *)
