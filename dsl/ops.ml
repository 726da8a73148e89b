open Ast
open Value

let binop_type op (a : Ty.t) (b : Ty.t) : Ty.t option =
  match (op, a, b) with
  | (Add | Sub), Num, Num -> Some Num
  | Add, Str, Str -> Some Str
  | (Add | Sub), Vec, Vec -> Some Vec
  | Mul, Num, Num -> Some Num
  | Mul, (Num | Vec), (Num | Vec) -> Some Vec
  | Div, Num, Num -> Some Num
  | Div, Vec, Num -> Some Vec
  | (Mod | Pow), Num, Num -> Some Num
  | (Eq | Ne), Num, Num
  | (Eq | Ne), Bool, Bool
  | (Eq | Ne), Str, Str
  | (Eq | Ne), Vec, Vec ->
      Some Bool
  | (Lt | Le | Gt | Ge), Num, Num -> Some Bool
  | _ -> None

let[@inline] add loc x y = num loc (x +. y)
let[@inline] sub loc x y = num loc (x -. y)
let[@inline] mul loc x y = num loc (x *. y)

let[@inline] div loc bloc x y =
  if y = 0. then fail bloc Msg.division_by_zero else num loc (x /. y)

let equal a b =
  match (a, b) with
  | VNum x, VNum y -> Float.equal x y
  | VBool x, VBool y -> Bool.equal x y
  | VStr x, VStr y -> String.equal x y
  | VVec x, VVec y -> Float.equal x.x y.x && Float.equal x.y y.y && Float.equal x.z y.z
  | _ -> false

let binop loc op bloc a b =
  (match (a, b) with VPoison, _ | _, VPoison -> raise Poisoned | _ -> ());
  match binop_type op (ty a) (ty b) with
  | None -> fail loc (Msg.cannot_combine op (ty a) (ty b))
  | Some _ -> (
      let vec v = VVec (finite_vec loc v) in
      match (op, a, b) with
      | Add, VNum x, VNum y -> add loc x y
      | Add, VVec x, VVec y -> vec (Vec3.add x y)
      | Add, VStr x, VStr y -> VStr (x ^ y)
      | Sub, VNum x, VNum y -> sub loc x y
      | Sub, VVec x, VVec y -> vec (Vec3.sub x y)
      | Mul, VNum x, VNum y -> mul loc x y
      | Mul, VNum s, VVec v | Mul, VVec v, VNum s -> vec (Vec3.smul s v)
      | Mul, VVec x, VVec y -> vec (Vec3.mul x y)
      | Div, VNum x, VNum y -> div loc bloc x y
      | Div, VVec v, VNum s ->
          if s = 0. then fail bloc Msg.division_by_zero else vec (Vec3.smul (1. /. s) v)
      | Mod, VNum x, VNum y ->
          if y = 0. then fail bloc Msg.modulo_by_zero else num loc (Float.rem x y)
      | Pow, VNum x, VNum y ->
          let r = Float.pow x y in
          if Float.is_nan r then fail loc (Msg.not_real x y) else num loc r
      | Eq, _, _ -> vbool (equal a b)
      | Ne, _, _ -> vbool (not (equal a b))
      | Lt, VNum x, VNum y -> vbool (x < y)
      | Le, VNum x, VNum y -> vbool (x <= y)
      | Gt, VNum x, VNum y -> vbool (x > y)
      | Ge, VNum x, VNum y -> vbool (x >= y)
      | _ -> fail loc (Msg.cannot_combine op (ty a) (ty b)))

let neg_type : Ty.t -> Ty.t option = function
  | Num -> Some Num
  | Vec -> Some Vec
  | _ -> None

let neg loc = function
  | VNum x -> VNum (-.x)
  | VVec v -> VVec (Vec3.neg v)
  | VPoison -> raise Poisoned
  | v -> fail loc (Msg.neg_needs (ty v))

let not_type : Ty.t -> Ty.t option = function Bool -> Some Bool | _ -> None

let not_ loc = function
  | VBool b -> vbool (not b)
  | VPoison -> raise Poisoned
  | v -> fail loc (Msg.not_needs (ty v))

let is_list : Ty.t -> bool = function List _ -> true | _ -> false
let element : Ty.t -> Ty.t = function List t -> t | _ -> Unknown

let list_type (elements : (Ty.t * Loc.t) list) =
  match elements with
  | [] -> Ok (Ty.List Unknown)
  | (first, _) :: rest ->
      let rec go i acc = function
        | [] -> Ok (Ty.List acc)
        | (t, loc) :: rest -> (
            match Ty.join first t with
            | None -> Error (loc, Msg.list_element i t first)
            | Some _ -> go (i + 1) (Option.value (Ty.join acc t) ~default:Ty.Unknown) rest
            )
      in
      go 2 first rest

let list (elements : (Value.t * Loc.t) array) =
  match list_type (Array.to_list (Array.map (fun (v, l) -> (ty v, l)) elements)) with
  | Error (loc, msg) -> fail loc msg
  | Ok _ -> VList (Array.map fst elements)

let index aloc iloc a i =
  match (a, i) with
  | VPoison, _ | _, VPoison -> raise Poisoned
  | VList l, VNum x ->
      let n = Array.length l in
      if not (Float.is_integer x) then fail iloc (Msg.index_whole x)
      else if x < 0. || x >= Float.of_int n then fail iloc (Msg.index_range x n)
      else l.(int_of_float x)
  | VList _, v -> fail iloc (Msg.index_type (ty v))
  | v, _ -> fail aloc (Msg.index_needs (ty v))
