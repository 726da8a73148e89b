open Ast

(* What an expression's value is known to be without running it: when it evaluates
   without error, its value has this type. *)
type ty =
  | Num
  | Bool
  | Vec
  | Str
  | Mat
  | Tex of string  (** a value of a texture-like built-in: its name *)
  | Pair
  | Fun
  | Macro
  | Builtin of string  (** a built-in function: the built-in's own name *)
  | Body
  | Unknown

module Env = Map.Make (String)

(* The names the evaluator gives the types, in its messages. *)
let type_name = function
  | Num -> "a number"
  | Bool -> "a boolean"
  | Vec -> "a vector"
  | Str -> "a string"
  | Mat -> "a material"
  | Tex "fog" -> "a fog (fog(colour, distance))"
  | Tex "color_map" -> "a colour map"
  | Tex _ -> "a texture"
  | Pair -> "a pair (t, colour)"
  | Fun -> "a function"
  | Macro -> "a scene macro"
  | Builtin _ -> "a built-in function"
  | Body -> "a body"
  | Unknown -> "a value"

let numeric =
  [
    "sin";
    "cos";
    "tan";
    "asin";
    "acos";
    "atan";
    "atan2";
    "radians";
    "degrees";
    "sqrt";
    "abs";
    "floor";
    "ceil";
    "round";
    "min";
    "max";
    "pow";
    "exp";
    "log";
    "clamp";
    "rand";
    "dot";
    "length";
  ]

let vectorial = [ "cross"; "normalize"; "rgb"; "hsv" ]

let textures =
  [
    "checker";
    "stripes";
    "noise";
    "marble";
    "wood";
    "image";
    "gradient";
    "color_map";
    "fog";
  ]

(* The names bound at the start are the evaluator's own built-ins; the lists above only
   say what some of them return (any other built-in's result is not known). *)
let initial_env =
  List.fold_left (fun env n -> Env.add n (Builtin n) env) Env.empty Eval.builtin_names
  |> Env.add "pi" Num |> Env.add "time" Num |> Env.add "frame" Num

let builtin name args =
  if List.mem name numeric then Num
  else if List.mem name vectorial then Vec
  else if List.mem name textures then Tex name
  else
    match (name, args) with
    | "mix", Num :: _ -> Num
    | "mix", Vec :: _ -> Vec
    | _ -> Unknown

let arith op a b =
  let num_or_unknown t = t = Num || t = Unknown in
  match op with
  | Add | Sub -> (
      match (a, b) with
      | Num, (Num | Unknown) | Unknown, Num -> Num
      | Vec, (Vec | Unknown) | Unknown, Vec -> Vec
      | _ -> Unknown)
  | Mul -> (
      match (a, b) with
      | Num, Num -> Num
      | Vec, (Num | Vec | Unknown) | (Num | Unknown), Vec -> Vec
      | _ -> Unknown)
  | Div -> ( match a with (Num | Vec) when num_or_unknown b -> a | _ -> Unknown)
  | Mod | Pow -> if num_or_unknown a && num_or_unknown b then Num else Unknown
  | Eq | Ne | Lt | Le | Gt | Ge | And | Or -> Bool

let rec type_of env (e : expr) =
  match e.e with
  | Num _ -> Num
  | Str _ -> Str
  | Bool _ -> Bool
  | Var x -> Option.value (Env.find_opt x env) ~default:Unknown
  | Vec _ -> Vec
  | Pair _ -> Pair
  | Material _ -> Mat
  | Unop (Neg, a) -> ( match type_of env a with (Num | Vec) as t -> t | _ -> Unknown)
  | Unop (Not, _) -> Bool
  | Binop (op, a, b) -> arith op (type_of env a) (type_of env b)
  | Dot (_, { id = "x" | "y" | "z"; _ }) -> Num
  | Dot (_, { id = "position" | "velocity"; _ }) -> Vec
  | Dot _ -> Unknown
  | If (_, a, b) ->
      let ta = type_of env a in
      if ta = type_of env b then ta else Unknown
  | Call (f, args) -> (
      match Env.find_opt f.id env with
      (* the built-in the name holds, which [let dot = cross] makes another than its
         name says *)
      | Some (Builtin b) -> builtin b (List.map (type_of env) args)
      | _ -> Unknown)

(* The message the evaluator gives for a value of type [t] in field [name] of type [ty];
   [None] when the type is right (or not known). *)
let mismatch name (ty : Schema.ty) t =
  let must what =
    Some (Printf.sprintf "`%s` must be %s, got %s" name what (type_name t))
  in
  match (ty, t) with
  | _, Unknown -> None
  | (Number | Integer), Num
  | Boolean, Bool
  | File, Str
  | Choice _, Str
  | (Vector | Direction | Colour), Vec
  | (Material | Base_material), Mat
  | Texture, (Tex _ | Vec)
  | Bump, Tex _
  | Scale, (Num | Vec)
  | Background, (Vec | Tex "gradient")
  | Fog, Tex "fog"
  | Gamma, (Str | Num) ->
      None
  | (Number | Integer), _ -> must "a number"
  | Boolean, _ -> must "true or false"
  | File, _ -> must "a file name string"
  | Choice l, _ -> must (Printf.sprintf "a string (%s)" (Schema.quoted l))
  | (Vector | Direction | Colour), _ -> must "a vector (x, y, z)"
  | Material, _ -> must "a material (material { … })"
  | Base_material, _ -> must "a material"
  | Texture, _ -> must "a texture (checker(…), stripes(…), …)"
  | Bump, _ -> must "noise(scale, amount) or image(\"file.png\", amount)"
  | Scale, _ -> must "a number or a vector"
  | Background, Tex _ -> must "a colour (r, g, b) or gradient(HORIZON, ZENITH)"
  | Background, _ -> must "a vector (x, y, z)"
  | Fog, _ -> must "fog(COLOR, DISTANCE)"
  | Gamma, _ ->
      Some (Printf.sprintf "`%s` must be \"srgb\" or a number in (0, 1000]" name)

let hint x candidates =
  match Eval.suggest x candidates with
  | Some c -> Printf.sprintf "; did you mean `%s`?" c
  | None -> ""

type cx = {
  sources : (string, string) Hashtbl.t;
  mutable errors : Error.t list;  (** reversed *)
  mutable count : int;  (** of [errors] *)
}

let report cx (loc : Loc.t) msg =
  cx.count <- cx.count + 1;
  cx.errors <-
    Error.make ?source:(Hashtbl.find_opt cx.sources loc.file) loc msg :: cx.errors

(* [in_group]: [Some true] inside a group, CSG block or body, [Some false] at top level,
   [None] in a macro that may be called from either. *)
let rec stmts cx env ~in_group ss =
  List.fold_left (fun env s -> stmt cx env ~in_group s) env ss

and stmt cx env ~in_group (s : stmt) =
  match s.s with
  | Let (x, e) -> Env.add x.id (checked_type cx env e) env
  | Fn (f, params, body) ->
      let env = Env.add f.id Fun env in
      expr cx (bind params env) body;
      env
  | Macro (f, params, body) ->
      let env = Env.add f.id Macro env in
      let in_group = if in_group = Some true then in_group else None in
      ignore (stmts cx (bind params env) ~in_group body);
      env
  | For (x, a, b, st, body) ->
      List.iter (expr cx env) (a :: b :: Option.to_list st);
      ignore (stmts cx (Env.add x.id Num env) ~in_group body);
      env
  | If_stmt (c, t, e) ->
      expr cx env c;
      ignore (stmts cx env ~in_group t);
      ignore (stmts cx env ~in_group e);
      env
  | Include _ -> env
  | Included (_, ss) -> stmts cx env ~in_group ss
  | Call_stmt (_, args) ->
      List.iter (expr cx env) args;
      env
  | Block (k, items) ->
      block cx env ~in_group k items;
      env
  | Body (n, items) ->
      if in_group = Some true then
        report cx n.nloc "a body cannot be inside a group or another body"
      else fields cx env ~in_group ~keyword:"body" n.nloc items;
      Env.add n.id Body env

and bind params env =
  List.fold_left (fun env (p : name) -> Env.add p.id Unknown env) env params

(* The type of [e], after checking it; unknown when a mistake was found in it (the
   evaluator does not report again the uses of a value whose definition failed). *)
and checked_type cx env e =
  let before = cx.count in
  expr cx env e;
  if cx.count > before then Unknown else type_of env e

and expr cx env (e : expr) =
  match e.e with
  | Num _ | Str _ | Bool _ | Var _ -> ()
  | Vec (a, b, c) -> List.iter (expr cx env) [ a; b; c ]
  | Pair (a, b) | Binop (_, a, b) ->
      expr cx env a;
      expr cx env b
  | Unop (_, a) | Dot (a, _) -> expr cx env a
  | If (c, a, b) -> List.iter (expr cx env) [ c; a; b ]
  | Call (_, args) -> List.iter (expr cx env) args
  | Material items -> fields cx env ~in_group:(Some false) ~keyword:"material" e.loc items

and block cx env ~in_group (k : name) items =
  match k.id with
  | ("settings" | "camera" | "animation" | "physics" | "light") when in_group = Some true
    ->
      report cx k.nloc
        (Printf.sprintf
           "`%s` cannot be inside a group: a group's transforms and material apply to \
            objects only; write it at top level"
           k.id)
  | "material" ->
      report cx k.nloc
        "a material is a value: write `material: material { … }` inside an object, or \
         `let m = material { … }`"
  | kw when List.mem kw Schema.keywords ->
      fields cx env ~in_group ~keyword:kw k.nloc items
  | x ->
      report cx k.nloc (Printf.sprintf "unknown block `%s`%s" x (hint x Schema.keywords))

(* A block's items, as the evaluator collects them, then its fields against its schema. *)
and fields cx env ~in_group ~keyword kloc items =
  let holds_objects =
    match Schema.for_keyword keyword with b :: _ -> b.holds_objects | [] -> false
  in
  let inner = if holds_objects then Some true else in_group in
  let given = ref [] in
  ignore
    (List.fold_left
       (fun env item ->
         match item with
         | Field (n, e) -> (
             match List.find_opt (fun ((m : name), _, _) -> m.id = n.id) !given with
             | Some (prev, _, _) when not (List.mem n.id Schema.repeatable) ->
                 report cx n.nloc
                   (Printf.sprintf "`%s` is given twice in this %s (first at line %d)"
                      n.id keyword prev.nloc.line);
                 env
             | _ ->
                 given := !given @ [ (n, e, checked_type cx env e) ];
                 env)
         | Stmt s -> (
             match s.s with
             | Let _ | Fn _ | Macro _ -> stmt cx env ~in_group:inner s
             | _ when holds_objects -> stmt cx env ~in_group:inner s
             | _ ->
                 report cx s.sloc
                   (Printf.sprintf
                      "a %s holds only `field: value` pairs (and `let`); objects go in a \
                       `group`"
                      keyword);
                 env))
       env items);
  let given = !given in
  let present name = List.exists (fun ((m : name), _, _) -> m.id = name) given in
  match Schema.choose ~keyword present with
  | Some b -> schema_fields cx b ~keyword kloc given
  | None when keyword = "light" -> (
      match List.find_opt (fun ((m : name), _, _) -> m.id = "direction") given with
      | Some (_, (e : expr), _) when present "position" ->
          report cx e.loc
            "a light has a `position` (point light) or a `direction` (directional \
             light), not both"
      | _ ->
          report cx kloc
            "a light needs a `position` (point light) or a `direction` (directional \
             light)")
  | None -> ()

(* The evaluator's messages for a field given where it does not apply (where the kind or
   the other field it depends on says so), and where it is shown: at the field's name or
   at its value. *)
and misplaced id name =
  match (id, name) with
  | "point_light", ("inner" | "outer") ->
      Some (`Name, Printf.sprintf "`%s` is for a spot light: give it a `point_at`" name)
  | "camera", "width" ->
      Some (`Value, "`width` is for an orthographic camera (kind: \"orthographic\")")
  | "camera", "fov" ->
      Some
        (`Value, "an orthographic camera has no `fov`: its `width` sets how much it sees")
  | "animation", "duration" -> Some (`Value, "give `frames` or `duration`, not both")
  | _ -> None

(* The evaluator's message for a required field that is missing. *)
and missing id keyword name =
  match (id, name) with
  | "camera", "width" ->
      "an orthographic camera needs a `width` (world units across the image)"
  | _ -> Printf.sprintf "%s needs a `%s` field" keyword name

and schema_fields cx (b : Schema.block) ~keyword kloc given =
  let allowed = Schema.names_of b in
  let present name = List.exists (fun ((m : name), _, _) -> m.id = name) given in
  (* The block's kind, when it is written as a literal (or left at its default). *)
  let kind =
    let known s =
      List.exists
        (fun (fl : Schema.field) ->
          match fl.ty with Choice l -> List.mem s l | _ -> false)
        (Schema.fields_named b "kind")
    in
    match List.find_opt (fun ((m : name), _, _) -> m.id = "kind") given with
    | Some (_, { e = Str s; _ }, _) when known s -> Some s
    | Some _ -> None
    | None -> (
        match Schema.fields_named b "kind" with
        | { default = Value v; _ } :: _ when String.length v >= 2 ->
            Some (String.sub v 1 (String.length v - 2))
        | _ -> None)
  in
  let applies (fl : Schema.field) =
    match fl.condition with
    | Always -> true
    | With n -> present n
    | Without n -> not (present n)
    | Kind_in ks -> ( match kind with Some k -> List.mem k ks | None -> false)
  in
  (* Whether a field surely does not apply (its kind, or the field it depends on, is
     known and says so). *)
  let excluded (fl : Schema.field) =
    match fl.condition with
    | Always -> false
    | With n -> not (present n)
    | Without n -> present n
    | Kind_in ks -> ( match kind with Some k -> not (List.mem k ks) | None -> false)
  in
  List.iter
    (fun ((n : name), (e : expr), t) ->
      if not (List.mem n.id allowed) then
        report cx n.nloc
          (Printf.sprintf "unknown field `%s` in %s%s" n.id keyword (hint n.id allowed))
      else
        let entries = Schema.fields_named b n.id in
        match List.filter applies entries with
        | fl :: _ -> Option.iter (report cx e.loc) (mismatch n.id fl.ty t)
        | [] -> (
            match misplaced b.id n.id with
            | Some (at, msg) when List.for_all excluded entries ->
                report cx (if at = `Name then n.nloc else e.loc) msg
            | _ -> ()))
    given;
  List.iter
    (fun (fl : Schema.field) ->
      if fl.default = Required && applies fl && not (present fl.name) then
        let misspelt =
          fl.condition = Always
          && List.exists
               (fun ((m : name), _, _) ->
                 (not (List.mem m.id allowed))
                 && Eval.suggest m.id [ fl.name ] = Some fl.name)
               given
        in
        if not misspelt then report cx kloc (missing b.id keyword fl.name))
    b.fields

let run ~sources program =
  let cx = { sources; errors = []; count = 0 } in
  ignore (stmts cx initial_env ~in_group:(Some false) program);
  List.rev cx.errors
