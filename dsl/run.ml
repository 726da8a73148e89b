module D = Description
open Ast
open Value

(* Errors in source order: files in the order they first appear, then line and column. *)
let sort_errors (es : Error.t list) =
  let files =
    List.fold_left
      (fun acc (e : Error.t) -> if List.mem e.file acc then acc else acc @ [ e.file ])
      [] es
  in
  let rec index x i = function
    | [] -> i
    | y :: r -> if y = x then i else index x (i + 1) r
  in
  let key (e : Error.t) = (index e.file 0 files, e.line, e.col) in
  List.stable_sort (fun a b -> compare (key a) (key b)) es

(* ------------------------------------------------------------------------------------ *)
(* What does not change between instants *)

(* Whether a statement or expression mentions a name for which [p] holds: a name it reads,
   in an expression, a call or a macro call (not a name it binds). A value the statement
   computes can come from nothing but these names and its literals, so if none of them
   holds anything that may differ between instants, neither does the statement's work. *)
let rec expr_mentions p (e : expr) =
  match e.e with
  | Num _ | Str _ | Bool _ -> false
  | Var x -> p x
  | Vec (a, b, c) | If (a, b, c) ->
      expr_mentions p a || expr_mentions p b || expr_mentions p c
  | Pair (a, b) | Binop (_, a, b) | Index (a, b) -> expr_mentions p a || expr_mentions p b
  | Unop (_, a) | Dot (a, _) -> expr_mentions p a
  | Call (f, args) -> p f.id || List.exists (expr_mentions p) args
  | List es -> List.exists (expr_mentions p) es
  | Material items -> items_mention p items

and items_mention p items =
  List.exists
    (function Field (_, e) -> expr_mentions p e | Stmt s -> stmt_mentions p s)
    items

and stmt_mentions p (s : stmt) =
  match s.s with
  | Let (_, e) | Fn (_, _, e) -> expr_mentions p e
  | Macro (_, _, b) | Included (_, b) -> List.exists (stmt_mentions p) b
  | For (_, a, b, st, body) ->
      expr_mentions p a || expr_mentions p b
      || (match st with Some e -> expr_mentions p e | None -> false)
      || List.exists (stmt_mentions p) body
  | For_each (_, l, body) -> expr_mentions p l || List.exists (stmt_mentions p) body
  | If_stmt (c, t, e) ->
      expr_mentions p c
      || List.exists (stmt_mentions p) t
      || List.exists (stmt_mentions p) e
  | Include _ -> false
  | Block (_, items) | Body (_, items) -> items_mention p items
  | Call_stmt (f, args) -> p f.id || List.exists (expr_mentions p) args

(* The names a statement binds anywhere inside it (loop variables, parameters, [let]s,
   functions, macros). *)
let rec bound_names acc (s : stmt) =
  let items acc its =
    List.fold_left
      (fun acc -> function Stmt s -> bound_names acc s | Field _ -> acc)
      acc its
  in
  match s.s with
  | Let (x, _) -> x.id :: acc
  | Fn (x, ps, _) -> (x.id :: List.map (fun (p : name) -> p.id) ps) @ acc
  | Macro (x, ps, b) ->
      List.fold_left bound_names ((x.id :: List.map (fun (p : name) -> p.id) ps) @ acc) b
  | For (x, _, _, _, b) | For_each (x, _, b) -> List.fold_left bound_names (x.id :: acc) b
  | If_stmt (_, t, e) -> List.fold_left bound_names (List.fold_left bound_names acc t) e
  | Included (_, b) -> List.fold_left bound_names acc b
  | Block (_, its) | Body (_, its) -> items acc its
  | Include _ | Call_stmt _ -> acc

let object_block k =
  match k with
  | "group" | "union" | "merge" | "intersection" | "difference" -> true
  | k -> Schema.is_shape k

(* Whether running [s] does nothing but build objects (into the scope it runs in) and
   use files: no settings, camera, light, animation, physics or body; a macro it calls
   must be one of [pure_macro]'s, not a name bound inside it. *)
let only_objects pure_macro (s : stmt) =
  let local = lazy (bound_names [] s) in
  let rec go (s : stmt) =
    match s.s with
    | Let _ | Fn _ | Macro _ -> true
    | For (_, _, _, _, b) | For_each (_, _, b) | Included (_, b) -> List.for_all go b
    | If_stmt (_, t, e) -> List.for_all go t && List.for_all go e
    | Block (k, its) ->
        object_block k.id
        && List.for_all (function Stmt s -> go s | Field _ -> true) its
    | Call_stmt (f, _) ->
        (not (List.exists (String.equal f.id) (Lazy.force local))) && pure_macro f.id
    | Include _ | Body _ -> false
  in
  go s

module Names = Set.Make (String)

(* What the recording run did in a static statement. *)
type recorded = {
  objects_before : int;  (** the count of objects built when it started *)
  steps_before : int;
  steps : int;  (** the evaluation steps it took *)
  counted : int;  (** the objects it counted against the limit (members included) *)
  built : D.obj list;  (** the objects it built, in order *)
  file_uses : D.file_use list;  (** in the order they were met *)
  warned : Error.t list;  (** in the order they were given *)
}

type plan = bool array
(* whether each top-level statement (includes flattened) depends on nothing that may
   differ between instants and only builds objects *)

type static = recorded option array
(* by position: what the recording run did in each static statement *)

(* The statements seen so far: names whose value may differ between instants (time,
   frame, bodies, and whatever is defined from them), macros that only build objects and
   depend on none of them, and which statements are static (newest first). *)
type analysis = {
  mutable dynamic : Names.t;
  mutable pure : Names.t;
  mutable static_rev : bool list;
}

let analysis () =
  { dynamic = Names.of_list [ "time"; "frame" ]; pure = Names.empty; static_rev = [] }

let rec analyse a (s : stmt) =
  let reads except =
    stmt_mentions (fun n -> (not (String.equal n except)) && Names.mem n a.dynamic) s
  in
  let set x dyn =
    a.dynamic <- (if dyn then Names.add x a.dynamic else Names.remove x a.dynamic)
  in
  let static =
    match s.s with
    | Let (x, _) ->
        set x.id (reads "");
        a.pure <- Names.remove x.id a.pure;
        false
    | Fn (x, _, _) ->
        set x.id (reads x.id);
        a.pure <- Names.remove x.id a.pure;
        false
    | Macro (x, _, b) ->
        let dyn = reads x.id in
        set x.id dyn;
        let self = Names.add x.id a.pure in
        let ok = (not dyn) && List.for_all (only_objects (fun f -> Names.mem f self)) b in
        a.pure <- (if ok then self else Names.remove x.id a.pure);
        false
    | Body (x, _) ->
        set x.id true;
        a.pure <- Names.remove x.id a.pure;
        false
    | Block _ | For _ | For_each _ | If_stmt _ | Call_stmt _ ->
        (not (reads "")) && only_objects (fun f -> Names.mem f a.pure) s
    | Include _ -> false
    | Included (_, b) ->
        List.iter (analyse a) b;
        false
  in
  match s.s with Included _ -> () | _ -> a.static_rev <- static :: a.static_rev

let plan_of a = Array.of_list (List.rev a.static_rev)

let plan stmts =
  let a = analysis () in
  List.iter (analyse a) stmts;
  plan_of a

let objects (st : static) =
  let acc = ref [] in
  Array.iteri (fun i -> function Some e -> acc := (i, e.built) :: !acc | None -> ()) st;
  List.rev !acc

(* ------------------------------------------------------------------------------------ *)
(* A run *)

(* The elements of [now] in front of [before] (a list it was grown from), oldest first. *)
let grown now before =
  let rec go acc l =
    if l == before then acc else match l with x :: r -> go (x :: acc) r | [] -> acc
  in
  go [] now

type mode = Plain | Record of plan * static | Replay of static

let exec ~mode ~parts ?body_state ?on_objects ?cancel ?(objects = true) ?emit
    ?(on_file = ignore) ~file ~sources ~time ~frame (prog : Compile.t) =
  let uses = ref [] in
  let on_file u =
    uses := u :: !uses;
    on_file u
  in
  let st =
    State.create ?body_state ?on_objects ?cancel ~on_file ~sources ~time ~frame ()
  in
  let out = st.out and count = st.count in
  let scope = { sink = ref []; emit; in_group = false; in_csg = false } in
  (* The objects built so far, newest piece first: those of the static statements, and
     between them those of the others (finished when a piece follows). *)
  let pieces = ref [] in
  let cut () =
    match !(scope.sink) with
    | [] -> ()
    | objs ->
        pieces := D.Built (List.rev objs) :: !pieces;
        scope.sink := []
  in
  let code = prog.stmts in
  let fr = { l = Array.make prog.slots VPoison; c = [||]; st } in
  let replay i (e : recorded) =
    (* It would do what it did then: the same objects, steps, files and warnings. *)
    cut ();
    pieces := D.Static i :: !pieces;
    let before = count.objects in
    count.objects <- count.objects + e.counted;
    count.steps <- count.steps + e.steps;
    List.iter (State.use st) e.file_uses;
    List.iter
      (fun (w : Error.t) ->
        let key = (w.file, w.line, w.col, "warning: " ^ w.message) in
        if not (Hashtbl.mem out.seen key) then (
          Hashtbl.add out.seen key ();
          out.warnings <- w :: out.warnings))
      e.warned;
    if count.objects lsr 16 > before lsr 16 then
      Option.iter (fun f -> f count.objects) on_objects;
    Option.iter Cancel.check cancel
  in
  let record into i =
    cut ();
    let objects_before = count.objects and steps_before = count.steps in
    let uses0 = !uses and warnings0 = out.warnings and errors0 = out.errors in
    code.(i) fr scope;
    let built = List.rev !(scope.sink) in
    scope.sink := [];
    pieces := D.Built built :: !pieces;
    if out.errors == errors0 then
      into.(i) <-
        Some
          {
            objects_before;
            steps_before;
            steps = count.steps - steps_before;
            counted = count.objects - objects_before;
            built;
            file_uses = grown !uses uses0;
            warned = grown out.warnings warnings0;
          }
  in
  let top i c =
    match mode with
    | Plain -> c fr scope
    | Record (plan, into) -> if plan.(i) then record into i else c fr scope
    | Replay static -> (
        match static.(i) with
        | Some e when count.objects = e.objects_before && count.steps <= e.steps_before ->
            replay i e
        | _ -> c fr scope)
  in
  (try Array.iteri top code with Abort -> ());
  if out.errors <> [] then Error (sort_errors (List.rev out.errors))
  else
    let static_objects = function
      | D.Built objs -> objs
      | D.Static i -> (
          match mode with
          | Replay static -> ( match static.(i) with Some e -> e.built | None -> [])
          | Plain | Record _ -> [])
    in
    let statics =
      if objects && not parts then (
        cut ();
        match !pieces with
        | [ p ] -> static_objects p
        | ps -> List.concat (List.rev_map static_objects ps))
      else []
    in
    let bodies = List.rev out.bodies in
    let body_objs =
      List.map
        (fun ((b : D.body), (o : D.obj)) ->
          let transform =
            match Option.bind body_state (fun f -> f b.name time) with
            | Some (p, _) ->
                Transform.then_ o.transform (Transform.translate (Vec3.sub p b.center))
            | None -> o.transform
          in
          { o with transform; body = Some b.name })
        (if objects then bodies else [])
    in
    let part_list =
      if parts then (
        cut ();
        List.rev (match body_objs with [] -> !pieces | b -> D.Built b :: !pieces))
      else []
    in
    Ok
      ( {
          D.file;
          time;
          frame;
          settings =
            (match out.settings with Some (s, _) -> s | None -> Settings.default);
          camera = (match out.camera with Some (c, _) -> c | None -> Camera.default);
          lights = List.rev out.lights;
          objects =
            (if parts then []
             else match body_objs with [] -> statics | _ -> statics @ body_objs);
          animation = Option.map fst out.animation;
          physics = Option.map fst out.physics;
          physics_loc = Option.map snd out.physics;
          warnings = sort_errors (List.rev out.warnings);
          bodies = List.map fst bodies;
          files =
            List.sort_uniq String.compare
              (Hashtbl.fold (fun p () acc -> p :: acc) out.used []);
        },
        part_list )

type 'a runner =
  ?on_objects:(int -> unit) ->
  ?cancel:Cancel.t ->
  ?on_file:(D.file_use -> unit) ->
  file:string ->
  sources:(string, string) Hashtbl.t ->
  time:float ->
  frame:int ->
  Compile.t ->
  ('a, Error.t list) result

let run ?static ?body_state ?objects ?on_objects ?cancel ?on_file ~file ~sources ~time
    ~frame prog =
  let mode = match static with Some st -> Replay st | None -> Plain in
  Result.map fst
    (exec ~mode ~parts:false ?body_state ?on_objects ?cancel ?objects ?on_file ~file
       ~sources ~time ~frame prog)

let run_parts ?static ?body_state ?on_objects ?cancel ?on_file ~file ~sources ~time ~frame
    prog =
  let mode = match static with Some st -> Replay st | None -> Plain in
  exec ~mode ~parts:true ?body_state ?on_objects ?cancel ?on_file ~file ~sources ~time
    ~frame prog

let record ?emit plan ?on_objects ?cancel ?on_file ~file ~sources ~time ~frame prog =
  let into = Array.make (Array.length plan) None in
  (* Objects that go to [emit] as they are made: nothing of them is recorded. *)
  let mode = match emit with None -> Record (plan, into) | Some _ -> Plain in
  Result.map
    (fun (d, _) -> (d, into))
    (exec ~mode ~parts:false ?on_objects ?cancel ?on_file ?emit ~file ~sources ~time
       ~frame prog)
