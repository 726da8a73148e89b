open Value
open Tast

type scode = frame -> scope -> unit
type t = { stmts : scode array; slots : int }

(* A statement that fails is reported and skipped. *)
let guard code : scode =
 fun fr sc -> try code fr sc with Fail (l, m) -> State.report fr.st l m | Poisoned -> ()

(* ... and a name it defines is poisoned: its uses give up quietly. *)
let guard_slot i code : scode =
 fun fr sc ->
  try code fr sc with
  | Fail (l, m) ->
      State.report fr.st l m;
      fr.l.(i) <- VPoison
  | Poisoned -> fr.l.(i) <- VPoison

let untyped what = invalid_arg ("Compile: " ^ what ^ " of a type not checked")

(* ------------------------------------------------------------------------------------ *)
(* What a list of statements builds *)

let block_stmts blk =
  List.concat_map (function Stmts ss -> ss | Field _ -> []) blk.items

let rec objects_written stmts =
  List.fold_left
    (fun n (s : stmt) ->
      n
      +
      match s.s with
      | Block blk when Schema.is_shape blk.keyword.id -> 1
      | Block
          ({
             keyword =
               { id = "group" | "union" | "merge" | "intersection" | "difference"; _ };
             _;
           } as blk) ->
          objects_written (block_stmts blk)
      | If_stmt (_, t, e) -> min (objects_written t) (objects_written e)
      | _ -> 0)
    0 stmts

(* Whether a statement may start a loop (its own, or a macro's): only then do the loops
   around it keep count of the iterations they have left. *)
let rec may_loop (s : stmt) =
  match s.s with
  | For _ | For_each _ | Call_stmt _ -> true
  | If_stmt (_, t, e) -> List.exists may_loop t || List.exists may_loop e
  | Block blk | Body (_, _, Some blk) -> List.exists may_loop (block_stmts blk)
  | _ -> false

(* ------------------------------------------------------------------------------------ *)
(* Blocks: their items evaluated in order, their fields read by [Build] *)

type item = CSlot of int * Cexpr.code | CStep of int * Cexpr.code | CStmt of scode

type site = {
  site : Fields.site;
  items : item array;
  nslots : int;  (** the slots an evaluation holds: up to the last field given *)
  nsteps : int;
  kloc : Loc.t;
  fields : (int * Cexpr.code) array option;
      (** where the block is only fields (no transform, no statement): each one's slot and
          code *)
}

let[@inline] value c fr =
  try c fr with
  | Fail (l, m) ->
      State.report fr.st l m;
      VPoison
  | Poisoned -> VPoison

(* [n] values not given yet. Blocks have a few fields: an array written out is made
   where it is used ([Array.make] is a call into the runtime, and an array of constants a
   copy of one), so its elements are not a constant. *)
let[@inline] unset n =
  let p = Sys.opaque_identity VPoison in
  match n with
  | 0 -> [||]
  | 1 -> [| p |]
  | 2 -> [| p; p |]
  | 3 -> [| p; p; p |]
  | 4 -> [| p; p; p; p |]
  | 5 -> [| p; p; p; p; p |]
  | 6 -> [| p; p; p; p; p; p |]
  | 7 -> [| p; p; p; p; p; p; p |]
  | 8 -> [| p; p; p; p; p; p; p; p |]
  | n -> Array.make n p

(* One evaluation of a block: its fields' values (a failed one poisoned, and the block
   failed), its statements run in [inner]. *)
let evaluate s fr inner =
  let vals = unset s.nslots in
  let failed = ref false in
  let svals =
    match s.fields with
    | Some fields ->
        for k = 0 to Array.length fields - 1 do
          let i, c = fields.(k) in
          let v = value c fr in
          if v == VPoison then failed := true;
          vals.(i) <- v
        done;
        [||]
    | None ->
        let svals = unset s.nsteps in
        for k = 0 to Array.length s.items - 1 do
          match s.items.(k) with
          | CSlot (i, c) ->
              let v = value c fr in
              if v == VPoison then failed := true;
              vals.(i) <- v
          | CStep (j, c) ->
              let v = value c fr in
              if v == VPoison then failed := true;
              svals.(j) <- v
          | CStmt c -> c fr inner
        done;
        svals
  in
  let b = Fields.make s.site fr.st.tell vals svals in
  if !failed then b.failed <- true;
  b

let top_level (blk : block) code : scode =
  match blk.where with
  | Either ->
      let k = blk.keyword in
      fun fr sc ->
        if sc.in_group then fail k.nloc (Msg.top_level_only k.id);
        code fr sc
  | Top | Inside -> code

(* A setting of the run that may be given once. *)
let once what (blk : block) get set build s : scode =
  let kloc = blk.keyword.nloc in
  top_level blk (fun fr sc ->
      (match get fr.st.out with Some (_, l) -> fail kloc (Msg.once what l) | None -> ());
      match build (evaluate s fr sc) with
      | Some x -> set fr.st.out (Some (x, kloc))
      | None -> ())

let csg s ~keyword fr (sc : scope) =
  let members = ref [] in
  let b = evaluate s fr { sink = members; emit = None; in_group = true; in_csg = true } in
  match Build.csg b ~keyword ~loc:s.kloc ~in_csg:sc.in_csg (List.rev !members) with
  | Some o -> State.add_object fr.st sc s.kloc o
  | None -> ()

let group s fr sc =
  let members = ref [] in
  let b =
    evaluate s fr { sink = members; emit = None; in_group = true; in_csg = false }
  in
  let t, tj = Build.transforms b in
  let mat = Build.object_material b in
  if not b.failed then
    match sc.emit with
    | None -> sc.sink := Build.group_members t tj mat !members !(sc.sink)
    | Some _ ->
        List.iter (State.put sc) (List.rev (Build.group_members t tj mat !members []))

(* The statements of a material block (lets) build nothing: one scope serves them all. *)
(* A material's block builds no object: its scope's sink stays empty. *)
let no_objects = { sink = ref []; emit = None; in_group = false; in_csg = false }

(* What reading a block of constants when it is compiled may not do: find a mistake, or
   name a file (the run reports it, and the file is read as it runs). *)
exception Not_constant

let refuses =
  {
    report = (fun _ _ -> raise_notrace Not_constant);
    use = (fun _ -> raise_notrace Not_constant);
    share = (fun m -> Some m);
  }

(* A material block of constants is one material, when it has no mistake. *)
let constant_material site (items : item array) consts mat =
  if Array.exists (function CSlot _ -> false | _ -> true) items then None
  else
    let ok = ref true in
    let vals = Array.make (Array.length consts) VPoison in
    Array.iter
      (function
        | CSlot (i, _) -> (
            match consts.(i) with Some v -> vals.(i) <- v | None -> ok := false)
        | _ -> ())
      items;
    if not !ok then None
    else
      let b = Fields.make site refuses vals [||] in
      match mat b with
      | m when Fields.finish b -> Some m
      | _ | (exception Not_constant) -> None

(* A shape block of constants (its material aside, of a type the checker knew) is its
   object, made once when it is compiled, when it has no mistake: each evaluation makes a
   copy with the material. The material's code, if it has one. *)
let folded_object s (blk : block) (values, steps) =
  let m = blk.kind.material in
  let n = Array.length values in
  let vals = Array.make n VPoison in
  let constant = ref (not blk.failed) in
  for i = 0 to n - 1 do
    match values.(i) with
    | Some ((e : expr), _) when i = m -> if not (Ty.equal e.ty Mat) then constant := false
    | Some (_, Some v) -> vals.(i) <- v
    | Some (_, None) -> constant := false
    | None -> ()
  done;
  let svals =
    Array.map
      (function
        | _, Some v -> v
        | _, None ->
            constant := false;
            VPoison)
      steps
  in
  if (not !constant) || Array.exists (function CStmt _ -> true | _ -> false) s.items
  then None
  else
    (* Its material not read: its value is not there, as if it had failed. *)
    let b = Fields.make s.site refuses vals svals in
    match Build.object_ s.site b with
    | o when Fields.finish b ->
        let code =
          Array.fold_left
            (fun acc -> function CSlot (i, c) when i = m -> Some c | _ -> acc)
            None s.items
        in
        Some (o, code)
    | _ | (exception Not_constant) -> None

(* ------------------------------------------------------------------------------------ *)
(* Statements *)

let body_code s ~name ~(where : where) ~nloc ~sloc fr (sc : scope) =
  if where = Either && sc.in_group then fail nloc Msg.body_in_group;
  let out = fr.st.out in
  if List.exists (fun ((b : Description.body), _) -> b.name = name) out.bodies then
    fail nloc (Msg.body_twice name);
  let members = ref [] in
  let b =
    evaluate s fr { sink = members; emit = None; in_group = true; in_csg = false }
  in
  match Build.body b ~name ~loc:sloc ~at:nloc !members with
  | None -> raise Poisoned
  | Some r -> (
      fr.st.count.objects <- fr.st.count.objects - List.length !members;
      match r with Error (l, m) -> fail l m | Ok bo -> out.bodies <- bo :: out.bodies)

(* [count] runs of a loop's body [cbody], its name in [slot] being [value k] in the k-th
   (the loops around it told how many are left, when the body may start loops). *)
let iterate sloc ~count ~nests slot value cbody fr sc =
  let c = fr.st.count in
  let outer = c.loops in
  Fun.protect
    ~finally:(fun () -> c.loops <- outer)
    (fun () ->
      for k = 0 to count - 1 do
        State.step fr.st sloc;
        if nests then c.loops <- outer *. Float.of_int (count - k);
        fr.l.(slot) <- value k;
        cbody fr sc
      done)

let for_loop sloc (na, nb, nst) per_iteration nests slot cbody fr sc =
  let a = na fr in
  let b = nb fr in
  let step = match nst with Some (n, l) -> (n fr, l) | None -> (1., sloc) in
  let step, step_loc = step in
  if step = 0. then fail step_loc Msg.loop_step_zero;
  let count = Float.floor (((b -. a) /. step) +. 1e-9) +. 1. in
  State.loop fr.st sloc ~range:(Some (a, b, step)) ~count ~per_iteration;
  let count = if count < 0. then 0 else int_of_float count in
  iterate sloc ~count ~nests slot
    (fun k -> VNum (a +. (Float.of_int k *. step)))
    cbody fr sc

(* [for x in LIST { … }]: the body run for each element, in order. *)
let for_each sloc lloc cl per_iteration nests slot cbody fr sc =
  match cl fr with
  | VList l ->
      let count = Array.length l in
      State.loop fr.st sloc ~range:None ~count:(Float.of_int count) ~per_iteration;
      iterate sloc ~count ~nests slot (Array.get l) cbody fr sc
  | v -> fail lloc (Msg.for_each_needs (ty v))

(* What a name named before a body took it. *)
let before cs = function
  | Some (Local b | Maybe (b, _)) -> Cexpr.raw (Cexpr.resolve cs b)
  | Some (Global { kind = Number f; _ }) -> fun fr -> f fr.st.hooks
  | Some (Global { name; kind = Function _; _ }) ->
      let v = VBuiltin name in
      fun _ -> v
  | Some (Unbound _) | None -> fun _ -> unbound

let rec expr cs e = Cexpr.expr ~block:material cs e

and items cs (blk : block) =
  let nsteps = ref 0 and n = blk.kind.values in
  let values = Array.make n None and steps = ref [] in
  (* Each value with its constant, if it is one (its code gives it). *)
  let valued value =
    let k = Cexpr.const value in
    ((value, k), match k with Some v -> fun _ -> v | None -> expr cs value)
  in
  let items =
    List.concat_map
      (function
        | Field { slot = Slot i; value; _ } ->
            let v, code = valued value in
            values.(i) <- Some v;
            [ CSlot (i, code) ]
        | Field { slot = Step _; value; _ } ->
            let j = !nsteps in
            incr nsteps;
            let v, code = valued value in
            steps := v :: !steps;
            [ CStep (j, code) ]
        | Field { slot = Dropped; _ } -> []
        | Stmts ss -> List.map (fun s -> CStmt (stmt cs s)) ss)
      blk.items
  in
  let site = Fields.site blk in
  ( {
      site;
      items = Array.of_list items;
      nslots =
        List.fold_left
          (fun w -> function CSlot (i, _) -> max w (i + 1) | _ -> w)
          0 items;
      nsteps = !nsteps;
      fields =
        (let fields =
           List.filter_map (function CSlot (i, c) -> Some (i, c) | _ -> None) items
         in
         if List.compare_lengths fields items = 0 then Some (Array.of_list fields)
         else None);
      kloc = blk.keyword.nloc;
    },
    (values, Array.of_list (List.rev !steps)) )

and material cs blk : Cexpr.code =
  let s, (values, _) = items cs blk in
  let mat = Build.material s.site in
  match
    if blk.failed then None
    else
      constant_material s.site s.items (Array.map (fun v -> Option.bind v snd) values) mat
  with
  | Some v -> fun _ -> v
  | None ->
      fun fr ->
        let b = evaluate s fr no_objects in
        let m = mat b in
        if Fields.finish b then m else raise Poisoned

(* A block statement's code, which reports a failure and skips the block (a shape block
   of constants has none: it is not guarded). *)
and block cs (blk : block) : scode =
  let s, values = items cs blk in
  let kloc = blk.keyword.nloc in
  match blk.keyword.id with
  | "settings" ->
      guard
        (once "settings" blk
           (fun o -> o.settings)
           (fun o v -> o.settings <- v)
           Build.settings s)
  | "camera" ->
      guard
        (once "camera" blk (fun o -> o.camera) (fun o v -> o.camera <- v) Build.camera s)
  | "animation" ->
      guard
        (once "animation" blk
           (fun o -> o.animation)
           (fun o v -> o.animation <- v)
           Build.animation s)
  | "physics" ->
      guard
        (once "physics" blk
           (fun o -> o.physics)
           (fun o v -> o.physics <- v)
           Build.physics s)
  | "light" ->
      guard
        (top_level blk (fun fr sc ->
             match Build.light (evaluate s fr sc) with
             | Some l -> fr.st.out.lights <- l :: fr.st.out.lights
             | None -> ()))
  | "group" ->
      guard (fun fr sc ->
          if sc.in_csg then csg s ~keyword:"group" fr sc else group s fr sc)
  | ("union" | "merge" | "intersection" | "difference") as keyword ->
      guard (csg s ~keyword)
  | _ -> (
      match folded_object s blk values with
      | Some ({ Description.kind; shape; transform; steps; loc; color; _ }, material) -> (
          (* Its parts, not the object: each evaluation makes its own. *)
          match material with
          | None ->
              fun fr sc ->
                State.add_object fr.st sc loc
                  {
                    Description.kind;
                    shape;
                    transform;
                    steps;
                    material = None;
                    color;
                    loc;
                    body = None;
                  }
          | Some c -> (
              fun fr sc ->
                match value c fr with
                | VMat m ->
                    State.add_object fr.st sc loc
                      {
                        Description.kind;
                        shape;
                        transform;
                        steps;
                        material = m.some;
                        color = m.color;
                        loc;
                        body = None;
                      }
                | VPoison -> ()
                | _ -> untyped "a material"))
      | None ->
          let obj = Build.object_ s.site in
          guard (fun fr sc ->
              let b = evaluate s fr sc in
              let o = obj b in
              if Fields.finish b then State.add_object fr.st sc kloc o))

and stmts cs ss : scode =
  match Array.of_list (List.map (stmt cs) ss) with
  | [||] -> fun _ _ -> ()
  | [| c |] -> c
  | a ->
      fun fr sc ->
        for k = 0 to Array.length a - 1 do
          a.(k) fr sc
        done

and func : 'a. Cexpr.t -> fn_def -> (Cexpr.t -> 'a) -> 'a * int * (frame -> Value.t array)
    =
 fun cs def body ->
  let inner = Cexpr.inner cs ~level:def.level ~nparams:(List.length def.params) in
  List.iteri (fun k (p : binding) -> Cexpr.set_slot inner p k) def.params;
  let code = body inner in
  let getters =
    Array.of_list (List.rev_map (fun (_, _, a) -> Cexpr.raw a) inner.fn.caps)
  in
  (code, inner.fn.nslots, fun fr -> Array.map (fun g -> g fr) getters)

and stmt cs (s : stmt) : scode =
  match s.s with
  | Let (b, e) ->
      let c = expr cs e in
      let i = Cexpr.new_slot cs b in
      fun fr _ ->
        fr.l.(i) <-
          (try c fr with
          | Fail (l, m) ->
              State.report fr.st l m;
              VPoison
          | Poisoned -> VPoison)
  | Fn (b, def, body) ->
      let i = Cexpr.new_slot cs b in
      let fbody, fslots, caps = func cs def (fun inner -> expr inner body) in
      let fname = def.fname and nparams = List.length def.params in
      guard_slot i (fun fr _ ->
          let c = { fname; nparams; fbody; fslots; fcaps = [||] } in
          fr.l.(i) <- VFun c;
          c.fcaps <- caps fr)
  | Macro (b, def, body) ->
      let i = Cexpr.new_slot cs b in
      let mbody, mslots, caps = func cs def (fun inner -> stmts inner body) in
      let mname = def.fname and mnparams = List.length def.params in
      guard_slot i (fun fr _ ->
          let m = { mname; mnparams; mbody; mslots; mcaps = [||] } in
          fr.l.(i) <- VMacro m;
          m.mcaps <- caps fr)
  | Poisoned_fn b ->
      let i = Cexpr.new_slot cs b in
      fun fr _ -> fr.l.(i) <- VPoison
  | For (b, a, z, st, body) ->
      let bound what (e : expr) =
        (Cexpr.number e (Msg.loop_bound what) (expr cs e), e.loc)
      in
      let na, _ = bound "start" a and nb, _ = bound "end" z in
      let nst = Option.map (bound "step") st in
      let i = Cexpr.new_slot cs b in
      let cbody = stmts cs body in
      let per_iteration = Float.of_int (objects_written body) in
      let nests = List.exists may_loop body in
      guard (for_loop s.sloc (na, nb, nst) per_iteration nests i cbody)
  | For_each (b, l, body) ->
      let cl = expr cs l in
      let i = Cexpr.new_slot cs b in
      let cbody = stmts cs body in
      let per_iteration = Float.of_int (objects_written body) in
      let nests = List.exists may_loop body in
      guard (for_each s.sloc l.loc cl per_iteration nests i cbody)
  | If_stmt (c, t, e) ->
      let cc = Cexpr.boolean c Msg.condition (expr cs c) in
      let ct = stmts cs t and ce = stmts cs e in
      guard (fun fr sc -> if cc fr then ct fr sc else ce fr sc)
  | Call_stmt (callee, name, args) -> (
      let get = expr cs callee in
      let codes = Array.of_list (List.map (expr cs) args) in
      let loc = s.sloc in
      match callee.ty with
      | Macro _ ->
          guard (fun fr sc ->
              match get fr with
              | VMacro m -> Cexpr.call_macro m codes loc fr sc
              | _ -> untyped name.id)
      | _ ->
          guard (fun fr sc ->
              match get fr with
              | VMacro m -> Cexpr.call_macro m codes loc fr sc
              | VFun c -> fail name.nloc (Msg.function_as_statement c.fname)
              | VBuiltin n -> fail name.nloc (Msg.builtin_as_statement n)
              | v -> fail name.nloc (Msg.not_a_macro name.id (ty v))))
  | Block blk -> block cs blk
  | Body (b, prev, blk) -> (
      let get_before = before cs prev in
      let i = Cexpr.new_slot cs b in
      match blk with
      | None -> fun fr _ -> fr.l.(i) <- get_before fr
      | Some blk -> (
          let s', _ = items cs blk in
          let v = VBody b.name in
          let code =
            body_code s' ~name:b.name ~where:blk.where ~nloc:blk.keyword.nloc ~sloc:s.sloc
          in
          fun fr sc ->
            try
              code fr sc;
              fr.l.(i) <- v
            with
            | Fail (l, m) ->
                State.report fr.st l m;
                fr.l.(i) <- get_before fr
            | Poisoned -> fr.l.(i) <- get_before fr))
  | Nothing -> fun _ _ -> ()

type state = { cs : Cexpr.t; mutable codes : scode list }

let start () = { cs = Cexpr.create (); codes = [] }
let top st s = st.codes <- stmt st.cs s :: st.codes
let finish st = { stmts = Array.of_list (List.rev st.codes); slots = st.cs.fn.nslots }

let program (p : Check.program) =
  let st = start () in
  List.iter (top st) p.stmts;
  finish st
