module D = Description

type t =
  | VNum of float
  | VBool of bool
  | VVec of Vec3.t
  | VStr of string
  | VMat of { some : D.material option; color : Color.t }
  | VTex of tex
  | VPair of t * t
  | VList of t array
  | VFun of closure
  | VMacro of macro
  | VBuiltin of string
  | VBody of string
  | VPoison

and tex = { tname : string; targs : t list; tloc : Loc.t }

and closure = {
  fname : string;
  nparams : int;
  fbody : frame -> t;
  fslots : int;
  mutable fcaps : t array;
}

and macro = {
  mname : string;
  mnparams : int;
  mbody : frame -> scope -> unit;
  mslots : int;
  mutable mcaps : t array;
}

and frame = { l : t array; c : t array; st : state }

and scope = {
  sink : D.obj list ref;
  emit : (D.obj -> unit) option;
  in_group : bool;
  in_csg : bool;
}

and state = { hooks : hooks; count : counters; out : outputs; tell : sink }

and sink = {
  report : Loc.t -> string -> unit;
  use : D.file_use -> unit;
  share : D.material -> D.material option;
}

and hooks = {
  time : float;
  time_v : t;
  frame_v : t;
  body_state : (string -> float -> (Vec3.t * Vec3.t) option) option;
  on_objects : (int -> unit) option;
  on_file : D.file_use -> unit;
  cancel : Cancel.t option;
  address_limit : int option;
  sources : (string, string) Hashtbl.t;
}

and counters = {
  mutable objects : int;
  mutable steps : int;
  mutable loops : float;
  mutable depth : int;
}

and outputs = {
  mutable errors : Error.t list;
  mutable warnings : Error.t list;
  seen : (string * int * int * string, unit) Hashtbl.t;
  mutable settings : (Settings.t * Loc.t) option;
  mutable camera : (Camera.t * Loc.t) option;
  mutable animation : ((float * int) * Loc.t) option;
  mutable physics : (D.physics * Loc.t) option;
  mutable lights : Light.t list;
  mutable bodies : (D.body * D.obj) list;
  used : (string, unit) Hashtbl.t;
}

exception Fail of Loc.t * string
exception Poisoned
exception Abort

let fail loc msg = raise (Fail (loc, msg))

let rec ty = function
  | VNum _ -> Ty.Num
  | VBool _ -> Ty.Bool
  | VVec _ -> Ty.Vec
  | VStr _ -> Ty.Str
  | VMat _ -> Ty.Mat
  | VTex t -> Ty.Tex t.tname
  | VPair (a, b) -> Ty.Pair (ty a, ty b)
  | VList a ->
      (* The type its elements share (one, as its making checked). *)
      let element =
        if Array.length a = 0 then Ty.Unknown
        else
          Array.fold_left
            (fun t v -> Option.value (Ty.join t (ty v)) ~default:Ty.Unknown)
            (ty a.(0))
            a
      in
      Ty.List element
  | VFun c -> Ty.Fun c.nparams
  | VMacro m -> Ty.Macro m.mnparams
  | VBuiltin n -> Ty.Builtin n
  | VBody _ -> Ty.Body
  | VPoison -> Ty.Unknown

let type_name v = Ty.name (ty v)

(* Physically unique: no program makes this very value. *)
let unbound = VStr "(unbound)"

let finite loc x =
  if Float.is_nan x then fail loc Msg.nan
  else if Float.is_integer x || Float.is_finite x then x
  else fail loc Msg.overflow

let finite_vec loc (v : Vec3.t) =
  ignore (finite loc v.x);
  ignore (finite loc v.y);
  ignore (finite loc v.z);
  v

let[@inline] num loc r = if r -. r = 0. then VNum r else VNum (finite loc r)
let vtrue = VBool true
let vfalse = VBool false
let[@inline] vbool b = if b then vtrue else vfalse

let material ?some (m : D.material) =
  VMat { some = (match some with Some s -> s | None -> Some m); color = m.color }

let colored some color = VMat { some; color }

(* Numbers compare by their bits, textures and bump maps by identity; the fields as
   {!D.material_hash} lists them. *)
let same_but_color (m : D.material) (d : D.material) =
  let same x y = Int64.equal (Int64.bits_of_float x) (Int64.bits_of_float y) in
  m.texture == d.texture && m.bump == d.bump
  && Bool.equal m.fresnel d.fresnel
  && same m.ambient d.ambient && same m.diffuse d.diffuse && same m.specular d.specular
  && same m.shininess d.shininess
  && same m.reflection d.reflection
  && same m.transparency d.transparency
  && same m.ior d.ior && same m.metallic d.metallic && same m.filter d.filter

module Shared = Hashtbl.Make (struct
  type t = D.material

  let equal m m' = same_but_color m m'
  let hash = D.material_hash (fun x -> Int64.to_int (Int64.bits_of_float x))
end)

let sharing () =
  let shared = Shared.create 16 in
  fun (m : D.material) ->
    match Shared.find_opt shared m with
    | Some some -> some
    | None ->
        let some = Some m in
        if Shared.length shared < D.shared_materials then Shared.add shared m some;
        some

let full_material ~some ~color : D.material =
  match some with
  | Some (m : D.material) when m.color == color -> m
  | Some m -> { m with color }
  | None -> { D.default_material with color }
