open Tast
module A = Ast
module Names = Map.Make (String)
module Keywords = Hashtbl.Make (String)

(* A block's keyword and the names of its fields as written. *)
module Written = Hashtbl.Make (struct
  type t = string * string list

  let equal (a, l) (b, m) = String.equal a b && List.equal String.equal l m

  (* Names are few and short: their lengths and first letters tell most apart. *)
  let hash (a, l) =
    List.fold_left
      (fun h n -> (h * 31) + (String.length n * 128) + Char.code n.[0])
      (Hashtbl.hash a) l
end)

type program = { stmts : Tast.stmt list; bindings : int }

(* What a name stands for where it is used, and its type. *)
type entry = { var : var; ty : Ty.t }
type env = { names : entry Names.t; level : int }

type cx = {
  sources : (string, string) Hashtbl.t;
  kinds : Kind.t list Keywords.t;  (** the schema's kinds, by keyword *)
  types : bool;  (** false: every expression's type is taken as unknown *)
  mutable errors : Error.t list;  (** reversed *)
  mutable count : int;  (** of [errors] *)
  mutable next : int;  (** the next binding's id *)
  mutable definitions : (string * Loc.t) list;
      (** every name the program defines, where, newest first *)
  placed : placed Written.t;
      (** the places of the fields of a block without a mistake, by its keyword and the
          names of its fields as written (those of a generated scene repeat) *)
  mutable last_kinds : string * Kind.t list;
      (** the last keyword looked up, and its kinds: a generated scene's blocks are mostly
          of one kind, and the reader makes the keywords the same string *)
  mutable moving : bool;
      (** whether an [animation] or [physics] block, a body or a camera's [shutter] is
          written anywhere *)
}

and placed = Kind.t * (slot * Schema.field option) list * bool

let report cx (loc : Loc.t) msg =
  cx.count <- cx.count + 1;
  cx.errors <-
    Error.make ?source:(Hashtbl.find_opt cx.sources loc.file) loc msg :: cx.errors

let binding cx env (x : A.name) =
  let b = { id = cx.next; name = x.id; level = env.level } in
  cx.next <- cx.next + 1;
  b

let bind env name var ty = { env with names = Names.add name { var; ty } env.names }

(* ------------------------------------------------------------------------------------ *)
(* Names *)

(* Every name a statement defines ([let], [fn], [body]), anywhere inside it, and where,
   newest first in front of [acc]. *)
let definitions acc stmts =
  let acc = ref acc in
  let rec stmt (s : A.stmt) =
    match s.s with
    | Let (x, _) | Fn (x, _, _) -> acc := (x.id, x.nloc) :: !acc
    | Macro (x, _, b) ->
        acc := (x.id, x.nloc) :: !acc;
        List.iter stmt b
    | Body (x, its) ->
        acc := (x.id, x.nloc) :: !acc;
        items its
    | For (_, _, _, _, b) | For_each (_, _, b) | Included (_, b) -> List.iter stmt b
    | If_stmt (_, t, e) ->
        List.iter stmt t;
        List.iter stmt e
    | Block (_, its) -> items its
    | Include _ | Call_stmt _ -> ()
  and items its = List.iter (function A.Stmt s -> stmt s | Field _ -> ()) its in
  List.iter stmt stmts;
  !acc

let colours = "lancer/colors.rts"

(* The message for a name that names nothing where it is used: one defined further down
   the same file was most likely meant; otherwise the closest name in scope. Made when the
   error is met, once the whole program is checked. *)
let unbound_message cx env x (loc : Loc.t) () =
  let later (d : Loc.t) =
    d.file = loc.file && (d.line > loc.line || (d.line = loc.line && d.col > loc.col))
  in
  match List.find_opt (fun (n, d) -> n = x && later d) (List.rev cx.definitions) with
  | Some (_, d) -> Msg.unknown_name_later x d
  | None -> (
      match Msg.hint x (List.map fst (Names.bindings env.names)) with
      | "" ->
          Msg.unknown_name x (Msg.library_hint x ~file:colours (Library.names colours))
      | hint -> Msg.unknown_name x hint)

let lookup cx env x loc =
  match Names.find_opt x env.names with
  | Some { var = Maybe (b, _); ty } ->
      { var = Maybe (b, unbound_message cx env x loc); ty }
  | Some e -> e
  | None -> { var = Unbound (unbound_message cx env x loc); ty = Unknown }

let initial =
  List.fold_left
    (fun env (b : Builtins.t) ->
      let ty : Ty.t =
        match b.kind with Number _ -> Num | Function _ -> Builtin b.name
      in
      bind env b.name (Global b) ty)
    { names = Names.empty; level = 0 }
    Builtins.all

(* ------------------------------------------------------------------------------------ *)
(* Expressions *)

let mk (e : A.expr) d ty = { e = d; ty; loc = e.loc }
let bad (e : A.expr) = { e = Bad; ty = Unknown; loc = e.loc }

(* A value of a known type that is not one [ok] takes: reported, with [msg]. *)
let refused cx (te : expr) ok msg =
  if Ty.known te.ty && not (ok te.ty) then (
    report cx te.loc (msg te.ty);
    true)
  else false

let is t u = Ty.equal t u

(* The call of a built-in: its arguments' types against its signature. *)
let builtin_call cx (e : A.expr) (f : A.name) (b : Builtins.t) args =
  match b.kind with
  | Number _ ->
      report cx f.nloc (Msg.not_a_function f.id Num);
      bad e
  | Function f -> (
      match
        Builtins.check b f e.loc (List.map (fun (a : expr) -> (a.ty, a.loc)) args)
      with
      | Ok ty -> mk e (Call_builtin (b, f, args)) ty
      | Error (loc, msg) ->
          report cx loc msg;
          bad e)

(* [material] checks a material block: the blocks' checking is below. *)
let rec expr ~material cx env (e : A.expr) : expr =
  let before = cx.count in
  let te = expr_ ~material cx env e in
  (* What a mistake was found in is not known, nor reported again where it is used. *)
  if cx.count > before || not cx.types then { te with ty = Unknown } else te

and expr_ ~material cx env (e : A.expr) =
  match e.e with
  | Num x -> mk e (Const (VNum x)) Num
  | Str s -> mk e (Const (VStr s)) Str
  | Bool b -> mk e (Const (Value.vbool b)) Bool
  | Var x ->
      let { var; ty } = lookup cx env x e.loc in
      mk e (Var var) ty
  | Vec (a, b, c) ->
      let ta = expr ~material cx env a
      and tb = expr ~material cx env b
      and tc = expr ~material cx env c in
      let component t = refused cx t (is Num) Msg.component in
      if component ta || component tb || component tc then bad e
      else mk e (Vec (ta, tb, tc)) Vec
  | Pair (a, b) ->
      let ta = expr ~material cx env a and tb = expr ~material cx env b in
      mk e (Pair (ta, tb)) (Pair (ta.ty, tb.ty))
  | Binop (((And | Or) as op), a, b) ->
      (* An operand of the wrong type fails where it is evaluated: the right one only
         where the left does not decide. *)
      let operand x =
        let t = expr ~material cx env x in
        if refused cx t (is Bool) (Msg.needs_booleans op) then { t with e = Bad } else t
      in
      let ta = operand a in
      let tb = operand b in
      mk e (Binop (op, ta, tb)) (if is ta.ty Bool && is tb.ty Bool then Bool else Unknown)
  | Binop (op, a, b) -> (
      let ta = expr ~material cx env a and tb = expr ~material cx env b in
      if not (Ty.known ta.ty && Ty.known tb.ty) then mk e (Binop (op, ta, tb)) Unknown
      else
        match Ops.binop_type op ta.ty tb.ty with
        | Some ty -> mk e (Binop (op, ta, tb)) ty
        | None ->
            report cx e.loc (Msg.cannot_combine op ta.ty tb.ty);
            bad e)
  | Unop (op, a) -> (
      let ta = expr ~material cx env a in
      let typ, msg =
        match op with
        | Neg -> (Ops.neg_type, Msg.neg_needs)
        | Not -> (Ops.not_type, Msg.not_needs)
      in
      match (Ty.known ta.ty, typ ta.ty) with
      | false, _ -> mk e (Unop (op, ta)) Unknown
      | true, Some ty -> mk e (Unop (op, ta)) ty
      | true, None ->
          report cx e.loc (msg ta.ty);
          bad e)
  | Dot (a, f) -> (
      let ta = expr ~material cx env a in
      let wrong msg =
        report cx f.nloc msg;
        bad e
      in
      match (ta.ty, f.id) with
      | Unknown, _ -> mk e (Dot (ta, f)) Unknown
      | Vec, ("x" | "y" | "z") -> mk e (Dot (ta, f)) Num
      | Vec, x -> wrong (Msg.vector_component x)
      | Body, ("position" | "velocity") -> mk e (Dot (ta, f)) Vec
      | Body, x -> wrong (Msg.body_member x)
      | t, x -> wrong (Msg.dot_needs x t))
  | Call (f, args) -> (
      let targs = List.map (expr ~material cx env) args in
      let { var; ty } = lookup cx env f.id f.nloc in
      match (var, ty) with
      | Global b, _ -> builtin_call cx e f b targs
      | _, Builtin name -> builtin_call cx e f (Option.get (Builtins.find name)) targs
      | _, Fun n ->
          if List.length targs <> n then (
            report cx e.loc (Msg.arity f.id n (List.length targs));
            bad e)
          else mk e (Call ({ e = Var var; ty; loc = f.nloc }, f, targs)) Unknown
      | _, Macro _ ->
          report cx f.nloc (Msg.macro_in_expression f.id);
          bad e
      | _, Unknown -> mk e (Call ({ e = Var var; ty; loc = f.nloc }, f, targs)) Unknown
      | _, t ->
          report cx f.nloc (Msg.not_a_function f.id t);
          bad e)
  | If (c, a, b) ->
      let tc = expr ~material cx env c in
      let wrong = refused cx tc (is Bool) Msg.condition in
      let ta = expr ~material cx env a and tb = expr ~material cx env b in
      if wrong then bad e
      else mk e (If (tc, ta, tb)) (if is ta.ty tb.ty then ta.ty else Unknown)
  | Material items -> mk e (Material (material cx env e.loc items)) Mat
  | List es -> (
      let tes = List.map (expr ~material cx env) es in
      match Ops.list_type (List.map (fun (t : expr) -> (t.ty, t.loc)) tes) with
      | Ok ty -> mk e (List tes) ty
      | Error (loc, msg) ->
          report cx loc msg;
          bad e)
  | Index (a, i) ->
      (* The list's mistake first: the evaluation finds it first. *)
      let ta = expr ~material cx env a in
      let ti = expr ~material cx env i in
      if
        refused cx ta Ops.is_list Msg.index_needs || refused cx ti (is Num) Msg.index_type
      then bad e
      else mk e (Index (ta, ti)) (Ops.element ta.ty)

(* ------------------------------------------------------------------------------------ *)
(* Blocks *)

(* The kinds a keyword stands for: none for a keyword that is no block's. *)
let kinds cx kw =
  match cx.last_kinds with
  | k, kinds when k == kw -> kinds
  | _ ->
      let kinds = Option.value (Keywords.find_opt cx.kinds kw) ~default:[] in
      cx.last_kinds <- (kw, kinds);
      kinds

(* The kind a block of these [kinds] (a keyword's) is, given the fields written. *)
let choose kinds present =
  match kinds with
  | [ k ] -> Some k
  | ks -> (
      match
        List.filter
          (fun (k : Kind.t) ->
            match k.block.chosen_by with Some n -> present n | None -> false)
          ks
      with
      | [ k ] -> Some k
      | _ -> None)

(* A field given where the block's kind (or the field it depends on) says it does not
   apply: the message, and whether it is shown at the field's name or at its value. *)
let misplaced id name =
  match (id, name) with
  | "point_light", ("inner" | "outer") -> Some (`Name, Msg.spot_only name)
  | "camera", "width" -> Some (`Value, Msg.width_not_orthographic)
  | "camera", "fov" -> Some (`Value, Msg.orthographic_fov)
  | "animation", "duration" -> Some (`Value, Msg.frames_or_duration)
  | _ -> None

let missing id keyword name =
  match (id, name) with
  | "camera", "width" -> Msg.orthographic_width
  | _ -> Msg.needs_field keyword name

(* The block's kind, when its [kind] field is left out or written as one of its choices. *)
let literal_kind (k : Kind.t) given =
  match k.kind with
  | -1 -> `None
  | i -> (
      let fields = k.named.(i) in
      let choices =
        List.concat_map
          (fun (fl : Schema.field) -> match fl.ty with Choice l -> l | _ -> [])
          fields
      in
      match List.find_opt (fun ((n : A.name), _) -> n.id = "kind") given with
      | Some (_, ({ e = A.Str s; _ } : A.expr)) when List.mem s choices -> `Known s
      | Some _ -> `Unknown
      | None -> (
          match fields with
          | { default = Value v; _ } :: _ when String.length v >= 2 ->
              `Known (String.sub v 1 (String.length v - 2))
          | _ -> `None))

(* Where each field of a block of kind [b] goes, from the fields written alone (each once:
   those given twice are left out), and the fields the block needs. A field the block
   does not take, there or at all, is reported and dropped: its value is neither checked
   nor run. The entry each other field's value is checked against ([None]: one that
   depends on a kind known only when the program runs). *)
let places cx (k : Kind.t) ~keyword kloc (given : (A.name * A.expr) list) =
  let b = k.block in
  let failed = ref false in
  let report loc msg =
    failed := true;
    report cx loc msg
  in
  let present name =
    List.exists (fun ((n : A.name), _) -> String.equal n.id name) given
  in
  let kind = literal_kind k given in
  let applies (fl : Schema.field) =
    match fl.condition with
    | Always -> true
    | With n -> present n
    | Without n -> not (present n)
    | Kind_in ks -> (
        match kind with `Known k -> List.exists (String.equal k) ks | _ -> false)
  in
  (* Surely not: its kind, or the field it depends on, is known and says so. *)
  let excluded (fl : Schema.field) =
    match fl.condition with
    | Always -> false
    | With n -> not (present n)
    | Without n -> present n
    | Kind_in ks -> (
        match kind with `Known k -> not (List.exists (String.equal k) ks) | _ -> false)
  in
  let place ((n : A.name), (v : A.expr)) =
    match Kind.slot k n.id with
    | -1 ->
        report n.nloc
          (Msg.unknown_field n.id keyword (Msg.hint n.id (Array.to_list k.names)));
        (Dropped, None)
    | i -> (
        let entries = k.named.(i) in
        match List.find_opt applies entries with
        | Some fl -> ((if fl.repeats then Step n.id else Slot i), Some fl)
        | None when List.for_all excluded entries ->
            (match misplaced b.id n.id with
            | Some (at, msg) -> report (if at = `Name then n.nloc else v.loc) msg
            | None -> failed := true);
            (Dropped, None)
        | None -> (Slot i, None))
  in
  let places = List.map place given in
  List.iter
    (fun (fl : Schema.field) ->
      if
        (match fl.default with Required -> true | _ -> false)
        && applies fl
        && not (present fl.name)
      then
        (* A misspelt field already reported as unknown, with this one as its hint, is
           not reported missing as well (a field of the block's own does not stand for a
           missing one: a triangle's `b` is not a missing `c`). *)
        let misspelt =
          (match fl.condition with Always -> true | _ -> false)
          && List.exists
               (fun ((n : A.name), _) ->
                 Kind.slot k n.id < 0 && Msg.suggest n.id [ fl.name ] = Some fl.name)
               given
        in
        if misspelt then failed := true else report kloc (missing b.id keyword fl.name))
    b.fields;
  (places, !failed, match kind with `Unknown -> false | _ -> true)

let repeatable = function "translate" | "rotate" | "scale" -> true | _ -> false

(* The block's fields as written, each once (those given twice reported), and whether a
   statement it does not hold was found (reported). *)
let written cx ~holds kw items =
  let failed = ref false and seen = ref [] and fields = ref [] in
  List.iter
    (function
      | A.Field (n, e) -> (
          match List.find_opt (fun (x, _) -> String.equal x n.id) !seen with
          | Some (_, line) when not (repeatable n.id) ->
              failed := true;
              report cx n.nloc (Msg.given_twice n.id kw line)
          | first ->
              if Option.is_none first then seen := (n.id, n.nloc.line) :: !seen;
              fields := (n, e) :: !fields)
      | A.Stmt s -> (
          match s.s with
          | Let _ | Fn _ | Macro _ -> ()
          | _ when holds -> ()
          | _ ->
              failed := true;
              let inner = match s.s with Block (k, _) -> Some k.id | _ -> None in
              report cx s.sloc (Msg.holds_only_fields ?inner kw)))
    items;
  (List.rev !fields, !failed)

(* A block's items in order: its fields' values (checked against their fields), its
   statements (a [let] is seen by the items after it). [stmt] checks a statement. *)
let rec block cx env ~stmt ~where ~(keyword : A.name) kloc items : block =
  let kw = keyword.id in
  let kinds = kinds cx kw in
  let holds = List.exists (fun (k : Kind.t) -> k.block.holds_objects) kinds in
  let inner = if holds then Inside else where in
  let given, mistaken = written cx ~holds kw items in
  let present name = List.exists (fun ((n : A.name), _) -> n.id = name) given in
  let names = List.map (fun ((n : A.name), _) -> n.id) given in
  (* What the places depend on, the names alone: not the value of a [kind]. *)
  let key = if List.exists (String.equal "kind") names then None else Some (kw, names) in
  let kind, places, failed, kind_known =
    match Option.bind key (Written.find_opt cx.placed) with
    | Some (b, places, k) -> (b, places, false, k)
    | None -> (
        match choose kinds present with
        | Some b ->
            let before = cx.count in
            let places, failed, k = places cx b ~keyword:kw kloc given in
            (match key with
            | Some key when cx.count = before && not failed ->
                Written.replace cx.placed key (b, places, k)
            | _ -> ());
            (b, places, failed, k)
        | None ->
            (* A light whose fields do not say which: none of them is read. *)
            (match List.find_opt (fun ((n : A.name), _) -> n.id = "direction") given with
            | Some (_, v) when present "position" -> report cx v.loc Msg.light_choice_both
            | _ -> report cx kloc Msg.light_choice_none);
            ( List.find
                (fun (k : Kind.t) -> k.block.id = "point_light")
                (Keywords.find cx.kinds "light"),
              List.map (fun _ -> (Dropped, None)) given,
              true,
              true ))
  in
  let failed = ref (failed || mistaken) in
  let places = ref (List.combine given places) in
  let _, rev =
    List.fold_left
      (fun (env, acc) item ->
        match item with
        | A.Field (n, e) -> (
            match !places with
            | ((n', _), (slot, fl)) :: rest when n' == n ->
                places := rest;
                let field v wrong = Field { name = n; value = v; slot; wrong } in
                if match slot with Dropped -> true | _ -> false then
                  (env, field (bad e) false :: acc)
                else
                  let v = expr ~material:(material_block ~stmt) cx env e in
                  let wrong =
                    match fl with
                    | Some (fl : Schema.field)
                      when Ty.known v.ty && not (Ty.accepts fl.ty v.ty) ->
                        report cx v.loc (Msg.field_type fl v.ty);
                        true
                    | _ -> false
                  in
                  if wrong then failed := true;
                  (env, field (if wrong then { v with e = Bad } else v) wrong :: acc)
            | _ -> (env, acc) (* given twice *))
        | A.Stmt s -> (
            match s.s with
            | Let _ | Fn _ | Macro _ ->
                let env, ts = stmt cx env ~where:inner s in
                (env, Stmts ts :: acc)
            | _ when holds ->
                let env, ts = stmt cx env ~where:inner s in
                (env, Stmts ts :: acc)
            | _ -> (env, acc)))
      (env, []) items
  in
  { keyword; kind; items = List.rev rev; failed = !failed; kind_known; where }

and material_block ~stmt cx env loc items =
  block cx env ~stmt ~where:Top ~keyword:{ id = "material"; nloc = loc } loc items

(* ------------------------------------------------------------------------------------ *)
(* Statements *)

(* Whether a parameter is named twice (reported, at the first of the two). *)
let params_twice cx (ps : A.name list) =
  let rec dup = function
    | [] -> false
    | (p : A.name) :: rest ->
        if List.exists (fun (q : A.name) -> q.id = p.id) rest then (
          report cx p.nloc (Msg.param_twice p.id);
          true)
        else dup rest
  in
  dup ps

(* The scope of a function's body: its parameters, one level down. *)
let params cx env (ps : A.name list) =
  let inner = { env with level = env.level + 1 } in
  let env, bs =
    List.fold_left
      (fun (env, bs) (p : A.name) ->
        let b = binding cx inner p in
        (bind env p.id (Local b) Unknown, b :: bs))
      (inner, []) ps
  in
  (env, List.rev bs)

let rec stmts cx env ~where ss =
  let env, rev =
    List.fold_left
      (fun (env, acc) s ->
        let env, ts = stmt cx env ~where s in
        (env, List.rev_append ts acc))
      (env, []) ss
  in
  (env, List.rev rev)

and stmt cx env ~where (s : A.stmt) : env * Tast.stmt list =
  let one d = [ { s = d; sloc = s.sloc } ] in
  let expr = expr ~material:(material_block ~stmt) cx in
  let unknown (t : Ty.t) = if cx.types then t else Unknown in
  match s.s with
  | Let (x, e) ->
      let te = expr env e in
      let b = binding cx env x in
      (bind env x.id (Local b) te.ty, one (Let (b, te)))
  | Fn (f, ps, body) ->
      let env, d =
        definition cx env f ps
          (fun n -> Fun n)
          (fun benv -> expr benv body)
          (fun b def te -> Fn (b, def, te))
      in
      (env, one d)
  | Macro (f, ps, body) ->
      let where = if where = Inside then Inside else Either in
      let env, d =
        definition cx env f ps
          (fun n -> Macro n)
          (fun benv -> snd (stmts cx benv ~where body))
          (fun b def tbody -> Macro (b, def, tbody))
      in
      (env, one d)
  | For (x, a, b, st, body) ->
      let bound what (e : A.expr) =
        let te = expr env e in
        if refused cx te (is Num) (Msg.loop_bound what) then { te with e = Bad } else te
      in
      let ta = bound "start" a in
      let tb = bound "end" b in
      let tst = Option.map (bound "step") st in
      let bx = binding cx env x in
      let _, tbody = stmts cx (bind env x.id (Local bx) (unknown Num)) ~where body in
      (env, one (For (bx, ta, tb, tst, tbody)))
  | For_each (x, l, body) ->
      let tl = expr env l in
      let tl =
        if refused cx tl Ops.is_list Msg.for_each_needs then { tl with e = Bad } else tl
      in
      let bx = binding cx env x in
      let _, tbody =
        stmts cx (bind env x.id (Local bx) (unknown (Ops.element tl.ty))) ~where body
      in
      (env, one (For_each (bx, tl, tbody)))
  | If_stmt (c, t, e) ->
      let tc = expr env c in
      let tc =
        if refused cx tc (is Bool) Msg.condition then { tc with e = Bad } else tc
      in
      let _, tt = stmts cx env ~where t in
      let _, te = stmts cx env ~where e in
      (env, one (If_stmt (tc, tt, te)))
  | Include _ -> (env, one Nothing)
  | Included (_, ss) -> stmts cx env ~where ss
  | Call_stmt (f, args) -> (
      let targs = List.map (expr env) args in
      let { var; ty } = lookup cx env f.id f.nloc in
      let refuse loc msg =
        report cx loc msg;
        (env, one Nothing)
      in
      match (var, ty) with
      | _, Macro n when List.length targs <> n ->
          refuse s.sloc (Msg.arity f.id n (List.length targs))
      | _, (Macro _ | Unknown) ->
          (env, one (Call_stmt ({ e = Var var; ty; loc = f.nloc }, f, targs)))
      | _, Fun _ -> refuse f.nloc (Msg.function_as_statement f.id)
      | _, Builtin _ -> refuse f.nloc (Msg.builtin_as_statement f.id)
      | _, t -> refuse f.nloc (Msg.not_a_macro f.id t))
  | Block (k, items) -> (
      (match k.id with
      | "animation" | "physics" -> cx.moving <- true
      | "camera" ->
          if
            List.exists
              (function A.Field (n, _) -> n.id = "shutter" | A.Stmt _ -> false)
              items
          then cx.moving <- true
      | _ -> ());
      match k.id with
      | "material" ->
          report cx k.nloc Msg.material_statement;
          (env, one Nothing)
      | kw when List.is_empty (kinds cx kw) || kw = "body" ->
          report cx k.nloc (Msg.unknown_block kw);
          (env, one Nothing)
      | ("settings" | "camera" | "animation" | "physics" | "light") when where = Inside ->
          report cx k.nloc (Msg.top_level_only k.id);
          (env, one Nothing)
      | _ -> (env, one (Block (block cx env ~stmt ~where ~keyword:k k.nloc items))))
  | Body (n, items) ->
      cx.moving <- true;
      let before = Names.find_opt n.id env.names in
      let b = binding cx env n in
      let tb =
        if where = Inside then (
          report cx n.nloc Msg.body_in_group;
          None)
        else
          Some
            (block cx env ~stmt ~where
               ~keyword:{ id = "body"; nloc = n.nloc }
               n.nloc items)
      in
      let ty : Ty.t =
        match before with
        | None -> Body
        | Some e when is e.ty Body -> Body
        | Some _ -> Unknown
      in
      ( bind env n.id (Maybe (b, fun () -> "")) (unknown ty),
        one (Body (b, Option.map (fun e -> e.var) before, tb)) )

(* A function or a macro [f] with parameters [ps] (its type [ty] of their count): its body
   checked by [body] in its scope, and the statement [make] makes of it. A parameter named
   twice poisons the definition. *)
and definition :
    'a.
    cx ->
    env ->
    A.name ->
    A.name list ->
    (int -> Ty.t) ->
    (env -> 'a) ->
    (binding -> fn_def -> 'a -> sdesc) ->
    env * sdesc =
 fun cx env f ps ty body make ->
  let b = binding cx env f in
  let dup = params_twice cx ps in
  let fty = if dup || not cx.types then Ty.Unknown else ty (List.length ps) in
  let env' = bind env f.id (Local b) fty in
  let benv, pbs = params cx env' ps in
  let tbody = body benv in
  ( env',
    if dup then Poisoned_fn b
    else make b { fname = f.id; params = pbs; level = env.level + 1 } tbody )

type state = { cx : cx; mutable env : env }

let start ?(schema = Schema.blocks) ?(types = true) ~sources () =
  let kinds = Keywords.create 32 in
  List.iter
    (fun (b : Schema.block) ->
      let k = Kind.get b in
      Keywords.replace kinds b.keyword
        (Option.value (Keywords.find_opt kinds b.keyword) ~default:[] @ [ k ]))
    schema;
  {
    cx =
      {
        sources;
        kinds;
        types;
        errors = [];
        count = 0;
        next = 0;
        definitions = [];
        placed = Written.create 16;
        last_kinds = ("", []);
        moving = false;
      };
    env = initial;
  }

let top st s =
  st.cx.definitions <- definitions st.cx.definitions [ s ];
  let env, ts = stmt st.cx st.env ~where:Top s in
  st.env <- env;
  ts

let finish st = (st.cx.next, List.rev st.cx.errors)
let moving st = st.cx.moving

let program ?schema ?types ~sources stmts =
  let st = start ?schema ?types ~sources () in
  let ts = List.concat_map (top st) stmts in
  let bindings, errors = finish st in
  ({ stmts = ts; bindings }, errors)
