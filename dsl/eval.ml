open Ast
module D = Description

let max_objects = D.max_objects
let max_steps = 20_000_000
let max_depth = 1000

(* Address space one object costs while the scene is built and rendered: 200 000 spheres
   took 462 MB at their peak (the objects, the garbage collector's free space, the
   BVH), 2.3 KB each; with a margin. *)
let bytes_per_object = 2560

(* The process's limit on its address space (ulimit -v), read once. *)
let address_limit = lazy (Address_space.limit ())

(* What the runtime reserves before any object: the minor heaps of the 128 domains it could
   run (256 MB at the default size), and the program itself. *)
let baseline_bytes = 320_000_000

let memory_refusal objects =
  match Lazy.force address_limit with
  | Some limit
    when Float.of_int objects *. Float.of_int bytes_per_object
         > Float.of_int (limit - baseline_bytes) ->
      Some
        (Printf.sprintf
           "%s objects need about %.0f MB of memory; this process may use %.0f MB in all \
            (ulimit -v), room for about %d objects: raise the limit or build fewer \
            objects"
           (if objects >= 1_000_000 then
              Printf.sprintf "%.1f million" (Float.of_int objects /. 1e6)
            else string_of_int objects)
           (Float.of_int objects *. Float.of_int bytes_per_object /. 1e6)
           (Float.of_int limit /. 1e6)
           (max 0 ((limit - baseline_bytes) / bytes_per_object)))
  | _ -> None

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

(* ------------------------------------------------------------------------------------ *)
(* Did-you-mean *)

let edit_distance a b =
  let la = String.length a and lb = String.length b in
  let d = Array.make_matrix (la + 1) (lb + 1) 0 in
  for i = 0 to la do
    d.(i).(0) <- i
  done;
  for j = 0 to lb do
    d.(0).(j) <- j
  done;
  for i = 1 to la do
    for j = 1 to lb do
      let c = if a.[i - 1] = b.[j - 1] then 0 else 1 in
      d.(i).(j) <-
        min (min (d.(i - 1).(j) + 1) (d.(i).(j - 1) + 1)) (d.(i - 1).(j - 1) + c);
      if i > 1 && j > 1 && a.[i - 1] = b.[j - 2] && a.[i - 2] = b.[j - 1] then
        d.(i).(j) <- min d.(i).(j) (d.(i - 2).(j - 2) + 1)
    done
  done;
  d.(la).(lb)

let suggest x candidates =
  let limit = max 1 (min 3 (String.length x / 3)) in
  let best =
    List.fold_left
      (fun acc c ->
        let d = edit_distance (String.lowercase_ascii x) (String.lowercase_ascii c) in
        match acc with
        | Some (_, bd) when bd <= d -> acc
        | _ -> if d <= limit && c <> x then Some (c, d) else acc)
      None candidates
  in
  Option.map fst best

let hint x candidates =
  match suggest x candidates with
  | Some c -> Printf.sprintf "; did you mean `%s`?" c
  | None -> ""

(* ------------------------------------------------------------------------------------ *)
(* Values *)

type pending_obj = D.obj

(* A scope: where objects go (the program, or a group or body being built). *)
type scope = { sink : pending_obj list ref; in_group : bool; in_csg : bool }

type value =
  | VNum of float
  | VBool of bool
  | VVec of Vec3.t
  | VStr of string
  | VMat of D.material
  | VTex of tex
  | VPair of value * value  (** [(t, c)], an entry of a colour map *)
  | VFun of closure
  | VMacro of macro
  | VBuiltin of string
  | VBody of string
  | VPoison  (** the value of a name whose definition failed (already reported) *)

and tex = { tname : string; targs : value list; tloc : Loc.t }

(* A function or macro made of compiled code: its parameters are the first slots of the
   frame a call makes ([fslots] in all), the names it reads from around its definition
   are copied into [fcaps] when it is defined (so a function defined in a loop's body
   keeps that iteration's values). *)
and closure = {
  fname : string;
  nparams : int;
  fbody : frame -> value;
  fslots : int;
  mutable fcaps : value array;
}

and macro = {
  mname : string;
  mnparams : int;
  mbody : frame -> scope -> unit;
  mslots : int;
  mutable mcaps : value array;
}

(* The values of one activation: its own names by slot, and those its function captured. *)
and frame = { l : value array; c : value array }

let type_name = function
  | VNum _ -> "a number"
  | VBool _ -> "a boolean"
  | VVec _ -> "a vector"
  | VStr _ -> "a string"
  | VMat _ -> "a material"
  | VTex { tname = "fog"; _ } -> "a fog (fog(colour, distance))"
  | VTex { tname = "color_map"; _ } -> "a colour map"
  | VTex _ -> "a texture"
  | VPair _ -> "a pair (t, colour)"
  | VFun _ -> "a function"
  | VMacro _ -> "a scene macro"
  | VBuiltin _ -> "a built-in function"
  | VBody _ -> "a body"
  | VPoison -> "an erroneous value"

(* An error to report; an error already reported (skip quietly); a limit was hit. *)
exception Fail of Loc.t * string
exception Poisoned
exception Abort

let fail loc fmt = Printf.ksprintf (fun m -> raise (Fail (loc, m))) fmt

(* The schema made ready for evaluation, once per block kind (see [specs_of]). *)

type entry = {
  sch : Schema.field;
  default : value;
      (** the schema's default, read as the literal it is; for a field without one, a
          placeholder of its type (used only once the block has failed, or where the
          evaluator supplies the value itself) *)
  required : bool;  (** required whatever else the block holds *)
  must : string;  (** [Schema.must] *)
}

type spec = { entries : entry list; names : string list }

type specs = {
  by_kind : (string, spec) Hashtbl.t;
      (** by block id, and by keyword (a [light] is a point light until its fields say) *)
  material : D.material;  (** [material { }]: every field at its default *)
}

(* ------------------------------------------------------------------------------------ *)
(* Context *)

type ctx = {
  time : float;
  body_state : (string -> float -> (Vec3.t * Vec3.t) option) option;
  sources : (string, string) Hashtbl.t;
  used : (string, unit) Hashtbl.t;  (** the image and mesh files this evaluation names *)
  on_file : D.file_use -> unit;  (** told each use of a file, as it is met *)
  mutable errors : Error.t list;  (** reversed *)
  seen : (string * int * int * string, unit) Hashtbl.t;
  mutable objects : int;
  mutable steps : int;
  mutable loops : float;  (** iterations the enclosing loops have left, multiplied *)
  mutable depth : int;
  mutable settings : (Settings.t * Loc.t) option;
  mutable camera : (Camera.t * Loc.t) option;
  mutable animation : ((float * int) * Loc.t) option;
  mutable physics : (physics * Loc.t) option;
  mutable lights : Light.t list;
  mutable bodies : (body * pending_obj) list;  (** reversed *)
  mutable warnings : Error.t list;  (** reversed *)
  on_objects : (int -> unit) option;  (** told the count every 65 536 objects *)
  cancel : Cancel.t option;  (** polled every 4096 steps *)
  specs : specs;  (** the block kinds' fields *)
  definitions : (string * Loc.t) list Lazy.t;
      (** every name the program defines ([let], [fn], [body]), anywhere, where it is
          defined; built only for an unknown name's message *)
}

let report ctx (loc : Loc.t) msg =
  let key = (loc.file, loc.line, loc.col, msg) in
  if not (Hashtbl.mem ctx.seen key) then (
    Hashtbl.add ctx.seen key ();
    ctx.errors <-
      Error.make ?source:(Hashtbl.find_opt ctx.sources loc.file) loc msg :: ctx.errors)

let warn ctx (loc : Loc.t) msg =
  let key = (loc.file, loc.line, loc.col, "warning: " ^ msg) in
  if not (Hashtbl.mem ctx.seen key) then (
    Hashtbl.add ctx.seen key ();
    ctx.warnings <-
      Error.warning ?source:(Hashtbl.find_opt ctx.sources loc.file) loc msg
      :: ctx.warnings)

let limit ctx loc msg =
  report ctx loc msg;
  raise Abort

let step ctx loc =
  ctx.steps <- ctx.steps + 1;
  (* An interrupt is felt here too: evaluation may run where a signal does not raise at
     once (inside a pool of domains). *)
  if ctx.steps land 4095 = 0 then Option.iter Cancel.check ctx.cancel;
  if ctx.steps > max_steps then
    limit ctx loc
      (Printf.sprintf
         "this scene takes more than %d evaluation steps (loop iterations and calls); \
          that is the limit"
         max_steps)

(* ------------------------------------------------------------------------------------ *)
(* Numbers *)

let finite loc x =
  if Float.is_nan x then fail loc "this expression is not a number (NaN)"
  else if Float.is_integer x || Float.is_finite x then x
  else fail loc "this expression overflows to infinity"

let finite_vec loc (v : Vec3.t) =
  ignore (finite loc v.x);
  ignore (finite loc v.y);
  ignore (finite loc v.z);
  v

let fmt_num x =
  if Float.is_integer x && Float.abs x < 1e15 then Printf.sprintf "%.0f" x
  else Printf.sprintf "%g" x

(* A whole number with its digits in groups of three: 10 000 000. *)
let grouped n =
  let s = string_of_int n in
  let len = String.length s in
  String.concat ""
    (List.init len (fun i ->
         (if i > 0 && (len - i) mod 3 = 0 then " " else "") ^ String.make 1 s.[i]))

(* ------------------------------------------------------------------------------------ *)
(* Built-in functions *)

let builtin_names =
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
    "mix";
    "dot";
    "cross";
    "length";
    "normalize";
    "rgb";
    "hsv";
    "rand";
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

let hsv h s v =
  let h = (h -. Float.floor h) *. 6. in
  let i = int_of_float (Float.floor h) mod 6 in
  let f = h -. Float.floor h in
  let p = v *. (1. -. s)
  and q = v *. (1. -. (s *. f))
  and t = v *. (1. -. (s *. (1. -. f))) in
  match i with
  | 0 -> Vec3.v v t p
  | 1 -> Vec3.v q v p
  | 2 -> Vec3.v p v t
  | 3 -> Vec3.v p q v
  | 4 -> Vec3.v t p v
  | _ -> Vec3.v v p q

(* A call of a built-in: its name, where, its arguments (values, where each is written). *)
type bcall = { bname : string; bloc : Loc.t; bargs : (value * Loc.t) list; bn : int }

let arity c k =
  if c.bn <> k then
    fail c.bloc "`%s` takes %d argument%s, got %d" c.bname k
      (if k = 1 then "" else "s")
      c.bn

let num c i =
  let v, l = List.nth c.bargs i in
  match v with
  | VNum x -> x
  | v ->
      fail l "argument %d of `%s` must be a number, got %s" (i + 1) c.bname (type_name v)

let vec c i =
  let v, l = List.nth c.bargs i in
  match v with
  | VVec x -> x
  | v ->
      fail l "argument %d of `%s` must be a vector (x, y, z), got %s" (i + 1) c.bname
        (type_name v)

let f1 c f =
  arity c 1;
  VNum (finite c.bloc (f (num c 0)))

let domain c ok what f =
  arity c 1;
  let x = num c 0 in
  if not (ok x) then fail c.bloc "`%s` needs %s, got %s" c.bname what (fmt_num x);
  VNum (finite c.bloc (f x))

let tex c k =
  arity c k;
  VTex { tname = c.bname; targs = List.map fst c.bargs; tloc = c.bloc }

(* A built-in's code, found once from its name. *)
let builtin_code name : bcall -> value =
  match name with
  | "sin" -> fun c -> f1 c sin
  | "cos" -> fun c -> f1 c cos
  | "tan" -> fun c -> f1 c tan
  | "asin" -> fun c -> domain c (fun x -> x >= -1. && x <= 1.) "a value in [-1, 1]" asin
  | "acos" -> fun c -> domain c (fun x -> x >= -1. && x <= 1.) "a value in [-1, 1]" acos
  | "atan" -> fun c -> f1 c atan
  | "atan2" ->
      fun c ->
        arity c 2;
        VNum (finite c.bloc (Float.atan2 (num c 0) (num c 1)))
  | "radians" -> fun c -> f1 c (fun d -> d *. Float.pi /. 180.)
  | "degrees" -> fun c -> f1 c (fun r -> r *. 180. /. Float.pi)
  | "sqrt" -> fun c -> domain c (fun x -> x >= 0.) "a value ≥ 0" sqrt
  | "abs" -> fun c -> f1 c Float.abs
  | "floor" -> fun c -> f1 c Float.floor
  | "ceil" -> fun c -> f1 c Float.ceil
  | "round" -> fun c -> f1 c Float.round
  | "exp" -> fun c -> f1 c exp
  | "log" -> fun c -> domain c (fun x -> x > 0.) "a value > 0" log
  | "pow" ->
      fun c ->
        arity c 2;
        VNum (finite c.bloc (Float.pow (num c 0) (num c 1)))
  | "min" | "max" ->
      fun c ->
        if c.bn < 2 then
          fail c.bloc "`%s` takes at least 2 arguments, got %d" c.bname c.bn;
        let xs = List.mapi (fun i _ -> num c i) c.bargs in
        let f = if c.bname = "min" then Float.min else Float.max in
        VNum (List.fold_left f (List.hd xs) (List.tl xs))
  | "clamp" ->
      fun c ->
        arity c 3;
        let x = num c 0 and lo = num c 1 and hi = num c 2 in
        if lo > hi then
          fail c.bloc "`clamp` needs lo ≤ hi, got %s > %s" (fmt_num lo) (fmt_num hi);
        VNum (Float.min hi (Float.max lo x))
  | "mix" -> (
      fun c ->
        arity c 3;
        let t = num c 2 in
        match (fst (List.nth c.bargs 0), fst (List.nth c.bargs 1)) with
        | VNum a, VNum b -> VNum (finite c.bloc (a +. (t *. (b -. a))))
        | VVec a, VVec b -> VVec (finite_vec c.bloc (Vec3.madd a t (Vec3.sub b a)))
        | a, b ->
            fail c.bloc "`mix` mixes two numbers or two vectors, got %s and %s"
              (type_name a) (type_name b))
  | "dot" ->
      fun c ->
        arity c 2;
        VNum (finite c.bloc (Vec3.dot (vec c 0) (vec c 1)))
  | "cross" ->
      fun c ->
        arity c 2;
        VVec (finite_vec c.bloc (Vec3.cross (vec c 0) (vec c 1)))
  | "length" ->
      fun c ->
        arity c 1;
        VNum (finite c.bloc (Vec3.length (vec c 0)))
  | "normalize" ->
      fun c ->
        arity c 1;
        let v = vec c 0 in
        if Vec3.max_abs v = 0. then fail c.bloc "`normalize` of the zero vector";
        VVec (finite_vec c.bloc (Vec3.normalize v))
  | "rgb" ->
      fun c ->
        arity c 3;
        VVec (Vec3.v (num c 0) (num c 1) (num c 2))
  | "hsv" ->
      fun c ->
        arity c 3;
        VVec (finite_vec c.bloc (hsv (num c 0) (num c 1) (num c 2)))
  | "rand" ->
      fun c ->
        arity c 1;
        VNum (Hash.of_float (num c 0))
  | "checker" | "stripes" -> fun c -> tex c 3
  | "marble" | "wood" ->
      fun c ->
        if c.bn <> 2 && c.bn <> 3 then
          fail c.bloc
            "`%s` takes 3 arguments (c1, c2, scale), or 2 (color_map(…), scale); got %d"
            c.bname c.bn;
        tex c c.bn
  | "noise" ->
      fun c ->
        if c.bn <> 2 && c.bn <> 3 then
          fail c.bloc
            "`noise` takes 3 arguments (c1, c2, scale) or 2 (color_map(…), scale) as a \
             texture, or 2 (scale, amount) as a bump map; got %d"
            c.bn;
        tex c c.bn
  | "gradient" -> (
      fun c ->
        (* gradient(AXIS, MAP) is a texture; gradient(HORIZON, ZENITH) a background. *)
        arity c 2;
        ignore (vec c 0);
        match List.nth c.bargs 1 with
        | VTex { tname = "color_map"; _ }, _ | VVec _, _ -> tex c 2
        | v, l ->
            fail l
              "argument 2 of `gradient` must be a color_map(…) (a texture along an axis) \
               or a colour (a background from horizon to zenith), got %s"
              (type_name v))
  | "color_map" ->
      fun c ->
        if c.bn = 0 then fail c.bloc "`color_map` needs at least one entry (t, colour)";
        ignore
          (List.fold_left
             (fun (i, prev) (v, l) ->
               (match v with
               | VPair (VNum t, VVec c) ->
                   if not (t >= 0. && t <= 1.) then
                     fail l "entry %d of `color_map` has t = %s; t must be in [0, 1]" i
                       (fmt_num t);
                   if t < prev then
                     fail l
                       "entry %d of `color_map` has t = %s, below the %s before it: \
                        entries go in increasing t"
                       i (fmt_num t) (fmt_num prev);
                   if c.x < 0. || c.y < 0. || c.z < 0. then
                     fail l
                       "entry %d of `color_map` has a colour with a negative component" i
               | _ -> ());
               (i + 1, match v with VPair (VNum t, _) -> t | _ -> prev))
             (1, 0.) c.bargs);
        List.iteri
          (fun i (v, l) ->
            match v with
            | VPair (VNum _, VVec _) -> ()
            | VPair (a, b) ->
                fail l
                  "entry %d of `color_map` must be (t, colour) with t a number and \
                   colour (r, g, b), got (%s, %s)"
                  (i + 1) (type_name a) (type_name b)
            | v ->
                fail l
                  "entry %d of `color_map` must be a pair (t, colour), e.g. (0.5, (1, 0, \
                   0)), got %s"
                  (i + 1) (type_name v))
          c.bargs;
        tex c c.bn
  | "fog" ->
      fun c ->
        arity c 2;
        ignore (vec c 0);
        let d = num c 1 in
        if not (d > 0. && d <= 1e150) then
          fail
            (snd (List.nth c.bargs 1))
            "the distance of `fog` must be in (0, 1e150], got %s" (fmt_num d);
        tex c 2
  | "image" ->
      fun c ->
        arity c 2;
        (match fst (List.nth c.bargs 0) with
        | VStr _ -> ()
        | v ->
            fail
              (snd (List.nth c.bargs 0))
              "argument 1 of `image` must be a file name string, got %s" (type_name v));
        ignore (num c 1);
        tex c 2
  | _ -> fun c -> fail c.bloc "internal error: unknown built-in `%s`" c.bname

(* The allowed fields of each block kind come from the language's schema. *)
let material_fields = Schema.field_names "material"
let repeatable = Schema.repeatable

(* ------------------------------------------------------------------------------------ *)
(* The schema made ready for evaluation, once per block kind: each field's default as a
   value, and what a message says of a number out of its range. *)

(* A default of the schema, a literal written as in a scene. *)
let literal (text : string) =
  let rec value (e : expr) =
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
  | Ok [ { s = Let (_, e); _ } ] when value e <> VPoison -> value e
  | _ ->
      invalid_arg (Printf.sprintf "Eval: the schema's default %S is not a literal" text)

let placeholder (fl : Schema.field) =
  match fl.ty with
  | Number | Integer -> VNum 1.
  | Boolean -> VBool false
  | File -> VStr ""
  | Choice l -> VStr (match l with c :: _ -> c | [] -> "")
  | Vector | Colour -> VVec Vec3.zero
  | Direction -> VVec Vec3.y_axis
  | Material | Base_material | Texture | Bump | Scale | Background | Fog | Gamma ->
      VPoison

let spec_of (b : Schema.block) =
  {
    entries =
      List.map
        (fun (fl : Schema.field) ->
          {
            sch = fl;
            default =
              (match fl.default with
              | Value v -> literal v
              | Required | Absent _ -> placeholder fl);
            required = fl.default = Required && fl.condition = Always;
            must = Schema.must fl;
          })
        b.fields;
    names = Schema.names_of b;
  }

let specs_of (blocks : Schema.block list) =
  let by_kind = Hashtbl.create 64 in
  List.iter
    (fun (b : Schema.block) ->
      let sp = spec_of b in
      Hashtbl.replace by_kind b.id sp;
      if not (Hashtbl.mem by_kind b.keyword) then Hashtbl.replace by_kind b.keyword sp)
    blocks;
  let m = Hashtbl.find by_kind "material" in
  let d name =
    match List.find_opt (fun e -> e.sch.name = name) m.entries with
    | Some e -> e.default
    | None -> invalid_arg ("Eval: the schema's material has no " ^ name)
  in
  let wrong n = invalid_arg ("Eval: the schema's material " ^ n) in
  let num n = match d n with VNum x -> x | _ -> wrong n in
  let material : D.material =
    {
      color = (match d "color" with VVec v -> Color.of_vec3 v | _ -> wrong "color");
      texture = None;
      ambient = num "ambient";
      diffuse = num "diffuse";
      specular = num "specular";
      shininess = num "shininess";
      reflection = num "reflection";
      transparency = num "transparency";
      ior = num "ior";
      fresnel = (match d "fresnel" with VBool x -> x | _ -> wrong "fresnel");
      bump = None;
    }
  in
  { by_kind; material }

let schema_specs = lazy (specs_of Schema.blocks)

(* The fields each block kind allows, listed once. *)
let field_names_of =
  let t = Hashtbl.create 64 in
  List.iter
    (fun (b : Schema.block) -> Hashtbl.replace t b.id (Schema.field_names b.id))
    Schema.blocks;
  fun id -> match Hashtbl.find_opt t id with Some l -> l | None -> Schema.field_names id

(* A block being evaluated: its fields in order, and the objects its statements built. *)
type fld = { name : name; value : value; vloc : Loc.t }

type block = {
  ctx : ctx;
  kind : string;
  kloc : Loc.t;
  mutable spec : spec;  (** its kind's fields (a light's is settled by its fields) *)
  mutable fields : fld list;
  mutable failed : bool;
  members : pending_obj list ref;
}

let rec find_field name = function
  | [] -> None
  | f :: rest -> if String.equal f.name.id name then Some f else find_field name rest

(* ------------------------------------------------------------------------------------ *)
(* Expressions *)

(* ------------------------------------------------------------------------------------ *)
(* Expressions: what does not depend on the program's structure (the code that runs it is
   compiled from it further down) *)

(* A statement as compiled: it runs in a frame, putting objects in a scope. *)
type code = frame -> value
type scode = frame -> scope -> unit

(* A block's items as compiled. What the items say of themselves is settled once: a field
   given twice, a statement a block does not hold. *)
type citem =
  | CField of name * code * Loc.t  (** the field, its value, where the value is written *)
  | CDup of name * int  (** a field given twice (the first at that line) *)
  | CStmt of scode
  | CRefused of Loc.t  (** a statement this block does not hold *)

let enter ctx loc =
  step ctx loc;
  if ctx.depth >= max_depth then
    limit ctx loc
      (Printf.sprintf "calls are nested more than %d deep (runaway recursion?)" max_depth);
  ctx.depth <- ctx.depth + 1

let binop loc op a b bloc =
  let num x = VNum (finite loc x) and vec v = VVec (finite_vec loc v) in
  let bad () =
    fail loc "`%s` cannot combine %s and %s" (binop_name op) (type_name a) (type_name b)
  in
  (match (a, b) with VPoison, _ | _, VPoison -> raise Poisoned | _ -> ());
  match (op, a, b) with
  | Add, VNum x, VNum y -> num (x +. y)
  | Add, VVec x, VVec y -> vec (Vec3.add x y)
  | Sub, VNum x, VNum y -> num (x -. y)
  | Sub, VVec x, VVec y -> vec (Vec3.sub x y)
  | Mul, VNum x, VNum y -> num (x *. y)
  | Mul, VNum s, VVec v | Mul, VVec v, VNum s -> vec (Vec3.smul s v)
  | Mul, VVec x, VVec y -> vec (Vec3.mul x y)
  | Div, VNum _, VNum 0. | Div, VVec _, VNum 0. -> fail bloc "division by zero"
  | Div, VNum x, VNum y -> num (x /. y)
  | Div, VVec v, VNum s -> vec (Vec3.smul (1. /. s) v)
  | Mod, VNum _, VNum 0. -> fail bloc "modulo by zero"
  | Mod, VNum x, VNum y -> num (Float.rem x y)
  | Pow, VNum x, VNum y ->
      let r = Float.pow x y in
      if Float.is_nan r then
        fail loc "%s ^ %s is not a real number" (fmt_num x) (fmt_num y);
      num r
  | (Eq | Ne), _, _ ->
      let eq =
        match (a, b) with
        | VNum x, VNum y -> Float.equal x y
        | VBool x, VBool y -> x = y
        | VStr x, VStr y -> String.equal x y
        | VVec x, VVec y ->
            Float.equal x.x y.x && Float.equal x.y y.y && Float.equal x.z y.z
        | _ -> bad ()
      in
      VBool (match op with Eq -> eq | _ -> not eq)
  | (Lt | Le | Gt | Ge), VNum x, VNum y ->
      VBool (match op with Lt -> x < y | Le -> x <= y | Gt -> x > y | _ -> x >= y)
  | _ -> bad ()

(* ------------------------------------------------------------------------------------ *)
(* Blocks: fields, their types and ranges *)

let rec eval_material ctx env loc items =
  material_of ctx loc
    (collect ctx env
       { sink = ref []; in_group = false; in_csg = false }
       "material" loc ~holds_objects:false items)

(* The material a material block states, once its fields are evaluated. *)
and material_of ctx loc b =
  check_names b material_fields;
  (* A field left out keeps the base's value; without a base, the schema's default. *)
  let base =
    match live b "base" with
    | None -> ctx.specs.material
    | Some f -> (
        match f.value with
        | VMat m -> m
        | v ->
            bad b f.vloc "`base` must be a material, got %s" (type_name v);
            ctx.specs.material)
  in
  let d = base in
  let m : D.material =
    {
      color = color b "color" ~default:d.color;
      texture = d.texture;
      ambient = number b "ambient" ~default:d.ambient;
      diffuse = number b "diffuse" ~default:d.diffuse;
      specular = number b "specular" ~default:d.specular;
      shininess = number b "shininess" ~default:d.shininess;
      reflection = number b "reflection" ~default:d.reflection;
      transparency = number b "transparency" ~default:d.transparency;
      ior = number b "ior" ~default:d.ior;
      fresnel = boolean b "fresnel" ~default:d.fresnel;
      bump = d.bump;
    }
  in
  let m =
    match live b "texture" with
    | None -> m
    | Some f -> (
        match f.value with
        | VTex t -> (
            match texture ctx t with
            | Ok tex -> { m with texture = Some tex }
            | Error msg ->
                bad b (image_loc t f.vloc) "%s" msg;
                m)
        | VVec v -> { m with texture = Some (D.Solid (Color.of_vec3 v)) }
        | v ->
            bad b f.vloc "`texture` must be a texture (checker(…), stripes(…), …), got %s"
              (type_name v);
            m)
  in
  let m =
    match live b "bump" with
    | None -> m
    | Some f -> (
        match f.value with
        | VTex t -> (
            match bump ctx t with
            | Ok bm -> { m with bump = Some bm }
            | Error msg ->
                bad b (image_loc t f.vloc) "%s" msg;
                m)
        | v ->
            bad b f.vloc
              "`bump` must be noise(scale, amount) or image(\"file.png\", amount), got %s"
              (type_name v);
            m)
  in
  (match (field b "reflection", field b "transparency") with
  | (Some _, _ | _, Some _) when m.reflection +. m.transparency > 1. && not b.failed ->
      let f =
        match field b "transparency" with
        | Some f -> f
        | None -> Option.get (field b "reflection")
      in
      bad b f.vloc "reflection + transparency must be at most 1, got %s + %s = %s"
        (fmt_num m.reflection) (fmt_num m.transparency)
        (fmt_num (m.reflection +. m.transparency))
  | _ -> ());
  finish b;
  (match D.validate_material m with
  | Ok () -> ()
  | Error msg -> fail loc "invalid material: %s" msg);
  VMat m

(* Where an [image(…)] texture's problem is shown: at the call that names the file (which
   may be a `let` away from the field that uses it); other textures at the field. *)
and image_loc t field_loc = if t.tname = "image" then t.tloc else field_loc

(* The image file of an [image(…)] texture or bump map, relative to the scene file that
   names it; the renderer reads it (and reports a problem with it at the call). *)
and image_file ctx t =
  match t.targs with
  | VStr p :: _ ->
      let path = Loc.relative_to t.tloc.file p in
      Hashtbl.replace ctx.used path ();
      let im = { D.written = p; path; at = t.tloc } in
      ctx.on_file (D.Picture im);
      Ok im
  | _ -> Error "image(…) needs a file name"

and texture ctx t =
  let c i =
    match List.nth t.targs i with
    | VVec v -> Ok (Color.of_vec3 v)
    | v ->
        Error
          (Printf.sprintf "argument %d of `%s` must be a colour (r, g, b), got %s" (i + 1)
             t.tname (type_name v))
  in
  let n i =
    match List.nth t.targs i with
    | VNum x -> Ok x
    | v ->
        Error
          (Printf.sprintf "argument %d of `%s` must be a number, got %s" (i + 1) t.tname
             (type_name v))
  in
  let ( let* ) = Result.bind in
  let size i what =
    let* s = n i in
    if s >= 1e-150 && s <= 1e150 then Ok s
    else
      Error
        (Printf.sprintf "the %s of `%s` must be in [1e-150, 1e150], got %s" what t.tname
           (fmt_num s))
  in
  let solid mk =
    let* c1 = c 0 in
    let* c2 = c 1 in
    let* s =
      size 2 (if t.tname = "checker" || t.tname = "stripes" then "size" else "scale")
    in
    Ok (mk c1 c2 s)
  in
  match (t.tname, List.length t.targs) with
  | "checker", _ -> solid (fun c1 c2 size -> D.Checker { c1; c2; size })
  | "stripes", _ -> solid (fun c1 c2 size -> D.Stripes { c1; c2; size })
  | ("noise" | "marble" | "wood"), 2
    when match t.targs with VTex { tname = "color_map"; _ } :: _ -> true | _ -> false -> (
      match t.targs with
      | [ VTex cm; _ ] ->
          let* scale = size 1 "scale" in
          let* map = color_map cm in
          let pattern =
            match t.tname with
            | "noise" -> D.Noise_pattern scale
            | "marble" -> D.Marble_pattern scale
            | _ -> D.Wood_pattern scale
          in
          Ok (D.Mapped { pattern; map })
      | _ ->
          Error
            (Printf.sprintf "%s(color_map(…), scale) takes a colour map and a number"
               t.tname))
  | "marble", 2 | "wood", 2 ->
      Error (Printf.sprintf "%s takes (c1, c2, scale) or (color_map(…), scale)" t.tname)
  | "noise", 3 -> solid (fun c1 c2 scale -> D.Noise { c1; c2; scale })
  | "marble", _ -> solid (fun c1 c2 scale -> D.Marble { c1; c2; scale })
  | "wood", _ -> solid (fun c1 c2 scale -> D.Wood { c1; c2; scale })
  | "noise", _ ->
      Error
        "noise(scale, amount) is a bump map: use it as `bump:`; as a texture, noise \
         takes (c1, c2, scale)"
  | "gradient", _ -> (
      match t.targs with
      | [ VVec axis; VTex ({ tname = "color_map"; _ } as cm) ] ->
          if not (Vec3.max_abs axis > 0. && Vec3.max_abs axis <= 1e150) then
            Error "the axis of `gradient` must be a non-zero vector within ±1e150"
          else
            let* map = color_map cm in
            Ok (D.Gradient { axis; map })
      | _ ->
          Error
            "gradient(HORIZON, ZENITH) with two colours is a background (settings { \
             background: … }); as a texture, write gradient(AXIS, color_map(…))")
  | "color_map", _ ->
      Error
        "a color_map is the colours of a texture, not a texture itself: write \
         gradient(AXIS, color_map(…))"
  | "image", _ -> (
      (* The file is the renderer's to read, once the call is right. *)
      match t.targs with
      | [ VStr _; VNum scale ] when scale >= 1e-150 && scale <= 1e150 ->
          let* image = image_file ctx t in
          Ok (D.Image { image; scale })
      | [ VStr _; VNum scale ] ->
          Error
            (Printf.sprintf "the scale of `image` must be in [1e-150, 1e150], got %s"
               (fmt_num scale))
      | [ VStr _ ] ->
          Error
            "image(\"file.png\", scale) needs a scale (1 maps the picture once onto the \
             surface's (u, v))"
      | _ -> Error "image(\"file.png\", scale) takes a file name and a number")
  | _ -> Error (Printf.sprintf "`%s` is not a texture" t.tname)

and color_map t =
  let entries =
    List.filter_map
      (function VPair (VNum x, VVec c) -> Some (x, Color.of_vec3 c) | _ -> None)
      t.targs
  in
  match D.color_map_problem entries with Some m -> Error m | None -> Ok entries

and bump ctx t =
  match (t.tname, t.targs) with
  | "noise", [ VNum scale; VNum amount ] ->
      if not (scale >= 1e-150 && scale <= 1e150) then
        Error
          (Printf.sprintf "the scale of a noise bump must be in [1e-150, 1e150], got %s"
             (fmt_num scale))
      else if not (Float.abs amount <= 1e150) then
        Error "the amount of a noise bump is out of range"
      else Ok (D.Noise_bump { scale; amount })
  | "noise", [ _; _ ] -> Error "a noise bump map takes two numbers: noise(scale, amount)"
  | "image", [ VStr _; VNum amount ] when Float.abs amount <= 1e150 ->
      Result.map (fun image -> D.Image_bump { image; amount }) (image_file ctx t)
  | "image", _ ->
      Error "an image bump map takes a file name and an amount: image(\"h.png\", amount)"
  | _ ->
      Error
        (Printf.sprintf
           "`%s(…)` is not a bump map: use noise(scale, amount) or image(\"file.png\", \
            amount)"
           t.tname)

and collect ?(csg = false) ctx fr scope kind kloc ~holds_objects (items : citem list) =
  let b =
    {
      ctx;
      kind;
      kloc;
      spec = spec_for ctx kind;
      fields = [];
      failed = false;
      members = ref [];
    }
  in
  let inner =
    { sink = b.members; in_group = scope.in_group || holds_objects; in_csg = csg }
  in
  List.iter
    (function
      | CField (n, code, vloc) -> (
          match code fr with
          | v -> b.fields <- { name = n; value = v; vloc } :: b.fields
          | exception Fail (l, m) ->
              report ctx l m;
              poisoned_field b n vloc
          | exception Poisoned -> poisoned_field b n vloc)
      | CDup (n, line) ->
          bad b n.nloc "`%s` is given twice in this %s (first at line %d)" n.id kind line
      | CStmt code -> code fr inner
      | CRefused loc ->
          bad b loc
            "a %s holds only `field: value` pairs (and `let`); objects go in a `group`"
            kind)
    items;
  b.fields <- List.rev b.fields;
  b

(* A field whose value failed (already reported) is kept as poisoned, so that it is
   neither unknown nor missing, and the block is not built. *)
and poisoned_field b n vloc =
  b.failed <- true;
  b.fields <- { name = n; value = VPoison; vloc } :: b.fields

(* The objects a list of statements surely builds each time it runs: object blocks, and
   those of groups; not those behind a condition (the smaller branch), a macro call or an
   inner loop (which checks its own). *)

and objects_written stmts =
  List.fold_left
    (fun n (s : stmt) ->
      n
      +
      match s.s with
      | Block (k, _) when Schema.is_shape k.id -> 1
      | Block
          ({ id = "group" | "union" | "merge" | "intersection" | "difference"; _ }, its)
        ->
          objects_written
            (List.filter_map (function Stmt s -> Some s | Field _ -> None) its)
      | If_stmt (_, t, e) -> min (objects_written t) (objects_written e)
      | Included (_, b) -> objects_written b
      | _ -> 0)
    0 stmts

and check_params params =
  let rec go = function
    | [] -> ()
    | (p : name) :: rest ->
        if List.exists (fun (q : name) -> q.id = p.id) rest then
          fail p.nloc "parameter `%s` is named twice" p.id;
        go rest
  in
  go params

and dup_params params =
  match check_params params with () -> false | exception Fail _ -> true

and add_object ctx scope loc o =
  ctx.objects <- ctx.objects + 1;
  if ctx.objects land 0xFFFF = 0 then Option.iter (fun f -> f ctx.objects) ctx.on_objects;
  if ctx.objects > max_objects then
    limit ctx loc
      (Printf.sprintf "this scene builds more than %d objects; that is the limit"
         max_objects);
  if ctx.objects land 1023 = 0 then
    Option.iter (limit ctx loc) (memory_refusal ctx.objects);
  scope.sink := o :: !(scope.sink)

and once : 'a. ctx -> string -> ('a * Loc.t) option -> name -> unit =
 fun ctx what slot k ->
  match slot with
  | Some (_, l) ->
      ignore ctx;
      fail k.nloc "%s is given twice (the first is at %s:%d:%d)" what l.file l.line l.col
  | None -> ()

and settings ctx env scope k items =
  once ctx "settings" ctx.settings k;
  let b = collect ctx env scope "settings" k.nloc ~holds_objects:false items in
  check_names b (field_names_of "settings");
  let gamma =
    let e = entry b "gamma" in
    let gamma = function
      | VStr s when String.lowercase_ascii s = "srgb" -> Some Settings.Srgb
      | VNum g when Schema.in_range e.sch.range g -> Some (Settings.Power g)
      | _ -> None
    in
    let default = Option.get (gamma e.default) in
    match live b "gamma" with
    | None -> default
    | Some f -> (
        match gamma f.value with
        | Some g -> g
        | None ->
            bad b f.vloc "`gamma` must be \"srgb\" or a number in %s"
              (Schema.range_text e.sch.range);
            default)
  in
  let s : Settings.t =
    {
      width = integer b "width";
      height = integer b "height";
      depth = integer b "depth";
      samples = integer b "samples";
      jitter = boolean b "jitter";
      adaptive = number b "adaptive";
      shadows = boolean b "shadows";
      background =
        (match live b "background" with
        | Some { value = VTex _; _ } ->
            (* a gradient's horizon, once [environment] has read it *)
            Color.of_vec3 (Option.get (as_vector (entry b "background").default))
        | _ -> color b "background");
      sky = None;
      fog = None;
      ambient = color b "ambient";
      gamma;
    }
  in
  let s = environment b s in
  finish b;
  (match Settings.validate s with
  | Ok () -> ()
  | Error m -> fail k.nloc "invalid settings: %s" m);
  ctx.settings <- Some (s, k.nloc)

(* A gradient background and fog, from the settings block's `background` and `fog`. *)
and environment b (s : Settings.t) =
  let colour_arg (v : value) =
    match v with
    | VVec c when c.x >= 0. && c.y >= 0. && c.z >= 0. -> Some (Color.of_vec3 c)
    | _ -> None
  in
  let s =
    match live b "background" with
    | Some ({ value = VTex { tname = "gradient"; targs = [ h; z ]; _ }; _ } as f) -> (
        match (colour_arg h, colour_arg z) with
        | Some horizon, Some zenith ->
            { s with background = horizon; sky = Some { horizon; zenith } }
        | _ ->
            bad b f.vloc
              "a background gradient(HORIZON, ZENITH) takes two colours (r, g, b) with \
               no negative component";
            s)
    | Some ({ value = VTex _; _ } as f) ->
        bad b f.vloc
          "`background` must be a colour (r, g, b) or gradient(HORIZON, ZENITH), got %s"
          (type_name f.value);
        s
    | _ -> s
  in
  match live b "fog" with
  | None -> s
  | Some { value = VTex { tname = "fog"; targs = [ VVec c; VNum distance ]; _ }; vloc; _ }
    ->
      if c.x < 0. || c.y < 0. || c.z < 0. then (
        bad b vloc "the colour of `fog` has no negative component";
        s)
      else { s with fog = Some { color = Color.of_vec3 c; distance } }
  | Some f ->
      bad b f.vloc "`fog` must be fog(COLOR, DISTANCE), got %s" (type_name f.value);
      s

and camera ctx env scope k items =
  once ctx "camera" ctx.camera k;
  let b = collect ctx env scope "camera" k.nloc ~holds_objects:false items in
  check_names b (field_names_of "camera");
  let kinds = [ "perspective"; "orthographic"; "fisheye" ] in
  (* An unknown kind is reported once; the fields that depend on the kind are then not
     checked against a guess. *)
  let kind_name =
    match live b "kind" with
    | None -> ( match (entry b "kind").default with VStr s -> s | _ -> "perspective")
    | Some { value = VStr s; _ } when List.mem s kinds -> s
    | Some { value = VStr s; vloc; _ } ->
        (match suggest s kinds with
        | Some k -> bad b vloc "unknown camera kind \"%s\"; did you mean \"%s\"?" s k
        | None ->
            bad b vloc
              "unknown camera kind \"%s\"; use \"perspective\", \"orthographic\" or \
               \"fisheye\""
              s);
        "unknown"
    | Some f ->
        bad b f.vloc
          "`kind` must be a string (\"perspective\", \"orthographic\" or \"fisheye\"), \
           got %s"
          (type_name f.value);
        "unknown"
  in
  let position = point b "position" in
  let look_at = point b "look_at" in
  let up = point b "up" in
  (* The default and the range of `fov` depend on the kind (the range is checked below). *)
  let fov_of kind =
    List.find_opt
      (fun e ->
        e.sch.name = "fov"
        && match e.sch.condition with Kind_in ks -> List.mem kind ks | _ -> false)
      b.spec.entries
  in
  let fov =
    let e = Option.value (fov_of kind_name) ~default:(entry b "fov") in
    number b "fov" ~default:(fallback None e as_number) ~check:(fun _ x -> x)
  in
  let perspective = Option.get (fov_of "perspective")
  and fisheye = Option.get (fov_of "fisheye") in
  (match field b "fov" with
  | Some f when kind_name = "fisheye" && not (Schema.in_range fisheye.sch.range fov) ->
      bad b f.vloc "a fisheye's `fov` %s, got %s" fisheye.must (fmt_num fov)
  | Some f when kind_name = "orthographic" ->
      bad b f.vloc
        "an orthographic camera has no `fov`: its `width` sets how much it sees"
  | Some f
    when kind_name = "perspective" && not (Schema.in_range perspective.sch.range fov) ->
      bad b f.vloc "`fov` %s, got %s%s" perspective.must (fmt_num fov)
        (if Schema.in_range fisheye.sch.range fov then
           " (a wider view needs kind: \"fisheye\")"
         else "")
  | _ -> ());
  let width =
    match field b "width" with
    | Some f when kind_name <> "orthographic" && kind_name <> "unknown" ->
        bad b f.vloc "`width` is for an orthographic camera (kind: \"orthographic\")";
        1.
    | None when kind_name = "orthographic" ->
        bad b k.nloc
          "an orthographic camera needs a `width` (world units across the image)";
        1.
    | _ -> number b "width"
  in
  let aperture = number b "aperture" in
  (* Without an aperture, the focal distance is the camera's own default (unused). *)
  let focal_distance = number b "focal_distance" ~default:Camera.default.focal_distance in
  let lens_samples = integer b "lens_samples" in
  (match (field b "aperture", field b "focal_distance") with
  | Some _, None when aperture > 0. ->
      bad b k.nloc
        "a camera with an `aperture` needs a `focal_distance` (the distance that is in \
         focus)"
  | _ -> ());
  finish b;
  let view = Vec3.sub look_at position in
  (if Vec3.max_abs view > 0. && Vec3.max_abs up > 0. then
     let cos = Vec3.dot view up /. (Vec3.length view *. Vec3.length up) in
     if Float.abs cos > 1. -. 1e-12 then
       let at =
         match (field b "up", field b "look_at") with
         | Some f, _ | None, Some f -> f.vloc
         | None, None -> k.nloc
       in
       fail at "%s" (Hints.camera_up view up));
  let kind =
    match kind_name with
    | "orthographic" -> Camera.Orthographic { width }
    | "fisheye" -> Camera.Fisheye
    | _ -> Camera.Perspective
  in
  let c =
    Camera.make ~kind ~position ~look_at ~up ~fov ~aperture ~focal_distance ~lens_samples
      ()
  in
  (match Camera.validate c with
  | Ok () -> ()
  | Error m -> fail k.nloc "invalid camera: %s" m);
  ctx.camera <- Some (c, k.nloc)

and animation ctx env scope k items =
  once ctx "animation" ctx.animation k;
  let b = collect ctx env scope "animation" k.nloc ~holds_objects:false items in
  check_names b (field_names_of "animation");
  (* A rate above its limit is told as such, not as a range. *)
  let fps =
    let e = entry b "fps" in
    number b "fps" ~check:(fun f x ->
        (match e.sch.range with
        | Real (Excl lo, Incl hi) ->
            if not (x > lo && x <= Schema.big) then
              bad b f.vloc "`fps` must be greater than %s, got %s" (fmt_num lo)
                (fmt_num x);
            if x > hi then bad b f.vloc "`fps` must be at most %s" (fmt_num hi)
        | r ->
            if not (Schema.in_range r x) then
              bad b f.vloc "`fps` %s, got %s" e.must (fmt_num x));
        x)
  in
  let frames =
    match (field b "frames", field b "duration") with
    | Some _, Some f ->
        bad b f.vloc "give `frames` or `duration`, not both";
        1
    | _, None -> integer b "frames"
    | None, Some f ->
        let d = number b "duration" in
        let n = Float.round (d *. fps) in
        let most =
          match (entry b "frames").sch.range with Whole (_, hi) -> hi | _ -> max_int
        in
        if n > Float.of_int most then (
          bad b f.vloc "this animation would have more than %s frames" (grouped most);
          1)
        else max 1 (int_of_float n)
  in
  finish b;
  ctx.animation <- Some ((fps, frames), k.nloc)

and physics ctx env scope k items =
  once ctx "physics" ctx.physics k;
  let b = collect ctx env scope "physics" k.nloc ~holds_objects:false items in
  check_names b (field_names_of "physics");
  let gravity = point b "gravity" in
  let method_ =
    let default =
      match (entry b "method").default with
      | VStr "verlet" -> Verlet
      | VStr "euler" -> Euler
      | _ -> Exact
    in
    match live b "method" with
    | None -> default
    | Some { value = VStr "exact"; _ } -> Exact
    | Some { value = VStr "verlet"; _ } -> Verlet
    | Some { value = VStr "euler"; _ } -> Euler
    | Some { value = VStr s; vloc; _ } ->
        bad b vloc
          "unknown physics method \"%s\"%s; use \"exact\", \"verlet\" or \"euler\"" s
          (hint s [ "exact"; "verlet"; "euler" ]);
        default
    | Some f ->
        bad b f.vloc
          "`method` must be a string (\"exact\", \"verlet\" or \"euler\"), got %s"
          (type_name f.value);
        default
  in
  let step = number b "step" in
  finish b;
  ctx.physics <- Some ({ gravity; method_; step }, k.nloc)

and light ctx env scope k items =
  let b = collect ctx env scope "light" k.nloc ~holds_objects:false items in
  match (field b "position", field b "direction") with
  | Some _, Some f ->
      bad b f.vloc
        "a light has a `position` (point light) or a `direction` (directional light), \
         not both";
      finish b
  | None, None ->
      bad b k.nloc
        "a light needs a `position` (point light) or a `direction` (directional light)";
      finish b
  | Some _, None ->
      check_names b (field_names_of "point_light");
      b.spec <- spec_for ctx "point_light";
      let position = point b "position" in
      let color = color b "color" in
      let intensity = number b "intensity" in
      let attenuation = point b "attenuation" in
      (match field b "attenuation" with
      | Some f
        when attenuation.x < 0. || attenuation.y < 0. || attenuation.z < 0.
             || Vec3.max_abs attenuation = 0. ->
          bad b f.vloc "`attenuation` (a0, a1, a2) must be non-negative and not all zero"
      | _ -> ());
      let radius = number b "radius" in
      let samples = integer b "samples" in
      let spot =
        match field b "point_at" with
        | None ->
            List.iter
              (fun n ->
                match field b n with
                | Some f ->
                    bad b f.name.nloc "`%s` is for a spot light: give it a `point_at`" n
                | None -> ())
              [ "inner"; "outer" ];
            None
        | Some pf -> (
            let point_at = point b "point_at" in
            let inner = number b "inner" and outer = number b "outer" in
            if b.failed then None
            else
              match Light.spot ~position ~point_at ~inner ~outer with
              | Ok sp -> Some sp
              | Error m ->
                  (* At point_at when it is the position, else at the angle written last. *)
                  let at_angle = List.filter_map (field b) [ "outer"; "inner" ] in
                  let loc =
                    match at_angle with
                    | f :: _ when Vec3.max_abs (Vec3.sub point_at position) > 0. -> f.vloc
                    | _ -> pf.vloc
                  in
                  bad b loc "%s" m;
                  None)
      in
      finish b;
      ctx.lights <-
        Light.point ~color ~intensity ~attenuation ~radius ~samples ?spot position
        :: ctx.lights
  | None, Some f ->
      check_names b (field_names_of "directional_light");
      b.spec <- spec_for ctx "directional_light";
      let direction = point b "direction" in
      if Vec3.max_abs direction = 0. then
        bad b f.vloc "the `direction` of a light must not be (0, 0, 0)";
      let color = color b "color" in
      let intensity = number b "intensity" in
      finish b;
      ctx.lights <- Light.directional ~color ~intensity direction :: ctx.lights

and transforms b =
  (* translate / rotate / scale, in the order written *)
  List.fold_left
    (fun (t, js) f ->
      match (f.name.id, f.value) with
      | _, VPoison -> (t, js) (* its value failed, already reported *)
      | "translate", VVec v ->
          check_coords b f v;
          (Transform.then_ t (Transform.translate v), js @ [ D.Translate v ])
      | "rotate", VVec v ->
          check_coords b f v;
          (Transform.then_ t (Transform.rotate v), js @ [ D.Rotate v ])
      | "scale", (VNum _ | VVec _) ->
          let v =
            match f.value with VNum s -> Vec3.v s s s | VVec v -> v | _ -> Vec3.one
          in
          let ok x = Float.abs x >= 1e-150 && Float.abs x <= 1e150 in
          if not (ok v.x && ok v.y && ok v.z) then (
            bad b f.vloc
              "`scale` factors must be non-zero, with magnitudes in [1e-150, 1e150]";
            (t, js))
          else (Transform.then_ t (Transform.scale v), js @ [ D.Scale v ])
      | ("translate" | "rotate"), v ->
          bad b f.vloc "`%s` must be a vector (x, y, z), got %s" f.name.id (type_name v);
          (t, js)
      | "scale", v ->
          bad b f.vloc "`scale` must be a number or a vector, got %s" (type_name v);
          (t, js)
      | _ -> (t, js))
    (Transform.identity, []) b.fields

and object_material b =
  match live b "material" with
  | None -> None
  | Some { value = VMat m; _ } -> Some m
  | Some f ->
      bad b f.vloc "`material` must be a material (material { … }), got %s"
        (type_name f.value);
      None

and object_ ctx env scope (k : name) items =
  object_of (collect ctx env scope k.id k.nloc ~holds_objects:false items) k

(* The object a shape block states, once its fields are evaluated. *)
and object_of ?(known = false) ?(plain = false) b (k : name) =
  if not known then check_names b (field_names_of k.id);
  let t, tj = if plain then (Transform.identity, []) else transforms b in
  let mat = object_material b in
  let shape = shape b k in
  finish b;
  match shape with
  | None -> None
  | Some shape ->
      Some
        {
          D.kind = k.id;
          shape;
          transform = t;
          steps = tj;
          material = mat;
          loc = k.nloc;
          body = None;
        }

and shape b (k : name) : D.shape option =
  let built sh = if b.failed then None else Some sh in
  match k.id with
  | "sphere" ->
      let center = point b "center" in
      let radius = number b "radius" in
      built (D.Sphere { center; radius })
  | "plane" ->
      let normal = direction b "normal" in
      let offset = number b "offset" in
      built (D.Plane { normal; offset })
  | "parallelogram" ->
      let origin = point b "origin" in
      let edge1 = direction b "edge1" in
      let edge2 = direction b "edge2" in
      if (not b.failed) && Vec3.length (Vec3.cross edge1 edge2) < 1e-300 then
        bad b b.kloc "the edges of a parallelogram must not be parallel";
      built (D.Parallelogram { origin; edge1; edge2 })
  | "triangle" ->
      let a = point b "a" in
      let bb = point b "b" in
      let c = point b "c" in
      if
        (not b.failed) && Vec3.length (Vec3.cross (Vec3.sub bb a) (Vec3.sub c a)) < 1e-300
      then bad b b.kloc "the corners of a triangle must not be in a line";
      built (D.Triangle { a; b = bb; c })
  | "paraboloid" ->
      let vertex = point b "vertex" in
      let axis = direction b "axis" in
      let radius = number b "radius" in
      let height = number b "height" in
      built (D.Paraboloid { vertex; axis; radius; height })
  | "box" ->
      let mn = point b "min" in
      let mx = point b "max" in
      if (not b.failed) && not (mn.x < mx.x && mn.y < mx.y && mn.z < mx.z) then
        bad b b.kloc "a box needs min < max on every axis";
      built (D.Box { min = mn; max = mx })
  | "cylinder" ->
      let base = point b "base" in
      let top = point b "top" in
      let radius = number b "radius" in
      let caps = boolean b "caps" in
      if (not b.failed) && Vec3.length (Vec3.sub top base) < 1e-150 then
        bad b b.kloc "the base and top of a cylinder must differ";
      built (D.Cylinder { base; top; radius; caps })
  | "cone" ->
      let base = point b "base" in
      let top = point b "top" in
      let r0 = number b "base_radius" and r1 = number b "top_radius" in
      let caps = boolean b "caps" in
      if (not b.failed) && Vec3.length (Vec3.sub top base) < 1e-150 then
        bad b b.kloc "the base and top of a cone must differ";
      if (not b.failed) && r0 < 1e-150 && r1 < 1e-150 then
        bad b b.kloc "a cone needs a `base_radius` or a `top_radius` greater than 0";
      built (D.Cone { base; top; base_radius = r0; top_radius = r1; caps })
  | "torus" ->
      let center = point b "center" in
      let major = number b "major" in
      let minor = number b "minor" in
      let axis = direction b "axis" in
      built (D.Torus { center; axis; major; minor })
  | "disk" ->
      let center = point b "center" in
      let normal = direction b "normal" in
      let radius = number b "radius" in
      built (D.Disk { center; normal; radius })
  | "mesh" ->
      let file = file b "file" in
      let smooth = boolean b "smooth" in
      if b.failed then None
      else
        let path = Loc.relative_to b.kloc.file file in
        Hashtbl.replace b.ctx.used path ();
        let at = (Option.get (field b "file")).vloc in
        b.ctx.on_file (D.Model { file; path; smooth; at; solid_in = None });
        Some (D.Mesh { file; path; smooth; at })
  | "height_field" ->
      let file = file b "file" in
      let origin = point b "origin" in
      let size =
        point b "size" ~check:(fun f (size : Vec3.t) ->
            if not (size.x >= 1e-150 && size.y >= 1e-150 && size.z >= 1e-150) then
              bad b f.vloc
                "the `size` (sx, sy, sz) of a height field must be positive on every axis";
            size)
      in
      if b.failed then None
      else
        let path = Loc.relative_to b.kloc.file file in
        Hashtbl.replace b.ctx.used path ();
        let at = (Option.get (field b "file")).vloc in
        b.ctx.on_file (D.Heights { file; path; at });
        Some (D.Height_field { file; path; origin; size; at })
  | _ -> fail k.nloc "%s is not an object" k.id

and group ctx env scope (k : name) items =
  group_of scope (collect ctx env scope "group" k.nloc ~holds_objects:true items)

(* A group's objects, once its items have run: each with the group's transform after its
   own, and its material unless it has one. *)
and group_of scope b =
  check_names b (field_names_of "group");
  let t, tj = transforms b in
  let mat = object_material b in
  finish b;
  group_members scope t tj mat !(b.members)

and group_members scope t tj mat members =
  if Transform.is_identity t && match (tj, mat) with [], None -> true | _ -> false then
    (* Each object would be itself again. *)
    List.iter (fun o -> scope.sink := o :: !(scope.sink)) (List.rev members)
  else
    List.iter
      (fun o ->
        let o =
          {
            o with
            D.transform = Transform.then_ o.D.transform t;
            steps = o.D.steps @ tj;
            material = (match o.D.material with Some _ -> o.D.material | None -> mat);
          }
        in
        scope.sink := o :: !(scope.sink))
      (List.rev members)

(* A CSG block: its members are combined into one object. A group inside a CSG block is
   one member, the union of its own. *)
and csg ctx env scope (k : name) items =
  let b = collect ~csg:true ctx env scope k.id k.nloc ~holds_objects:true items in
  check_names b (field_names_of k.id);
  let t, tj = transforms b in
  let mat = object_material b in
  let members = List.rev !(b.members) in
  let op : D.csg_op =
    match k.id with
    | "merge" -> Merge
    | "intersection" -> Intersection
    | "difference" -> Difference
    | _ -> Union
  in
  let what =
    if k.id = "group" then "a group inside a CSG block" else Printf.sprintf "a `%s`" k.id
  in
  if members = [] && not b.failed then
    bad b k.nloc "%s needs at least one object inside" what;
  if op = Difference && List.length members = 1 then
    bad b k.nloc
      "a `difference` needs a solid to subtract from and at least one to subtract";
  (* A union shows every member's surface; the other operations (and a union that is
     itself a member of one) need each member to have an inside (a mesh's, closed, is
     checked when its file is read). *)
  let need_solid = op <> Union || scope.in_csg in
  List.iter
    (fun o ->
      match o.D.shape with
      | D.Mesh _ -> ()
      | D.Height_field _ ->
          bad b o.D.loc "a %s is not a solid: `%s` combines solids"
            (String.map (function '_' -> ' ' | c -> c) o.D.kind)
            k.id
      | sh when D.is_solid sh || not need_solid -> ()
      | _ ->
          bad b o.D.loc
            "%s is not a solid: %s combines solids (sphere, box, torus, cylinder or cone \
             with caps, closed mesh, plane as a half-space, CSG of solids)%s"
            (match o.D.kind with
            | "mesh" -> "this mesh"
            | "cylinder" -> "a cylinder without caps"
            | "cone" -> "a cone without caps"
            | kd -> Printf.sprintf "a %s" kd)
            (if k.id = "group" then "a CSG block" else Printf.sprintf "`%s`" k.id)
            (if o.D.kind = "cylinder" || o.D.kind = "cone" then "; give it `caps: true`"
             else ""))
    members;
  (* A mesh member must be closed: its file tells. *)
  if need_solid then
    List.iter
      (fun o ->
        match o.D.shape with
        | D.Mesh { file; path; smooth; at } ->
            ctx.on_file
              (D.Model { file; path; smooth; at; solid_in = Some (k.id, o.D.loc) })
        | _ -> ())
      members;
  finish b;
  let member o =
    {
      D.kind = o.D.kind;
      shape = o.D.shape;
      transform = o.D.transform;
      steps = o.D.steps;
      material = o.D.material;
      loc = o.D.loc;
      body = None;
    }
  in
  let o =
    {
      D.kind = (if k.id = "group" then "union" else k.id);
      shape =
        D.Csg { op; block = k.id; members = List.map member members; solid = need_solid };
      transform = t;
      steps = tj;
      material = mat;
      loc = k.nloc;
      body = None;
    }
  in
  add_object ctx scope k.nloc o

and body ctx env scope loc (n : name) items =
  if scope.in_group then fail n.nloc "a body cannot be inside a group or another body";
  if List.exists (fun ((b : body), _) -> b.name = n.id) ctx.bodies then
    fail n.nloc "body `%s` is defined twice" n.id;
  let b = collect ctx env scope "body" n.nloc ~holds_objects:true items in
  check_names b (field_names_of "body");
  let velocity = point b "velocity" in
  let mass = number b "mass" in
  let restitution = number b "restitution" in
  finish b;
  ctx.objects <- ctx.objects - List.length !(b.members);
  match !(b.members) with
  | [ ({ D.shape = D.Sphere { center; radius }; _ } as o) ] ->
      let c0 = Transform.point o.D.transform center in
      (* The simulated sphere is the rendered one: its radius is scaled by the length of
         the transformed axes, which must agree (a rotation keeps them; a non-uniform
         scale would draw an ellipsoid that the physics cannot follow). *)
      let axis a = Vec3.length (Transform.vector o.D.transform a) in
      let sx = axis Vec3.x_axis and sy = axis Vec3.y_axis and sz = axis Vec3.z_axis in
      let lo = Float.min sx (Float.min sy sz) and hi = Float.max sx (Float.max sy sz) in
      if hi > lo *. (1. +. 1e-9) then
        fail n.nloc
          "the sphere of body `%s` is scaled differently along its axes (%s, %s, %s): a \
           body must stay a sphere"
          n.id (fmt_num sx) (fmt_num sy) (fmt_num sz);
      let r = radius *. hi in
      let bd =
        { name = n.id; center = c0; radius = r; velocity; mass; restitution; loc }
      in
      ctx.bodies <- (bd, o) :: ctx.bodies
  | _ -> fail n.nloc "a body holds exactly one sphere { … }"

(* Field access on a block being evaluated. Each accessor reports a wrong type or an
   out-of-range value at the value's location, marks the block failed and returns the
   default, so that every mistake of a block is reported at once. *)
and field b name = find_field name b.fields

(* A field whose value is usable: [None] also when its value failed (already reported). *)
and live b name = match field b name with Some { value = VPoison; _ } -> None | f -> f

and bad : 'a. block -> Loc.t -> ('a, unit, string, unit) format4 -> 'a =
 fun b loc fmt ->
  Printf.ksprintf
    (fun m ->
      report b.ctx loc m;
      b.failed <- true)
    fmt

and finish b = if b.failed then raise Poisoned

and check_names b allowed =
  List.iter
    (fun f ->
      if not (List.mem f.name.id allowed) then
        bad b f.name.nloc "unknown field `%s` in %s%s" f.name.id b.kind
          (hint f.name.id allowed))
    b.fields

and spec_for ctx kind =
  match Hashtbl.find ctx.specs.by_kind kind with
  | sp -> sp
  | exception Not_found -> invalid_arg ("Eval: no block kind " ^ kind ^ " in the schema")

(* The schema's entry for a field of the block (the first, for a field listed under
   several conditions). *)
and entry b name =
  let rec find = function
    | e :: rest -> if String.equal e.sch.name name then e else find rest
    | [] ->
        invalid_arg (Printf.sprintf "Eval: no field %s of %s in the schema" name b.kind)
  in
  find b.spec.entries

(* A field's value as [conv] reads it, then [check]ed; when the field is left out, its
   default ([default], or the schema's); when it is missing although required, or its
   value is wrong, the same after reporting it. *)
(* A field's value as [conv] reads it, [given] the field as found; when the field is
   left out, its default ([default], or the schema's); when it is missing although
   required, or its value is wrong, the same after reporting it. The accessors below read
   a right value, or the default of a field left out, at once and leave the rest to
   this. *)
and get :
    'a. 'a option -> block -> string -> fld option -> string -> (value -> 'a option) -> 'a
    =
 fun default b name given what conv ->
  match given with
  | None ->
      let e = entry b name in
      (* A misspelt field already reported as unknown, with this one as its hint, is not
         reported missing as well (a field of the block's own is not misspelt: a
         triangle's `b` does not stand for a missing `c`). *)
      let misspelt =
        e.required
        && List.exists
             (fun f ->
               (not (List.mem f.name.id b.spec.names))
               && suggest f.name.id [ name ] = Some name)
             b.fields
      in
      if e.required && misspelt then b.failed <- true
      else if e.required then bad b b.kloc "%s needs a `%s` field" b.kind name;
      fallback default e conv
  | Some { value = VPoison; _ } -> fallback default (entry b name) conv
  | Some f -> (
      match conv f.value with
      | Some x -> x
      | None ->
          bad b f.vloc "`%s` must be %s, got %s" name what (type_name f.value);
          fallback default (entry b name) conv)

and fallback : 'a. 'a option -> entry -> (value -> 'a option) -> 'a =
 fun default e conv ->
  match default with
  | Some d -> d
  | None -> (
      match conv e.default with
      | Some x -> x
      | None -> invalid_arg ("Eval: the schema has no default of " ^ e.sch.name))

and as_number = function VNum x -> Some x | _ -> None
and as_vector = function VVec v -> Some v | _ -> None

and check_range b e f x =
  if not (Schema.in_range e.sch.range x) then
    bad b f.vloc "`%s` %s, got %s" e.sch.name e.must (fmt_num x)

(* A number, refused outside the field's range; [check] instead checks it otherwise. *)
and number ?default ?check b name =
  match field b name with
  | Some ({ value = VNum x; _ } as f) -> (
      match check with
      | Some c -> c f x
      | None ->
          check_range b (entry b name) f x;
          x)
  | None as given -> (
      match (default, entry b name) with
      | Some d, { required = false; _ } -> d
      | None, { required = false; default = VNum x; _ } -> x
      | _ -> get default b name given "a number" as_number)
  | given -> get default b name given "a number" as_number

(* A whole number in the field's range. *)
and integer b name =
  match field b name with
  | Some ({ value = VNum x; _ } as f) ->
      let e = entry b name in
      if Schema.in_range e.sch.range x then int_of_float x
      else (
        check_range b e f x;
        int_of_float (fallback None e as_number))
  | given -> int_of_float (get None b name given "a number" as_number)

and boolean ?default b name =
  match field b name with
  | Some { value = VBool x; _ } -> x
  | given ->
      get default b name given "true or false" (function VBool x -> Some x | _ -> None)

and file b name =
  get None b name (field b name) "a file name string" (function
    | VStr s -> Some s
    | _ -> None)

and check_coords b f (v : Vec3.t) =
  let big = Schema.big in
  if not (Float.abs v.x <= big && Float.abs v.y <= big && Float.abs v.z <= big) then
    bad b f.vloc "the coordinates of `%s` must be %s" f.name.id
      (Schema.range_text Schema.coordinate)

(* A vector with coordinates within ±1e150; [check] checks it further. *)
and point ?default ?check b name =
  match field b name with
  | Some ({ value = VVec v; _ } as f) -> (
      check_coords b f v;
      match check with Some c -> c f v | None -> v)
  | None as given -> (
      match (default, entry b name) with
      | Some d, { required = false; _ } -> d
      | None, { required = false; default = VVec v; _ } -> v
      | _ -> get default b name given "a vector (x, y, z)" as_vector)
  | given -> get default b name given "a vector (x, y, z)" as_vector

and direction b name =
  match field b name with
  | Some ({ value = VVec v; _ } as f) ->
      check_coords b f v;
      if Vec3.max_abs v < 1e-150 then bad b f.vloc "`%s` must be a non-zero vector" name;
      v
  | _ -> point b name

and color ?default b name =
  match field b name with
  | Some ({ value = VVec v; _ } as f) ->
      check_coords b f v;
      if v.x < 0. || v.y < 0. || v.z < 0. then
        bad b f.vloc "a colour has no negative component; `%s` is (%s, %s, %s)" name
          (fmt_num v.x) (fmt_num v.y) (fmt_num v.z);
      Color.of_vec3 v
  | _ -> Color.of_vec3 (point ?default:(Option.map Color.to_vec3 default) b name)

(* ------------------------------------------------------------------------------------ *)
(* Compiling a program: names resolved to frame slots once, built-ins to their code *)

(* Where a name's value is, seen from the code being compiled: a slot of the frame, a
   value its function captured, or a constant (the built-ins, pi, time, frame). [true]:
   the slot may hold [unbound] (the name of a body that failed is not defined). *)
type binding = Slot of int * bool | Cap of int * bool | Const of value

(* The function (or the program) being compiled: its slots, and the names it captures
   from around its definition ([parent]), newest first with their index. *)
type fstate = {
  mutable nslots : int;
  mutable caps : (string * int * binding) list;
  mutable ncaps : int;
  parent : cenv option;
}

and cenv = { names : (string * binding) list; fs : fstate }

(* Physically unique: no program makes this very value. *)
let unbound = VStr "(unbound)"
let flagged = function Slot (_, f) | Cap (_, f) -> f | Const _ -> false

let rec resolve ce x =
  match List.assoc_opt x ce.names with
  | Some b -> Some b
  | None -> (
      match List.find_opt (fun (n, _, _) -> String.equal n x) ce.fs.caps with
      | Some (_, i, pb) -> Some (Cap (i, flagged pb))
      | None -> (
          match ce.fs.parent with
          | None -> None
          | Some p -> (
              match resolve p x with
              | None -> None
              | Some (Const v) -> Some (Const v)
              | Some pb ->
                  let i = ce.fs.ncaps in
                  ce.fs.caps <- (x, i, pb) :: ce.fs.caps;
                  ce.fs.ncaps <- i + 1;
                  Some (Cap (i, flagged pb)))))

let new_slot ce =
  let i = ce.fs.nslots in
  ce.fs.nslots <- i + 1;
  i

let bind ce x b = { ce with names = (x, b) :: ce.names }

(* Every name in scope (as an environment would list them: sorted, once each). *)
let scope_names ce =
  let rec go ce acc =
    let acc = List.fold_left (fun acc (n, _) -> n :: acc) acc ce.names in
    match ce.fs.parent with None -> acc | Some p -> go p acc
  in
  List.sort_uniq String.compare (go ce [])

let raw = function
  | Slot (i, _) -> fun fr -> fr.l.(i)
  | Cap (i, _) -> fun fr -> fr.c.(i)
  | Const v -> fun _ -> v

let unknown_name ctx ce x (loc : Loc.t) =
  (* A name defined further down the same file was most likely meant. *)
  let later (d : Loc.t) =
    d.file = loc.file && (d.line > loc.line || (d.line = loc.line && d.col > loc.col))
  in
  match List.find_opt (fun (n, d) -> n = x && later d) (Lazy.force ctx.definitions) with
  | Some (_, d) -> fail loc "unknown name `%s`: %s" x (Hints.defined_later x d)
  | None -> fail loc "unknown name `%s`%s" x (hint x (scope_names ce))

(* The code that reads a name: a poisoned value is not read (already reported). *)
let access ctx ce x loc : code =
  match resolve ce x with
  | Some (Slot (i, false)) -> (
      fun fr -> match fr.l.(i) with VPoison -> raise Poisoned | v -> v)
  | Some (Cap (i, false)) -> (
      fun fr -> match fr.c.(i) with VPoison -> raise Poisoned | v -> v)
  | Some (Const v) -> fun _ -> v
  | Some b -> (
      let get = raw b in
      fun fr ->
        match get fr with
        | VPoison -> raise Poisoned
        | v when v == unbound -> unknown_name ctx ce x loc
        | v -> v)
  | None -> fun _ -> unknown_name ctx ce x loc

let[@inline] num loc r = if r -. r = 0. then VNum r else VNum (finite loc r)
let vtrue = VBool true
let vfalse = VBool false
let[@inline] vbool b = if b then vtrue else vfalse

(* The locals of a call of [name] (its [nparams] parameters first, [nslots] in all), its
   arguments evaluated in the caller's frame, in order. *)
let call_frame name nparams nslots (args : code array) loc fr =
  let na = Array.length args in
  if nparams <> na then
    fail loc "`%s` takes %d argument%s, got %d" name nparams
      (if nparams = 1 then "" else "s")
      na;
  let l = Array.make nslots VPoison in
  for k = 0 to na - 1 do
    l.(k) <- args.(k) fr
  done;
  l

let call_fun ctx c (args : code array) loc fr =
  let l = call_frame c.fname c.nparams c.fslots args loc fr in
  enter ctx loc;
  match c.fbody { l; c = c.fcaps } with
  | v ->
      ctx.depth <- ctx.depth - 1;
      v
  | exception e ->
      ctx.depth <- ctx.depth - 1;
      raise e

let call_macro ctx m (args : code array) loc fr sc =
  let l = call_frame m.mname m.mnparams m.mslots args loc fr in
  enter ctx loc;
  match m.mbody { l; c = m.mcaps } sc with
  | () -> ctx.depth <- ctx.depth - 1
  | exception e ->
      ctx.depth <- ctx.depth - 1;
      raise e

(* A built-in called with arguments evaluated in order; a poisoned one is not passed. *)
let generic_builtin name loc (cargs : (code * Loc.t) list) : code =
  let code = builtin_code name and bn = List.length cargs in
  fun fr ->
    let args = List.map (fun (c, l) -> (c fr, l)) cargs in
    List.iter (fun (v, _) -> match v with VPoison -> raise Poisoned | _ -> ()) args;
    code { bname = name; bloc = loc; bargs = args; bn }

(* A built-in resolved once: the common numeric ones with their arguments straight from
   the frame; any other case (or a wrong argument, for its message) through
   [builtin_code]. *)
let builtin_call name loc (cargs : (code * Loc.t) list) : code =
  match cargs with
  | [ (a, al) ] -> (
      let code = builtin_code name in
      let slow v =
        match v with
        | VPoison -> raise Poisoned
        | _ -> code { bname = name; bloc = loc; bargs = [ (v, al) ]; bn = 1 }
      in
      match name with
      | "sin" -> ( fun fr -> match a fr with VNum x -> num loc (sin x) | v -> slow v)
      | "cos" -> ( fun fr -> match a fr with VNum x -> num loc (cos x) | v -> slow v)
      | "tan" -> ( fun fr -> match a fr with VNum x -> num loc (tan x) | v -> slow v)
      | "atan" -> ( fun fr -> match a fr with VNum x -> num loc (atan x) | v -> slow v)
      | "exp" -> ( fun fr -> match a fr with VNum x -> num loc (exp x) | v -> slow v)
      | "abs" -> (
          fun fr -> match a fr with VNum x -> num loc (Float.abs x) | v -> slow v)
      | "floor" -> (
          fun fr -> match a fr with VNum x -> num loc (Float.floor x) | v -> slow v)
      | "ceil" -> (
          fun fr -> match a fr with VNum x -> num loc (Float.ceil x) | v -> slow v)
      | "round" -> (
          fun fr -> match a fr with VNum x -> num loc (Float.round x) | v -> slow v)
      | "sqrt" -> (
          fun fr ->
            match a fr with VNum x when x >= 0. -> num loc (sqrt x) | v -> slow v)
      | "log" -> (
          fun fr -> match a fr with VNum x when x > 0. -> num loc (log x) | v -> slow v)
      | "rand" -> (
          fun fr -> match a fr with VNum x -> VNum (Hash.of_float x) | v -> slow v)
      | _ -> generic_builtin name loc cargs)
  | [ (a, al); (b, bl) ] -> (
      let code = builtin_code name in
      let slow va vb =
        (match (va, vb) with VPoison, _ | _, VPoison -> raise Poisoned | _ -> ());
        code { bname = name; bloc = loc; bargs = [ (va, al); (vb, bl) ]; bn = 2 }
      in
      match name with
      | "min" -> (
          fun fr ->
            let va = a fr in
            let vb = b fr in
            match (va, vb) with VNum x, VNum y -> VNum (Float.min x y) | _ -> slow va vb)
      | "max" -> (
          fun fr ->
            let va = a fr in
            let vb = b fr in
            match (va, vb) with VNum x, VNum y -> VNum (Float.max x y) | _ -> slow va vb)
      | "pow" -> (
          fun fr ->
            let va = a fr in
            let vb = b fr in
            match (va, vb) with
            | VNum x, VNum y -> num loc (Float.pow x y)
            | _ -> slow va vb)
      | "atan2" -> (
          fun fr ->
            let va = a fr in
            let vb = b fr in
            match (va, vb) with
            | VNum x, VNum y -> num loc (Float.atan2 x y)
            | _ -> slow va vb)
      | _ -> generic_builtin name loc cargs)
  | _ -> generic_builtin name loc cargs

let dot_value ctx (f : name) v =
  match (v, f.id) with
  | VVec v, "x" -> VNum v.x
  | VVec v, "y" -> VNum v.y
  | VVec v, "z" -> VNum v.z
  | VVec _, x -> fail f.nloc "a vector has components `x`, `y` and `z`, not `%s`" x
  | VBody name, ("position" | "velocity") ->
      let b, _ = List.find (fun ((b : body), _) -> b.name = name) ctx.bodies in
      let pos, vel =
        match Option.bind ctx.body_state (fun f -> f name ctx.time) with
        | Some pv -> pv
        | None -> (b.center, b.velocity)
      in
      VVec (if f.id = "position" then pos else vel)
  | VBody _, x ->
      fail f.nloc "a body has `position` and `velocity`, not `%s`%s" x
        (hint x [ "position"; "velocity" ])
  | v, x -> fail f.nloc "`.%s` needs a vector or a body, got %s" x (type_name v)

let component (e : expr) v =
  match v with
  | VNum x -> x
  | v -> fail e.loc "a vector component must be a number, got %s" (type_name v)

(* A material block of plain fields only (colour, numbers, fresnel; no base, texture or
   bump), each once: where each field is is settled here, once per site; its values are
   evaluated in order, as [collect] would, and a right set of them is the material at
   once. Anything else (a wrong type, a value out of range, a failed value) is read by
   [material_of], for its messages. The same values as the site's last material give
   that material again (a site whose fields are constants builds one). *)
exception Slow

let plain_material_fields =
  [
    "color";
    "ambient";
    "diffuse";
    "specular";
    "shininess";
    "reflection";
    "transparency";
    "ior";
    "fresnel";
  ]

(* The transforms of a block (translate, rotate, scale in the order written) read by
   position: where each is is settled once per site. The reading raises [Slow] when one
   is wrong (the block's own reading then tells what is wrong). *)
let fast_transforms ids =
  let big = Schema.big in
  let coords (v : Vec3.t) =
    Float.abs v.x <= big && Float.abs v.y <= big && Float.abs v.z <= big
  in
  let steps =
    Array.of_list
      (List.filter_map Fun.id
         (List.mapi
            (fun i id ->
              match id with
              | "translate" -> Some (i, 0)
              | "rotate" -> Some (i, 1)
              | "scale" -> Some (i, 2)
              | _ -> None)
            ids))
  in
  let nsteps = Array.length steps in
  let factor x = Float.abs x >= 1e-150 && Float.abs x <= 1e150 in
  let transform vals =
    let t = ref Transform.identity in
    for s = 0 to nsteps - 1 do
      let i, what = steps.(s) in
      t :=
        Transform.then_ !t
          (match (what, vals.(i)) with
          | 0, VVec v when coords v -> Transform.translate v
          | 1, VVec v when coords v -> Transform.rotate v
          | 2, VNum x when factor x -> Transform.scale (Vec3.v x x x)
          | 2, VVec v when factor v.x && factor v.y && factor v.z -> Transform.scale v
          | _ -> raise_notrace Slow)
    done;
    let js = ref [] in
    for s = nsteps - 1 downto 0 do
      let i, what = steps.(s) in
      js :=
        (match (what, vals.(i)) with
        | 0, VVec v -> D.Translate v
        | 1, VVec v -> D.Rotate v
        | 2, VNum x -> D.Scale (Vec3.v x x x)
        | 2, VVec v -> D.Scale v
        | _ -> raise_notrace Slow)
        :: !js
    done;
    (!t, !js)
  in
  (nsteps, transform)

(* A site's last material and the values it was made of. *)
type last_material = { mutable pvals : value array; mutable pmat : value }

let fast_material ctx loc (its : citem list) : code option =
  let fields =
    List.filter_map (function CField (n, c, l) -> Some (n, c, l) | _ -> None) its
  in
  let ids = List.map (fun ((n : name), _, _) -> n.id) fields in
  if
    not
      (List.length fields = List.length its
      && List.length (List.sort_uniq String.compare ids) = List.length ids
      && List.for_all (fun id -> List.mem id plain_material_fields) ids)
  then None
  else
    let spec = spec_for ctx "material" in
    let index id =
      let rec go i = function
        | [] -> -1
        | x :: rest -> if String.equal x id then i else go (i + 1) rest
      in
      go 0 ids
    in
    let range name =
      match List.find_opt (fun e -> String.equal e.sch.name name) spec.entries with
      | Some e -> e.sch.range
      | None -> invalid_arg ("Eval: the schema's material has no " ^ name)
    in
    let codes = Array.of_list (List.map (fun (_, c, _) -> c) fields) in
    let n = Array.length codes in
    let d = ctx.specs.material and big = Schema.big in
    let ci = index "color" and fi = index "fresnel" in
    let num name =
      let i = index name and r = range name in
      fun (vals : value array) default ->
        if i < 0 then default
        else
          match vals.(i) with
          | VNum x when Schema.in_range r x -> x
          | _ -> raise_notrace Slow
    in
    let ambient = num "ambient" and diffuse = num "diffuse" in
    let specular = num "specular" and shininess = num "shininess" in
    let reflection = num "reflection" and transparency = num "transparency" in
    let ior = num "ior" in
    let build vals : D.material =
      let color =
        if ci < 0 then d.color
        else
          match vals.(ci) with
          | VVec v
            when Float.abs v.x <= big
                 && Float.abs v.y <= big
                 && Float.abs v.z <= big
                 && v.x >= 0. && v.y >= 0. && v.z >= 0. ->
              Color.of_vec3 v
          | _ -> raise_notrace Slow
      in
      let fresnel =
        if fi < 0 then d.fresnel
        else match vals.(fi) with VBool x -> x | _ -> raise_notrace Slow
      in
      let m : D.material =
        {
          color;
          texture = None;
          ambient = ambient vals d.ambient;
          diffuse = diffuse vals d.diffuse;
          specular = specular vals d.specular;
          shininess = shininess vals d.shininess;
          reflection = reflection vals d.reflection;
          transparency = transparency vals d.transparency;
          ior = ior vals d.ior;
          fresnel;
          bump = None;
        }
      in
      (* What [D.validate_material] refuses (the ranges above keep the rest out). *)
      if m.reflection +. m.transparency <= 1. then m else raise_notrace Slow
    in
    let slow vals failed =
      let b =
        {
          ctx;
          kind = "material";
          kloc = loc;
          spec;
          fields =
            List.mapi
              (fun i ((name : name), _, vloc) -> { name; value = vals.(i); vloc })
              fields;
          failed;
          members = ref [];
        }
      in
      material_of ctx loc b
    in
    let last = { pvals = [||]; pmat = VPoison } in
    let same vals p =
      let rec go i = i >= n || (vals.(i) == p.(i) && go (i + 1)) in
      go 0
    in
    Some
      (fun fr ->
        let vals = Array.make n VPoison in
        let failed = ref false in
        for i = 0 to n - 1 do
          match codes.(i) fr with
          | v -> vals.(i) <- v
          | exception Fail (l, m) ->
              report ctx l m;
              failed := true
          | exception Poisoned -> failed := true
        done;
        if !failed then slow vals true
        else if last.pmat != VPoison && same vals last.pvals then last.pmat
        else
          match build vals with
          | m ->
              let v = VMat m in
              last.pvals <- vals;
              last.pmat <- v;
              v
          | exception Slow -> slow vals false)

let rec cexpr ctx ce (e : expr) : code =
  match e.e with
  | Num x ->
      let v = VNum x in
      fun _ -> v
  | Str s ->
      let v = VStr s in
      fun _ -> v
  | Bool b ->
      let v = vbool b in
      fun _ -> v
  | Var x -> access ctx ce x e.loc
  | Vec (a, b, c) -> (
      (* A vector of literal numbers is one value (a material of constants is then the
         same material each time). *)
      let lit (e : expr) =
        match e.e with
        | Num x -> Some x
        | Unop (Neg, { e = Num x; _ }) -> Some (-.x)
        | _ -> None
      in
      match (lit a, lit b, lit c) with
      | Some x, Some y, Some z ->
          let v = VVec { x; y; z } in
          fun _ -> v
      | _ ->
          let ca = cexpr ctx ce a and cb = cexpr ctx ce b and cc = cexpr ctx ce c in
          fun fr ->
            let x = match ca fr with VNum x -> x | v -> component a v in
            let y = match cb fr with VNum y -> y | v -> component b v in
            let z = match cc fr with VNum z -> z | v -> component c v in
            VVec { x; y; z })
  | Pair (a, b) ->
      let ca = cexpr ctx ce a and cb = cexpr ctx ce b in
      fun fr ->
        let x = ca fr in
        let y = cb fr in
        VPair (x, y)
  | Unop (Neg, a) -> (
      let ca = cexpr ctx ce a and loc = e.loc in
      fun fr ->
        match ca fr with
        | VNum x -> VNum (-.x)
        | VVec v -> VVec (Vec3.neg v)
        | v -> fail loc "`-` needs a number or a vector, got %s" (type_name v))
  | Unop (Not, a) -> (
      let ca = cexpr ctx ce a and loc = e.loc in
      fun fr ->
        match ca fr with
        | VBool b -> vbool (not b)
        | v -> fail loc "`not` needs a boolean, got %s" (type_name v))
  | Binop (((And | Or) as op), a, b) -> (
      let ca = cexpr ctx ce a and cb = cexpr ctx ce b in
      let bool (x : expr) v =
        match v with
        | VBool b -> b
        | v -> fail x.loc "`%s` needs booleans, got %s" (binop_name op) (type_name v)
      in
      match op with
      | And -> fun fr -> vbool (bool a (ca fr) && bool b (cb fr))
      | _ -> fun fr -> vbool (bool a (ca fr) || bool b (cb fr)))
  | Binop (op, a, b) -> (
      let ca = cexpr ctx ce a and cb = cexpr ctx ce b in
      let loc = e.loc and bloc = b.loc in
      let slow va vb = binop loc op va vb bloc in
      match op with
      | Add -> (
          fun fr ->
            let va = ca fr in
            let vb = cb fr in
            match (va, vb) with VNum x, VNum y -> num loc (x +. y) | _ -> slow va vb)
      | Sub -> (
          fun fr ->
            let va = ca fr in
            let vb = cb fr in
            match (va, vb) with VNum x, VNum y -> num loc (x -. y) | _ -> slow va vb)
      | Mul -> (
          fun fr ->
            let va = ca fr in
            let vb = cb fr in
            match (va, vb) with VNum x, VNum y -> num loc (x *. y) | _ -> slow va vb)
      | Div -> (
          fun fr ->
            let va = ca fr in
            let vb = cb fr in
            match (va, vb) with
            | VNum x, VNum y when y <> 0. -> num loc (x /. y)
            | _ -> slow va vb)
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
            let vb = cb fr in
            slow va vb)
  | Dot (a, f) -> (
      let ca = cexpr ctx ce a in
      match f.id with
      | "x" -> ( fun fr -> match ca fr with VVec v -> VNum v.x | v -> dot_value ctx f v)
      | "y" -> ( fun fr -> match ca fr with VVec v -> VNum v.y | v -> dot_value ctx f v)
      | "z" -> ( fun fr -> match ca fr with VVec v -> VNum v.z | v -> dot_value ctx f v)
      | _ -> fun fr -> dot_value ctx f (ca fr))
  | If (c, a, b) -> (
      let cc = cexpr ctx ce c and ca = cexpr ctx ce a and cb = cexpr ctx ce b in
      fun fr ->
        match cc fr with
        | VBool true -> ca fr
        | VBool false -> cb fr
        | v -> fail c.loc "the condition of `if` must be a boolean, got %s" (type_name v))
  | Call (f, args) -> (
      let cargs = List.map (fun (a : expr) -> (cexpr ctx ce a, a.loc)) args in
      let loc = e.loc in
      match resolve ce f.id with
      | Some (Const (VBuiltin name)) -> builtin_call name loc cargs
      | _ -> (
          let get = access ctx ce f.id f.nloc in
          let codes = Array.of_list (List.map fst cargs) in
          fun fr ->
            match get fr with
            | VBuiltin name -> generic_builtin name loc cargs fr
            | VFun c -> call_fun ctx c codes loc fr
            | VMacro m ->
                fail f.nloc
                  "`%s` is a scene macro (fn %s(…) { … }): call it as a statement, not \
                   in an expression"
                  m.mname m.mname
            | v -> fail f.nloc "`%s` is %s, not a function" f.id (type_name v)))
  | Material items -> (
      let its = citems ctx ce ~holds_objects:false items and loc = e.loc in
      match fast_material ctx loc its with
      | Some code -> code
      | None -> fun fr -> eval_material ctx fr loc its)

(* Whether a statement may start a loop (its own, or a macro's): only then do the loops
   around it keep count of the iterations they have left. *)
and may_loop (s : stmt) =
  match s.s with
  | For _ | Call_stmt _ -> true
  | If_stmt (_, t, e) -> List.exists may_loop t || List.exists may_loop e
  | Included (_, b) -> List.exists may_loop b
  | Block (_, its) | Body (_, its) ->
      List.exists (function Stmt s -> may_loop s | Field _ -> false) its
  | Let _ | Fn _ | Macro _ | Include _ -> false

(* A block's items: a field given twice is told as such (its value not evaluated), a
   statement the block does not hold is refused (not run); the names its `let`s define
   are seen by the items after them, not outside it. *)
and citems ctx ce ~holds_objects items =
  let rec go ce firsts acc = function
    | [] -> List.rev acc
    | Field (n, e) :: rest -> (
        match List.assoc_opt n.id firsts with
        | Some line when not (List.mem n.id repeatable) ->
            go ce firsts (CDup (n, line) :: acc) rest
        | first ->
            let c = cexpr ctx ce e in
            let firsts = if first = None then (n.id, n.nloc.line) :: firsts else firsts in
            go ce firsts (CField (n, c, e.loc) :: acc) rest)
    | Stmt s :: rest -> (
        match s.s with
        | Let _ | Fn _ | Macro _ ->
            let ce, c = cstmt ctx ce s in
            go ce firsts (CStmt c :: acc) rest
        | _ when holds_objects ->
            let ce, c = cstmt ctx ce s in
            go ce firsts (CStmt c :: acc) rest
        | _ -> go ce firsts (CRefused s.sloc :: acc) rest)
  in
  go ce [] [] items

and clist ctx ce stmts : cenv * scode =
  let ce, codes =
    List.fold_left
      (fun (ce, acc) s ->
        let ce, c = cstmt ctx ce s in
        (ce, c :: acc))
      (ce, []) stmts
  in
  let a = Array.of_list (List.rev codes) in
  ( ce,
    match a with
    | [||] -> fun _ _ -> ()
    | [| c |] -> c
    | _ ->
        fun fr sc ->
          for k = 0 to Array.length a - 1 do
            a.(k) fr sc
          done )

(* A statement that fails is reported and skipped; a name it defines is then poisoned. *)
and cstmt ctx ce (s : stmt) : cenv * scode =
  let guard code : scode =
   fun fr sc -> try code fr sc with Fail (l, m) -> report ctx l m | Poisoned -> ()
  in
  let guard_slot i code : scode =
   fun fr sc ->
    try code fr sc with
    | Fail (l, m) ->
        report ctx l m;
        fr.l.(i) <- VPoison
    | Poisoned -> fr.l.(i) <- VPoison
  in
  match s.s with
  | Let (x, e) ->
      let c = cexpr ctx ce e in
      let i = new_slot ce in
      (bind ce x.id (Slot (i, false)), guard_slot i (fun fr _ -> fr.l.(i) <- c fr))
  | Fn (f, params, body) ->
      let i = new_slot ce in
      let ce' = bind ce f.id (Slot (i, false)) in
      if dup_params params then (ce', guard_slot i (fun _ _ -> check_params params))
      else
        let fs =
          { nslots = List.length params; caps = []; ncaps = 0; parent = Some ce' }
        in
        let names = List.mapi (fun k (p : name) -> (p.id, Slot (k, false))) params in
        let fbody = cexpr ctx { names; fs } body in
        let getters = Array.of_list (List.rev_map (fun (_, _, pb) -> raw pb) fs.caps) in
        let fname = f.id and nparams = List.length params in
        ( ce',
          guard_slot i (fun fr _ ->
              let c = { fname; nparams; fbody; fslots = fs.nslots; fcaps = [||] } in
              fr.l.(i) <- VFun c;
              c.fcaps <- Array.map (fun g -> g fr) getters) )
  | Macro (f, params, body) ->
      let i = new_slot ce in
      let ce' = bind ce f.id (Slot (i, false)) in
      if dup_params params then (ce', guard_slot i (fun _ _ -> check_params params))
      else
        let fs =
          { nslots = List.length params; caps = []; ncaps = 0; parent = Some ce' }
        in
        let names = List.mapi (fun k (p : name) -> (p.id, Slot (k, false))) params in
        let _, mbody = clist ctx { names; fs } body in
        let getters = Array.of_list (List.rev_map (fun (_, _, pb) -> raw pb) fs.caps) in
        let mname = f.id and mnparams = List.length params in
        ( ce',
          guard_slot i (fun fr _ ->
              let m = { mname; mnparams; mbody; mslots = fs.nslots; mcaps = [||] } in
              fr.l.(i) <- VMacro m;
              m.mcaps <- Array.map (fun g -> g fr) getters) )
  | For (x, a, b, st, body) ->
      let ca = cexpr ctx ce a and cb = cexpr ctx ce b in
      let cst = Option.map (cexpr ctx ce) st in
      let i = new_slot ce in
      let _, cbody = clist ctx (bind ce x.id (Slot (i, false))) body in
      let per_iteration = Float.of_int (objects_written body) in
      let nests = List.exists may_loop body in
      ( ce,
        guard (fun fr sc ->
            for_loop ctx s a b st ca cb cst per_iteration nests i cbody fr sc) )
  | If_stmt (c, t, e) ->
      let cc = cexpr ctx ce c in
      let _, ct = clist ctx ce t in
      let _, cf = clist ctx ce e in
      ( ce,
        guard (fun fr sc ->
            match cc fr with
            | VBool true -> ct fr sc
            | VBool false -> cf fr sc
            | v ->
                fail c.loc "the condition of `if` must be a boolean, got %s" (type_name v))
      )
  | Include (p, loc) ->
      (ce, guard (fun _ _ -> fail loc "internal error: include \"%s\" was not resolved" p))
  | Included (_, stmts) -> clist ctx ce stmts
  | Call_stmt (f, args) ->
      let get = access ctx ce f.id f.nloc in
      let codes = Array.of_list (List.map (cexpr ctx ce) args) in
      ( ce,
        guard (fun fr sc ->
            match get fr with
            | VMacro m -> call_macro ctx m codes s.sloc fr sc
            | VFun c ->
                fail f.nloc
                  "`%s` is an expression function (fn %s(…) = …): use it in an \
                   expression, e.g. let x = %s(…)"
                  c.fname c.fname c.fname
            | VBuiltin n ->
                fail f.nloc "`%s` is a built-in function: use it in an expression" n
            | v -> fail f.nloc "`%s` is %s, not a scene macro" f.id (type_name v)) )
  | Block (k, items) -> (ce, guard (cblock ctx ce k items))
  | Body (n, items) -> (
      let its = citems ctx ce ~holds_objects:true items in
      (* A body that fails defines nothing: its name keeps what it named before. *)
      let before =
        match resolve ce n.id with Some b -> raw b | None -> fun _ -> unbound
      in
      let i = new_slot ce in
      let v = VBody n.id in
      ( bind ce n.id (Slot (i, true)),
        fun fr sc ->
          try
            body ctx fr sc s.sloc n its;
            fr.l.(i) <- v
          with
          | Fail (l, m) ->
              report ctx l m;
              fr.l.(i) <- before fr
          | Poisoned -> fr.l.(i) <- before fr ))

and cblock ctx ce (k : name) items : scode =
  let top_level f : scode =
   fun fr sc ->
    if sc.in_group then
      fail k.nloc
        "`%s` cannot be inside a group: a group's transforms and material apply to \
         objects only; write it at top level"
        k.id;
    f fr sc
  in
  match k.id with
  | "settings" ->
      let its = citems ctx ce ~holds_objects:false items in
      top_level (fun fr sc -> settings ctx fr sc k its)
  | "camera" ->
      let its = citems ctx ce ~holds_objects:false items in
      top_level (fun fr sc -> camera ctx fr sc k its)
  | "animation" ->
      let its = citems ctx ce ~holds_objects:false items in
      top_level (fun fr sc -> animation ctx fr sc k its)
  | "physics" ->
      let its = citems ctx ce ~holds_objects:false items in
      top_level (fun fr sc -> physics ctx fr sc k its)
  | "light" ->
      let its = citems ctx ce ~holds_objects:false items in
      top_level (fun fr sc -> light ctx fr sc k its)
  | "group" -> (
      let its = citems ctx ce ~holds_objects:true items in
      match fast_group ctx k its with
      | Some fast -> fun fr sc -> if sc.in_csg then csg ctx fr sc k its else fast fr sc
      | None ->
          fun fr sc -> if sc.in_csg then csg ctx fr sc k its else group ctx fr sc k its)
  | "union" | "merge" | "intersection" | "difference" ->
      let its = citems ctx ce ~holds_objects:true items in
      fun fr sc -> csg ctx fr sc k its
  | kind when Schema.is_shape kind -> (
      let its = citems ctx ce ~holds_objects:false items in
      match fast_object ctx k its with
      | Some code -> code
      | None -> (
          fun fr sc ->
            match object_ ctx fr sc k its with
            | Some o -> add_object ctx sc k.nloc o
            | None -> ()))
  | "material" ->
      fun _ _ ->
        fail k.nloc
          "a material is a value: write `material: material { … }` inside an object, or \
           `let m = material { … }`"
  | x -> fun _ _ -> fail k.nloc "unknown block `%s`%s" x (hint x Schema.keywords)

(* A shape block of fields only, each a field of its kind (the common case of a scene of
   many objects): what the fields are is settled here, once, not per object; their values
   are evaluated in order, as [collect] would, and read by position. A sphere that gives
   its centre and radius (and perhaps its material), right, is built at once; any other
   block is read field by field (its transforms only when it has some), for its
   messages. *)
and fast_object ctx (k : name) its =
  match Hashtbl.find_opt ctx.specs.by_kind k.id with
  | None -> None (* not a kind of this schema: the block says so when it runs *)
  | Some spec -> fast_object_of ctx spec k its

and fast_object_of ctx spec (k : name) (its : citem list) : scode option =
  let fields =
    List.filter_map (function CField (n, c, l) -> Some (n, c, l) | _ -> None) its
  in
  let ids = List.map (fun ((n : name), _, _) -> n.id) fields in
  let index id =
    let rec go i = function
      | [] -> None
      | x :: rest -> if String.equal x id then Some i else go (i + 1) rest
    in
    go 0 ids
  in
  let range name =
    List.find_map
      (fun e -> if String.equal e.sch.name name then Some e.sch.range else None)
      spec.entries
  in
  let allowed = field_names_of k.id in
  let codes = Array.of_list (List.map (fun (_, c, _) -> c) fields) in
  let n = Array.length codes in
  let kind = k.id and loc = k.nloc in
  let plain =
    not (List.exists (fun id -> List.mem id [ "translate"; "rotate"; "scale" ]) ids)
  in
  let evaluate fr =
    let vals = Array.make n VPoison in
    for i = 0 to n - 1 do
      vals.(i) <-
        (match codes.(i) fr with
        | v -> v
        | exception Fail (l, m) ->
            report ctx l m;
            VPoison
        | exception Poisoned -> VPoison)
    done;
    vals
  in
  let slow vals sc =
    let b =
      {
        ctx;
        kind;
        kloc = loc;
        spec;
        fields =
          List.mapi
            (fun i ((name : name), _, vloc) -> { name; value = vals.(i); vloc })
            fields;
        failed = Array.exists (fun v -> v == VPoison) vals;
        members = ref [];
      }
    in
    match object_of ~known:true ~plain b k with
    | Some o -> add_object ctx sc loc o
    | None -> ()
  in
  if
    not
      (List.length fields = List.length its
      && List.for_all (fun id -> List.mem id allowed) ids)
  then None
  else
    let big = Schema.big in
    let coords (v : Vec3.t) =
      Float.abs v.x <= big && Float.abs v.y <= big && Float.abs v.z <= big
    in
    let nsteps, transform = fast_transforms ids in
    let untransformed = (Transform.identity, []) in
    let mi = index "material" in
    let last = ref None and wrong = Some ctx.specs.material in
    let material vals =
      match mi with
      | None -> None
      | Some i -> (
          match vals.(i) with
          | VMat m -> (
              (* The objects of a site mostly share one material: so do their
                 options. *)
              match !last with
              | Some m' as o when m' == m -> o
              | _ ->
                  let o = Some m in
                  last := o;
                  o)
          | _ -> wrong)
    in
    (* The shape, read by position, for the kinds of many objects; [None]: read by the
       block. *)
    let only own =
      List.for_all
        (fun id ->
          List.mem id own || List.mem id [ "material"; "translate"; "rotate"; "scale" ])
        ids
    in
    let shape : (value array -> D.shape) option =
      match
        (k.id, index "center", index "radius", range "radius", index "min", index "max")
      with
      | ("sphere" | "box"), _, _, _, _, _
        when not
               (only
                  (if k.id = "sphere" then [ "center"; "radius" ] else [ "min"; "max" ]))
        ->
          None (* a field these lines do not read: the block reads it *)
      | "sphere", Some ci, Some ri, Some radius_range, _, _ ->
          Some
            (fun vals ->
              match (vals.(ci), vals.(ri)) with
              | VVec c, VNum r when coords c && Schema.in_range radius_range r ->
                  D.Sphere { center = c; radius = r }
              | _ -> raise_notrace Slow)
      | "box", _, _, _, Some ni, Some xi ->
          Some
            (fun vals ->
              match (vals.(ni), vals.(xi)) with
              | VVec mn, VVec mx
                when coords mn && coords mx && mn.x < mx.x && mn.y < mx.y && mn.z < mx.z
                ->
                  D.Box { min = mn; max = mx }
              | _ -> raise_notrace Slow)
      | _ -> None
    in
    match shape with
    | Some shape ->
        Some
          (fun fr sc ->
            let vals = evaluate fr in
            match
              let material = material vals in
              if material == wrong then raise_notrace Slow;
              let shape = shape vals in
              let transform, steps =
                if nsteps = 0 then untransformed else transform vals
              in
              { D.kind; shape; transform; steps; material; loc; body = None }
            with
            | o -> add_object ctx sc loc o
            | exception Slow -> slow vals sc)
    | None -> Some (fun fr sc -> slow (evaluate fr) sc)

(* A group (not in a CSG block) whose fields are all a group's, each given once: its items
   run in order, as [collect] would run them; right transforms and material are read by
   position, anything else by the group's own reading. *)
and fast_group ctx (k : name) (its : citem list) : scode option =
  let allowed = field_names_of "group" in
  if
    not
      (List.for_all
         (function
           | CField (n, _, _) ->
               List.mem n.id allowed
               && List.mem n.id [ "material"; "translate"; "rotate"; "scale" ]
           | CStmt _ -> true
           | CDup _ | CRefused _ -> false)
         its)
  then None
  else
    let fields =
      List.filter_map (function CField (n, _, l) -> Some (n, l) | _ -> None) its
    in
    let ids = List.map (fun ((n : name), _) -> n.id) fields in
    let n = List.length fields in
    let mi =
      let rec go i = function
        | [] -> -1
        | x :: rest -> if String.equal x "material" then i else go (i + 1) rest
      in
      go 0 ids
    in
    let _, transform = fast_transforms ids in
    let items = Array.of_list its and spec = spec_for ctx "group" in
    let slow sc vals failed members =
      group_of sc
        {
          ctx;
          kind = "group";
          kloc = k.nloc;
          spec;
          fields =
            List.mapi (fun i (name, vloc) -> { name; value = vals.(i); vloc }) fields;
          failed;
          members;
        }
    in
    Some
      (fun fr sc ->
        let vals = Array.make n VPoison in
        let members = ref [] in
        let inner = { sink = members; in_group = true; in_csg = false } in
        let failed = ref false and f = ref 0 in
        for i = 0 to Array.length items - 1 do
          match items.(i) with
          | CField (_, code, _) ->
              (match code fr with
              | v -> vals.(!f) <- v
              | exception Fail (l, m) ->
                  report ctx l m;
                  failed := true
              | exception Poisoned -> failed := true);
              incr f
          | CStmt code -> code fr inner
          | CDup _ | CRefused _ -> ()
        done;
        if !failed then slow sc vals true members
        else
          match
            let mat =
              if mi < 0 then None
              else match vals.(mi) with VMat m -> Some m | _ -> raise_notrace Slow
            in
            (transform vals, mat)
          with
          | (t, tj), mat -> group_members sc t tj mat !members
          | exception Slow -> slow sc vals false members)

(* The checks before a loop runs, then its iterations. *)
and for_loop ctx (s : stmt) (a : expr) (b : expr) st ca cb cst per_iteration nests slot
    cbody fr sc =
  let num c (e : expr) what =
    match c fr with
    | VNum v -> v
    | v -> fail e.loc "the %s of a `for` loop must be a number, got %s" what (type_name v)
  in
  let a' = num ca a "start" in
  let b' = num cb b "end" in
  let st' = match (st, cst) with Some e, Some c -> num c e "step" | _ -> 1. in
  if st' = 0. then fail (Option.get st).loc "the step of a `for` loop must not be 0";
  let count = Float.floor (((b' -. a') /. st') +. 1e-9) +. 1. in
  (* Refused before it starts when this loop, run inside the loops around it, would
     go past the step limit: nested loops fail at once instead of after minutes. *)
  let total = Float.max 0. count *. ctx.loops in
  if count > 1e15 || total +. Float.of_int ctx.steps > Float.of_int max_steps then
    limit ctx s.sloc
      (Printf.sprintf
         "this loop would run %s times%s; a scene may take at most %d loop iterations \
          and calls, and build at most %d objects"
         (fmt_num count)
         (if ctx.loops > 1. then
            Printf.sprintf " inside loops that have %s iterations left (%s in all)"
              (fmt_num ctx.loops) (fmt_num total)
          else "")
         max_steps max_objects);
  (* The same for the object limit: each iteration builds at least the objects
     written in the loop's body. *)
  if
    per_iteration > 0.
    && (total *. per_iteration) +. Float.of_int ctx.objects > Float.of_int max_objects
  then
    limit ctx s.sloc
      (Printf.sprintf
         "this loop would build %s objects (%s an iteration, %s iterations%s)%s; a scene \
          may build at most %d objects"
         (fmt_num (total *. per_iteration))
         (fmt_num per_iteration) (fmt_num count)
         (if ctx.loops > 1. then
            Printf.sprintf " inside loops that have %s iterations left"
              (fmt_num ctx.loops)
          else "")
         (if ctx.objects > 0 then
            Printf.sprintf ", after the %d already built" ctx.objects
          else "")
         max_objects);
  if count <= 0. then
    warn ctx s.sloc
      (Printf.sprintf
         "this loop runs zero times: it counts from %s to %s in steps of %s%s"
         (fmt_num a') (fmt_num b') (fmt_num st')
         (if st' > 0. then " (to count down, give a negative step: `step -1`)"
          else " (to count up, give a positive step)"));
  (* And for memory: objects that would not fit under the process's limit are refused
     before they are built (the runtime would abort, not raise, once it runs out). *)
  if per_iteration > 0. && total < 1e15 then
    Option.iter (limit ctx s.sloc)
      (memory_refusal (ctx.objects + int_of_float (total *. per_iteration)));
  let count = if count < 0. then 0 else int_of_float count in
  let outer = ctx.loops in
  Fun.protect
    ~finally:(fun () -> ctx.loops <- outer)
    (fun () ->
      for k = 0 to count - 1 do
        step ctx s.sloc;
        if nests then ctx.loops <- outer *. Float.of_int (count - k);
        fr.l.(slot) <- VNum (a' +. (Float.of_int k *. st'));
        cbody fr sc
      done)

(* ------------------------------------------------------------------------------------ *)
(* A whole program *)

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

(* Every name a program defines and where, in program order (for "defined later"). *)
let definitions stmts =
  let acc = ref [] in
  let rec stmt (s : stmt) =
    match s.s with
    | Let (x, _) | Fn (x, _, _) -> acc := (x.id, x.nloc) :: !acc
    | Macro (x, _, b) ->
        acc := (x.id, x.nloc) :: !acc;
        List.iter stmt b
    | Body (x, its) ->
        acc := (x.id, x.nloc) :: !acc;
        items its
    | For (_, _, _, _, b) -> List.iter stmt b
    | If_stmt (_, t, e) ->
        List.iter stmt t;
        List.iter stmt e
    | Included (_, b) -> List.iter stmt b
    | Block (_, its) -> items its
    | Include _ | Call_stmt _ -> ()
  and items its = List.iter (function Stmt s -> stmt s | Field _ -> ()) its in
  List.iter stmt stmts;
  List.rev !acc

(* ------------------------------------------------------------------------------------ *)
(* What does not change between instants *)

(* Every name a statement or expression mentions: the names it reads, and more (names it
   binds itself, field names excluded). A value the statement computes can come from
   nothing but these names and its literals, so if none of them holds anything that may
   differ between instants, neither does the statement's work. *)
let rec expr_names acc (e : expr) =
  match e.e with
  | Num _ | Str _ | Bool _ -> acc
  | Var x -> x :: acc
  | Vec (a, b, c) | If (a, b, c) -> expr_names (expr_names (expr_names acc a) b) c
  | Pair (a, b) | Binop (_, a, b) -> expr_names (expr_names acc a) b
  | Unop (_, a) | Dot (a, _) -> expr_names acc a
  | Call (f, args) -> List.fold_left expr_names (f.id :: acc) args
  | Material items -> items_names acc items

and items_names acc items =
  List.fold_left
    (fun acc -> function Field (_, e) -> expr_names acc e | Stmt s -> stmt_names acc s)
    acc items

and stmt_names acc (s : stmt) =
  match s.s with
  | Let (_, e) | Fn (_, _, e) -> expr_names acc e
  | Macro (_, _, b) | Included (_, b) -> List.fold_left stmt_names acc b
  | For (_, a, b, st, body) ->
      let acc = expr_names (expr_names acc a) b in
      let acc = match st with Some e -> expr_names acc e | None -> acc in
      List.fold_left stmt_names acc body
  | If_stmt (c, t, e) ->
      List.fold_left stmt_names (List.fold_left stmt_names (expr_names acc c) t) e
  | Include _ -> acc
  | Block (_, items) | Body (_, items) -> items_names acc items
  | Call_stmt (f, args) -> List.fold_left expr_names (f.id :: acc) args

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
  | For (x, _, _, _, b) -> List.fold_left bound_names (x.id :: acc) b
  | If_stmt (_, t, e) -> List.fold_left bound_names (List.fold_left bound_names acc t) e
  | Included (_, b) -> List.fold_left bound_names acc b
  | Block (_, its) | Body (_, its) -> items acc its
  | Include _ | Call_stmt _ -> acc

let object_block k =
  Schema.is_shape k
  || List.mem k [ "group"; "union"; "merge"; "intersection"; "difference" ]

(* Whether running [s] does nothing but build objects (into the scope it runs in) and
   use files: no settings, camera, light, animation, physics or body; a macro it calls
   must be one of [pure_macro]'s, not a name bound inside it. *)
let only_objects pure_macro (s : stmt) =
  let local = bound_names [] s in
  let rec go (s : stmt) =
    match s.s with
    | Let _ | Fn _ | Macro _ -> true
    | For (_, _, _, _, b) | Included (_, b) -> List.for_all go b
    | If_stmt (_, t, e) -> List.for_all go t && List.for_all go e
    | Block (k, its) ->
        object_block k.id
        && List.for_all (function Stmt s -> go s | Field _ -> true) its
    | Call_stmt (f, _) -> (not (List.mem f.id local)) && pure_macro f.id
    | Include _ | Body _ -> false
  in
  go s

module Names = Set.Make (String)

(* What the first evaluation recorded of a top-level statement that [memo] may skip. *)
type recorded = {
  objects_before : int;  (** the count of objects built when it started *)
  steps_before : int;
  steps : int;  (** the evaluation steps it took *)
  counted : int;  (** the objects it counted against the limit (members included) *)
  built : D.obj list;  (** the objects it built, in order *)
  file_uses : D.file_use list;  (** in the order they were met *)
  warned : Error.t list;  (** in the order they were given *)
}

type memo = {
  top : stmt array;  (** the program's top-level statements, includes flattened *)
  fixed : bool array;
      (** whether each depends on nothing that may differ between instants and only builds
          objects *)
  entries : recorded option array;  (** filled by the first evaluation *)
  mutable recorded : bool;
}

let rec flatten stmts =
  List.concat_map
    (fun (s : stmt) -> match s.s with Included (_, b) -> flatten b | _ -> [ s ])
    stmts

let memo stmts =
  let top = Array.of_list (flatten stmts) in
  (* Names whose value may differ between instants: time, frame, bodies, and whatever is
     defined from them. Macros that only build objects and depend on none of them. *)
  let dynamic = ref (Names.of_list [ "time"; "frame" ]) in
  let pure = ref Names.empty in
  let fixed =
    Array.map
      (fun (s : stmt) ->
        let reads except =
          List.exists (fun n -> n <> except && Names.mem n !dynamic) (stmt_names [] s)
        in
        let set x dyn =
          dynamic := if dyn then Names.add x !dynamic else Names.remove x !dynamic
        in
        match s.s with
        | Let (x, _) ->
            set x.id (reads "");
            pure := Names.remove x.id !pure;
            false
        | Fn (x, _, _) ->
            set x.id (reads x.id);
            pure := Names.remove x.id !pure;
            false
        | Macro (x, _, b) ->
            let dyn = reads x.id in
            set x.id dyn;
            let self = Names.add x.id !pure in
            let ok =
              (not dyn) && List.for_all (only_objects (fun f -> Names.mem f self)) b
            in
            pure := if ok then self else Names.remove x.id !pure;
            false
        | Body (x, _) ->
            set x.id true;
            pure := Names.remove x.id !pure;
            false
        | Block _ | For _ | If_stmt _ | Call_stmt _ ->
            (not (reads "")) && only_objects (fun f -> Names.mem f !pure) s
        | Include _ | Included _ -> false)
      top
  in
  { top; fixed; entries = Array.make (Array.length top) None; recorded = false }

let fixed_pieces m =
  Array.fold_left
    (fun acc e -> match e with Some e -> e.built :: acc | None -> acc)
    [] m.entries
  |> List.rev

let fixed_objects m = List.concat (fixed_pieces m)

(* The names every program starts with. *)
let top_cenv ~time ~frame =
  let names = List.map (fun n -> (n, Const (VBuiltin n))) builtin_names in
  let names =
    ("frame", Const (VNum (Float.of_int frame)))
    :: ("time", Const (VNum time)) :: ("pi", Const (VNum Float.pi)) :: names
  in
  { names; fs = { nslots = 0; caps = []; ncaps = 0; parent = None } }

let use_path : D.file_use -> string = function
  | Picture im -> im.path
  | Model { path; _ } | Heights { path; _ } -> path

(* The elements of [now] in front of [before] (a list it was grown from), oldest first. *)
let grown now before =
  let rec go acc l =
    if l == before then acc else match l with x :: r -> go (x :: acc) r | [] -> acc
  in
  go [] now

let run ?memo ?body_state ?on_objects ?cancel ?(objects = true) ?parts ?(on_file = ignore)
    ?schema ~file ~sources ~time ~frame stmts =
  let uses = ref [] in
  let on_file u =
    uses := u :: !uses;
    on_file u
  in
  let ctx =
    {
      specs =
        (match schema with
        | None -> Lazy.force schema_specs
        | Some blocks -> specs_of blocks);
      on_file;
      on_objects;
      cancel;
      time;
      body_state;
      sources;
      used = Hashtbl.create 4;
      errors = [];
      seen = Hashtbl.create 16;
      objects = 0;
      steps = 0;
      loops = 1.;
      depth = 0;
      settings = None;
      camera = None;
      animation = None;
      physics = None;
      lights = [];
      bodies = [];
      warnings = [];
      definitions = lazy (definitions stmts);
    }
  in
  let scope = { sink = ref []; in_group = false; in_csg = false } in
  let finish ~transform ~body (o : D.obj) = { o with transform; body = Some body } in
  (* The objects built so far, newest piece first: those of statements the memo records
     or replays, and between them those of the others (finished when a piece follows). *)
  let pieces = ref [] in
  let cut () =
    if !(scope.sink) <> [] then (
      pieces := List.rev !(scope.sink) :: !pieces;
      scope.sink := [])
  in
  (* The program's top-level statements (includes flattened), compiled. *)
  let stmts = match memo with Some m -> m.top | None -> Array.of_list (flatten stmts) in
  let top_ce = top_cenv ~time ~frame in
  let code =
    let ce = ref top_ce in
    Array.map
      (fun s ->
        let ce', c = cstmt ctx !ce s in
        ce := ce';
        c)
      stmts
  in
  let fr = { l = Array.make top_ce.fs.nslots VPoison; c = [||] } in
  let top m i =
    match m.entries.(i) with
    | Some e
      when m.recorded && ctx.objects = e.objects_before && ctx.steps <= e.steps_before ->
        (* It would do what it did then: the same objects, steps, files and warnings. *)
        cut ();
        pieces := e.built :: !pieces;
        let before = ctx.objects in
        ctx.objects <- ctx.objects + e.counted;
        ctx.steps <- ctx.steps + e.steps;
        List.iter
          (fun u ->
            Hashtbl.replace ctx.used (use_path u) ();
            ctx.on_file u)
          e.file_uses;
        List.iter
          (fun (w : Error.t) ->
            let key = (w.file, w.line, w.col, "warning: " ^ w.message) in
            if not (Hashtbl.mem ctx.seen key) then (
              Hashtbl.add ctx.seen key ();
              ctx.warnings <- w :: ctx.warnings))
          e.warned;
        if ctx.objects lsr 16 > before lsr 16 then
          Option.iter (fun f -> f ctx.objects) ctx.on_objects;
        Option.iter Cancel.check ctx.cancel
    | _ when m.fixed.(i) && not m.recorded ->
        cut ();
        let objects_before = ctx.objects and steps_before = ctx.steps in
        let uses0 = !uses and warnings0 = ctx.warnings and errors0 = ctx.errors in
        code.(i) fr scope;
        let built = List.rev !(scope.sink) in
        scope.sink := [];
        pieces := built :: !pieces;
        if ctx.errors == errors0 then
          m.entries.(i) <-
            Some
              {
                objects_before;
                steps_before;
                steps = ctx.steps - steps_before;
                counted = ctx.objects - objects_before;
                built;
                file_uses = grown !uses uses0;
                warned = grown ctx.warnings warnings0;
              }
    | _ -> code.(i) fr scope
  in
  (try
     match memo with
     | None -> Array.iter (fun c -> c fr scope) code
     | Some m ->
         Array.iteri (fun i _ -> top m i) m.top;
         if ctx.errors = [] then m.recorded <- true
   with Abort -> ());
  if ctx.errors <> [] then Error (sort_errors (List.rev ctx.errors))
  else
    (* With [parts], the pieces themselves, not one list copied from them: a piece the
       memo replayed is the very list it recorded. *)
    let in_parts = objects && Option.is_some parts in
    let statics =
      if objects && not in_parts then (
        cut ();
        match !pieces with [ p ] -> p | ps -> List.concat (List.rev ps))
      else []
    in
    let bodies = List.rev ctx.bodies in
    let body_objs =
      List.map
        (fun ((b : body), o) ->
          let transform =
            match Option.bind body_state (fun f -> f b.name time) with
            | Some (p, _) ->
                Transform.then_ o.D.transform (Transform.translate (Vec3.sub p b.center))
            | None -> o.D.transform
          in
          finish ~transform ~body:b.name o)
        (if objects then bodies else [])
    in
    (match parts with
    | Some f when in_parts ->
        cut ();
        f (List.rev (match body_objs with [] -> !pieces | b -> b :: !pieces))
    | _ -> ());
    Ok
      {
        D.file;
        time;
        frame;
        settings = (match ctx.settings with Some (s, _) -> s | None -> Settings.default);
        camera = (match ctx.camera with Some (c, _) -> c | None -> Camera.default);
        lights = List.rev ctx.lights;
        objects =
          (if in_parts then []
           else match body_objs with [] -> statics | _ -> statics @ body_objs);
        animation = Option.map fst ctx.animation;
        physics = Option.map fst ctx.physics;
        physics_loc = Option.map snd ctx.physics;
        warnings = sort_errors (List.rev ctx.warnings);
        bodies = List.map (fun ((b : body), _) -> b) bodies;
        files =
          List.sort_uniq String.compare
            (Hashtbl.fold (fun p () acc -> p :: acc) ctx.used []);
      }
