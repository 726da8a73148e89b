open Value
open Tast

type code = frame -> Value.t
type access = Slot of int | Cap of int

type fn = {
  level : int;
  mutable nslots : int;
  mutable caps : (int * int * access) list;
  mutable ncaps : int;
  parent : fn option;
}

type slots = {
  mutable a : int array;
  mutable reads : code option array;
      (** the code that reads a slot of the frame, by slot: one for all its uses *)
}

type t = { slots : slots; fn : fn }

let create () =
  {
    slots = { a = Array.make 64 (-1); reads = [||] };
    fn = { level = 0; nslots = 0; caps = []; ncaps = 0; parent = None };
  }

let set_slot cs (b : binding) i =
  let s = cs.slots in
  if b.id >= Array.length s.a then (
    let a = Array.make (max (2 * Array.length s.a) (b.id + 1)) (-1) in
    Array.blit s.a 0 a 0 (Array.length s.a);
    s.a <- a);
  s.a.(b.id) <- i

let inner cs ~level ~nparams =
  { cs with fn = { level; nslots = nparams; caps = []; ncaps = 0; parent = Some cs.fn } }

let new_slot cs (b : binding) =
  let i = cs.fn.nslots in
  cs.fn.nslots <- i + 1;
  set_slot cs b i;
  i

let rec resolve_in slots fn (b : binding) =
  if b.level = fn.level then Slot slots.a.(b.id)
  else
    match List.find_opt (fun (id, _, _) -> id = b.id) fn.caps with
    | Some (_, i, _) -> Cap i
    | None -> (
        match fn.parent with
        | None -> invalid_arg ("Cexpr: " ^ b.name ^ " is defined nowhere around")
        | Some p ->
            let around = resolve_in slots p b in
            let i = fn.ncaps in
            fn.caps <- (b.id, i, around) :: fn.caps;
            fn.ncaps <- i + 1;
            Cap i)

let resolve cs b = resolve_in cs.slots cs.fn b
let raw = function Slot i -> fun fr -> fr.l.(i) | Cap i -> fun fr -> fr.c.(i)

(* A value the checker knew the type of, and that has another: compiled code is wrong. *)
let untyped what = invalid_arg ("Cexpr: " ^ what ^ " of a type not checked")

(* The value in slot [i] of the frame (a scene names the same few things again and again:
   one closure serves them all). *)
let read_slot cs i : code =
  let s = cs.slots in
  if i >= Array.length s.reads then (
    let a = Array.make (max 16 (2 * (i + 1))) None in
    Array.blit s.reads 0 a 0 (Array.length s.reads);
    s.reads <- a);
  match s.reads.(i) with
  | Some c -> c
  | None ->
      let c fr = match fr.l.(i) with VPoison -> raise Poisoned | v -> v in
      s.reads.(i) <- Some c;
      c

let var cs v (loc : Loc.t) : code =
  match v with
  | Local b -> (
      match resolve cs b with
      | Slot i -> read_slot cs i
      | Cap i -> ( fun fr -> match fr.c.(i) with VPoison -> raise Poisoned | v -> v))
  | Maybe (b, msg) -> (
      let get = raw (resolve cs b) in
      fun fr ->
        match get fr with
        | VPoison -> raise Poisoned
        | v when v == unbound -> fail loc (msg ())
        | v -> v)
  | Global { kind = Number f; _ } -> fun fr -> f fr.st.hooks
  | Global { name; kind = Function _; _ } ->
      let v = VBuiltin name in
      fun _ -> v
  | Unbound msg -> fun _ -> fail loc (msg ())

let rec const (e : expr) =
  match e.e with
  | Const v -> Some v
  | Unop (Neg, { e = Const (VNum x); _ }) -> Some (VNum (-.x))
  | Vec (a, b, c) -> (
      match (const a, const b, const c) with
      | Some (VNum x), Some (VNum y), Some (VNum z) -> Some (VVec { x; y; z })
      | _ -> None)
  | _ -> None

(* ------------------------------------------------------------------------------------ *)
(* Calls *)

(* The locals of a call of [name] (its [nparams] parameters first, [nslots] in all), its
   arguments evaluated in the caller's frame, in order. *)
let call_frame name nparams nslots (args : code array) loc fr =
  let na = Array.length args in
  if nparams <> na then fail loc (Msg.arity name nparams na);
  let l = Array.make nslots VPoison in
  for k = 0 to na - 1 do
    l.(k) <- args.(k) fr
  done;
  l

let call_fun (c : closure) (args : code array) loc fr =
  let l = call_frame c.fname c.nparams c.fslots args loc fr in
  let st = fr.st in
  State.enter st loc;
  match c.fbody { l; c = c.fcaps; st } with
  | v ->
      State.leave st;
      v
  | exception e ->
      State.leave st;
      raise e

let call_macro (m : macro) (args : code array) loc fr sc =
  let l = call_frame m.mname m.mnparams m.mslots args loc fr in
  let st = fr.st in
  State.enter st loc;
  match m.mbody { l; c = m.mcaps; st } sc with
  | () -> State.leave st
  | exception e ->
      State.leave st;
      raise e

(* A built-in called with arguments of types the checker knew and found right. *)
let builtin_known (b : Builtins.t) (f : Builtins.fn) loc (args : (code * Loc.t) list) :
    code =
  match (f.impl, args) with
  | F1 g, [ (a, _) ] -> (
      fun fr -> match a fr with VNum x -> num loc (g x) | _ -> untyped b.name)
  | Partial (ok, what, g), [ (a, _) ] -> (
      fun fr ->
        match a fr with
        | VNum x when ok x -> num loc (g x)
        | VNum x -> fail loc (Msg.domain b.name what x)
        | _ -> untyped b.name)
  | F2 g, [ (a, _); (c, _) ] -> (
      fun fr ->
        let va = a fr in
        match (va, c fr) with VNum x, VNum y -> num loc (g x y) | _ -> untyped b.name)
  | _ ->
      let args = Array.of_list args in
      fun fr -> Builtins.call b f loc (Array.map (fun (c, l) -> (c fr, l)) args)

(* A built-in called with arguments whose types are known only as it runs: checked then,
   as the checker checks them. *)
let builtin_checked (b : Builtins.t) (f : Builtins.fn) loc (args : (code * Loc.t) list) :
    code =
  let args = Array.of_list args in
  fun fr ->
    let vals = Array.map (fun (c, l) -> (c fr, l)) args in
    match
      Builtins.check b f loc (Array.to_list (Array.map (fun (v, l) -> (ty v, l)) vals))
    with
    | Error (l, msg) -> fail l msg
    | Ok _ -> Builtins.call b f loc vals

let builtin b f loc (args : (code * Tast.expr) list) =
  let coded = List.map (fun (c, (a : expr)) -> (c, a.loc)) args in
  if List.for_all (fun (_, (a : expr)) -> Ty.known a.ty) args then
    builtin_known b f loc coded
  else builtin_checked b f loc coded

(* A call of a value known only as it runs. *)
let dynamic_call (name : Ast.name) get (args : (code * expr) list) loc : code =
  let codes = Array.of_list (List.map fst args) in
  fun fr ->
    match get fr with
    | VBuiltin n -> (
        match Builtins.find n with
        | Some ({ kind = Function f; _ } as b) ->
            builtin_checked b f loc (List.map (fun (c, (a : expr)) -> (c, a.loc)) args) fr
        | _ -> untyped n)
    | VFun c -> call_fun c codes loc fr
    | VMacro m -> fail name.nloc (Msg.macro_in_expression m.mname)
    | v -> fail name.nloc (Msg.not_a_function name.id (ty v))

(* ------------------------------------------------------------------------------------ *)
(* Expressions *)

(* Whether a type is known through and through (no unknown part). *)
let rec complete : Ty.t -> bool = function
  | Unknown -> false
  | List t -> complete t
  | Pair (a, b) -> complete a && complete b
  | _ -> true

(* A list literal of type [ty]: its elements' types checked as it is made, unless the
   checker knew them all (then it found them to be one). *)
let list (elements : (code * expr) list) (ty : Ty.t) : code =
  let codes = Array.of_list (List.map fst elements) in
  if complete ty then fun fr -> VList (Array.map (fun c -> c fr) codes)
  else
    let locs = Array.of_list (List.map (fun (_, (a : expr)) -> a.loc) elements) in
    fun fr -> Ops.list (Array.mapi (fun k c -> (c fr, locs.(k))) codes)

(* Each a function of the frame alone, made once: called as it runs, it is one call. *)
let number (e : expr) msg (c : code) : frame -> float =
  if Ty.known e.ty then fun fr -> match c fr with VNum x -> x | _ -> untyped "a number"
  else fun fr -> match c fr with VNum x -> x | v -> fail e.loc (msg (ty v))

let boolean (e : expr) msg (c : code) : frame -> bool =
  if Ty.known e.ty then fun fr ->
    match c fr with VBool b -> b | _ -> untyped "a boolean"
  else fun fr -> match c fr with VBool b -> b | v -> fail e.loc (msg (ty v))

(* [num]'s check, of the number alone. *)
let[@inline] checked loc r = if r -. r = 0. then r else finite loc r

(* Whether an expression is one [floats] computes on numbers (the checker knew it and its
   operands to be numbers). *)
let arithmetic (e : expr) =
  let num (a : expr) = Ty.equal a.ty Num in
  match e.e with
  | Binop ((Add | Sub | Mul | Div), a, b) -> num a && num b
  | Call_builtin (_, { impl = F1 _ | Partial _; _ }, [ a ]) -> num a
  | Call_builtin (_, { impl = F2 _; _ }, [ a; b ]) -> num a && num b
  | _ -> false

let rec expr ~block cs (e : expr) : code =
  let sub = expr ~block cs in
  match const e with
  | Some v -> fun _ -> v
  | None when arithmetic e ->
      let f = floats ~block cs e in
      fun fr -> VNum (f fr)
  | None -> (
      match e.e with
      | Const v -> fun _ -> v
      | Var v -> var cs v e.loc
      | Vec (a, b, c) when Ty.known a.ty && Ty.known b.ty && Ty.known c.ty ->
          (* Numbers, as the checker made sure: computed as numbers. *)
          let fa = floats ~block cs a and fb = floats ~block cs b in
          let fc = floats ~block cs c in
          fun fr ->
            let x = fa fr in
            let y = fb fr in
            let z = fc fr in
            VVec { x; y; z }
      | Vec (a, b, c) ->
          let na = number a Msg.component (sub a) in
          let nb = number b Msg.component (sub b) in
          let nc = number c Msg.component (sub c) in
          fun fr ->
            let x = na fr in
            let y = nb fr in
            let z = nc fr in
            VVec { x; y; z }
      | Pair (a, b) ->
          let ca = sub a and cb = sub b in
          fun fr ->
            let x = ca fr in
            let y = cb fr in
            VPair (x, y)
      | Unop (Neg, a) -> (
          let ca = sub a and loc = e.loc in
          match a.ty with
          | Num -> (
              fun fr -> match ca fr with VNum x -> VNum (-.x) | _ -> untyped "`-`")
          | _ -> fun fr -> Ops.neg loc (ca fr))
      | Unop (Not, a) ->
          let ca = sub a and loc = e.loc in
          fun fr -> Ops.not_ loc (ca fr)
      | Binop (((And | Or) as op), a, b) -> (
          let ca = sub a and cb = sub b in
          let ba = boolean a (Msg.needs_booleans op) ca in
          let bb = boolean b (Msg.needs_booleans op) cb in
          match op with
          | And -> fun fr -> vbool (ba fr && bb fr)
          | _ -> fun fr -> vbool (ba fr || bb fr))
      | Binop (op, a, b) -> binop ~sub e op a b
      | Dot (a, f) -> dot (sub a) a f
      | Call_builtin (b, f, args) ->
          builtin b f e.loc (List.map (fun a -> (sub a, a)) args)
      | Call (callee, name, args) -> (
          let get = sub callee and args = List.map (fun a -> (sub a, a)) args in
          let loc = e.loc in
          match callee.ty with
          | Fun _ -> (
              let codes = Array.of_list (List.map fst args) in
              fun fr ->
                match get fr with
                | VFun c -> call_fun c codes loc fr
                | _ -> untyped name.id)
          | _ -> dynamic_call name get args loc)
      | If (c, a, b) ->
          let cc = boolean c Msg.condition (sub c) in
          let ca = sub a and cb = sub b in
          fun fr -> if cc fr then ca fr else cb fr
      | Material blk -> block cs blk
      | List es -> list (List.map (fun a -> (sub a, a)) es) e.ty
      | Index (a, i) ->
          let ca = sub a and ci = sub i in
          let aloc = a.loc and iloc = i.loc in
          fun fr ->
            let va = ca fr in
            Ops.index aloc iloc va (ci fr)
      | Bad -> fun _ -> raise Poisoned)

(* An expression the checker knew to be a number, as the function computing it: the
   operations and built-ins of numbers on numbers are done on floats, and only the result
   is made a value (checked as [Ops] and [Builtins] check it). *)
and floats ~block cs (e : expr) : frame -> float =
  let sub = floats ~block cs and loc = e.loc in
  match (const e, e.e) with
  | Some (VNum x), _ -> fun _ -> x
  | _, Binop (op, a, b) when arithmetic e -> (
      let fa = sub a and fb = sub b in
      match op with
      | Add ->
          fun fr ->
            let x = fa fr in
            let y = fb fr in
            checked loc (x +. y)
      | Sub ->
          fun fr ->
            let x = fa fr in
            let y = fb fr in
            checked loc (x -. y)
      | Mul ->
          fun fr ->
            let x = fa fr in
            let y = fb fr in
            checked loc (x *. y)
      | _ ->
          let bloc = b.loc in
          fun fr ->
            let x = fa fr in
            let y = fb fr in
            if y = 0. then fail bloc Msg.division_by_zero else checked loc (x /. y))
  | _, Call_builtin (_, { impl = F1 g; _ }, [ a ]) when arithmetic e ->
      let fa = sub a in
      fun fr -> checked loc (g (fa fr))
  | _, Call_builtin (b, { impl = Partial (ok, what, g); _ }, [ a ]) when arithmetic e ->
      let fa = sub a in
      fun fr ->
        let x = fa fr in
        if ok x then checked loc (g x) else fail loc (Msg.domain b.name what x)
  | _, Call_builtin (_, { impl = F2 g; _ }, [ a; b ]) when arithmetic e ->
      let fa = sub a and fb = sub b in
      fun fr ->
        let x = fa fr in
        let y = fb fr in
        checked loc (g x y)
  | _, Unop (Neg, a) when Ty.equal a.ty Num ->
      let fa = sub a in
      fun fr -> -.fa fr
  | _, Var (Local v) -> (
      match resolve cs v with
      | Slot i -> (
          fun fr ->
            match fr.l.(i) with
            | VNum x -> x
            | VPoison -> raise Poisoned
            | _ -> untyped "a number")
      | Cap i -> (
          fun fr ->
            match fr.c.(i) with
            | VNum x -> x
            | VPoison -> raise Poisoned
            | _ -> untyped "a number"))
  | _ -> (
      let c = expr ~block cs e in
      fun fr -> match c fr with VNum x -> x | _ -> untyped "a number")

(* An operator on two numbers (or on values whose types the checker could not know, most
   often numbers) at once; any other case through [Ops.binop]. *)
and binop ~sub (e : expr) op (a : expr) (b : expr) : code =
  let ca = sub a and cb = sub b in
  let loc = e.loc and bloc = b.loc in
  let slow va vb = Ops.binop loc op bloc va vb in
  let numeric =
    match (a.ty, b.ty) with (Num | Unknown), (Num | Unknown) -> true | _ -> false
  in
  if not numeric then fun fr ->
    let va = ca fr in
    slow va (cb fr)
  else
    match op with
    | Add -> (
        fun fr ->
          let va = ca fr in
          let vb = cb fr in
          match (va, vb) with VNum x, VNum y -> Ops.add loc x y | _ -> slow va vb)
    | Sub -> (
        fun fr ->
          let va = ca fr in
          let vb = cb fr in
          match (va, vb) with VNum x, VNum y -> Ops.sub loc x y | _ -> slow va vb)
    | Mul -> (
        fun fr ->
          let va = ca fr in
          let vb = cb fr in
          match (va, vb) with VNum x, VNum y -> Ops.mul loc x y | _ -> slow va vb)
    | Div -> (
        fun fr ->
          let va = ca fr in
          let vb = cb fr in
          match (va, vb) with VNum x, VNum y -> Ops.div loc bloc x y | _ -> slow va vb)
    | Lt -> (
        fun fr ->
          let va = ca fr in
          let vb = cb fr in
          match (va, vb) with VNum x, VNum y -> vbool (x < y) | _ -> slow va vb)
    | Le -> (
        fun fr ->
          let va = ca fr in
          let vb = cb fr in
          match (va, vb) with VNum x, VNum y -> vbool (x <= y) | _ -> slow va vb)
    | Gt -> (
        fun fr ->
          let va = ca fr in
          let vb = cb fr in
          match (va, vb) with VNum x, VNum y -> vbool (x > y) | _ -> slow va vb)
    | Ge -> (
        fun fr ->
          let va = ca fr in
          let vb = cb fr in
          match (va, vb) with VNum x, VNum y -> vbool (x >= y) | _ -> slow va vb)
    | _ ->
        fun fr ->
          let va = ca fr in
          slow va (cb fr)

and dot ca (a : expr) (f : Ast.name) : code =
  let x = f.id in
  match (a.ty, x) with
  | Vec, "x" -> ( fun fr -> match ca fr with VVec v -> VNum v.x | _ -> untyped "`.x`")
  | Vec, "y" -> ( fun fr -> match ca fr with VVec v -> VNum v.y | _ -> untyped "`.y`")
  | Vec, "z" -> ( fun fr -> match ca fr with VVec v -> VNum v.z | _ -> untyped "`.z`")
  | _ -> (
      fun fr ->
        match ca fr with
        | VVec v -> (
            match x with
            | "x" -> VNum v.x
            | "y" -> VNum v.y
            | "z" -> VNum v.z
            | _ -> fail f.nloc (Msg.vector_component x))
        | VBody name -> (
            match x with
            | "position" -> VVec (fst (State.body_at fr.st name))
            | "velocity" -> VVec (snd (State.body_at fr.st name))
            | _ -> fail f.nloc (Msg.body_member x))
        | v -> fail f.nloc (Msg.dot_needs x (ty v)))
