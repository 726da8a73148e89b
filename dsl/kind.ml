open Value

(* A default of the schema, a literal written as in a scene. *)
let literal (text : string) =
  let rec value (e : Ast.expr) =
    match e.e with
    | Num x -> VNum x
    | Str s -> VStr s
    | Bool b -> VBool b
    | Unop (Neg, a) -> ( match value a with VNum x -> VNum (-.x) | _ -> VPoison)
    | Binop (Div, a, b) -> (
        match (value a, value b) with VNum x, VNum y -> VNum (x /. y) | _ -> VPoison)
    | Vec (a, b, c) -> (
        match (value a, value b, value c) with
        | VNum x, VNum y, VNum z -> VVec (Vec3.v x y z)
        | _ -> VPoison)
    | _ -> VPoison
  in
  match Syntax.parse ~file:"schema" ("let default = " ^ text) with
  | Ok [ { s = Let (_, e); _ } ] when value e != VPoison -> value e
  | _ ->
      invalid_arg (Printf.sprintf "Kind: the schema's default %S is not a literal" text)

(* For a field without a default: a placeholder of its type. *)
let placeholder (fl : Schema.field) =
  match fl.ty with
  | Number | Integer -> VNum 1.
  | Boolean -> VBool false
  | File -> VStr ""
  | Choice l -> VStr (match l with c :: _ -> c | [] -> "")
  | Vector | Colour -> VVec Vec3.zero
  | Direction -> VVec Vec3.y_axis
  | Material | Base_material | Texture | Bump | Scale | Background | Fog | Gamma
  | Interval ->
      VPoison

type entry = { sch : Schema.field; default : Value.t; required : bool }

let entry (fl : Schema.field) =
  {
    sch = fl;
    default =
      (match fl.default with
      | Value v -> literal v
      | Required | Absent _ -> placeholder fl);
    required = fl.default = Required && fl.condition = Always;
  }

type t = {
  block : Schema.block;
  names : string array;
  entries : entry array;
  named : Schema.field list array;
  material : int;
  kind : int;
  values : int;
}

let index names name =
  let rec go i =
    if i >= Array.length names then -1
    else if String.equal names.(i) name then i
    else go (i + 1)
  in
  go 0

let make (b : Schema.block) =
  let names = Array.of_list (Schema.names_of b) in
  let named = Array.map (Schema.fields_named b) names in
  {
    block = b;
    names;
    entries = Array.map (fun fs -> entry (List.hd fs)) named;
    named;
    material = index names "material";
    kind = index names "kind";
    values =
      1
      + Array.fold_left max (-1)
          (Array.mapi
             (fun i fs ->
               if List.exists (fun (fl : Schema.field) -> not fl.repeats) fs then i
               else -1)
             named);
  }

let get = make
let slot k name = index k.names name
