open Value

type arg = Of of (Ty.t -> bool) * string | Any | Entry

type arity =
  | Exactly of int
  | At_least of int * (int -> string)
  | Among of int list * (int -> string)

type impl =
  | F1 of (float -> float)
  | Partial of (float -> bool) * string * (float -> float)
  | F2 of (float -> float -> float)
  | Code of (Loc.t -> (Value.t * Loc.t) array -> Value.t)

type fn = {
  arity : arity;
  arg : int -> arg;
  result : Ty.t list -> (Ty.t, string) result;
  impl : impl;
}

type kind = Number of (Value.hooks -> Value.t) | Function of fn
type t = { name : string; usage : string; doc : string; kind : kind }

(* ---- What arguments must be ---- *)

let number = Of ((fun t -> t = Ty.Num), "a number")
let vector = Of ((fun t -> t = Ty.Vec), "a vector (x, y, z)")
let file_name = Of ((fun t -> t = Ty.Str), "a file name string")
let list = Of (Ops.is_list, "a list")

let map_or_colour =
  Of
    ( (function Ty.Tex "color_map" | Ty.Vec -> true | _ -> false),
      "a color_map(…) (a texture along an axis) or a colour (a background from horizon \
       to zenith)" )

let all_of a _ = a
let returns t _ = Ok t

(* ---- Implementations ---- *)

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

let unchecked () = invalid_arg "Builtins: an argument of a type not checked"
let n args i = match fst args.(i) with VNum x -> x | _ -> unchecked ()
let v args i = match fst args.(i) with VVec x -> x | _ -> unchecked ()
let vnum loc x = VNum (finite loc x)
let vvec loc x = VVec (finite_vec loc x)

(* A texture-like value: what it means is read where it is used. *)
let tex name loc args =
  VTex { tname = name; targs = Array.to_list (Array.map fst args); tloc = loc }

(* The entries' values, once their types are right: t in [0, 1], in order, colours not
   negative. *)
let color_map loc args =
  ignore
    (Array.fold_left
       (fun (i, prev) (v, l) ->
         match v with
         | VPair (VNum t, VVec c) ->
             if not (t >= 0. && t <= 1.) then fail l (Msg.color_map_t i t);
             if t < prev then fail l (Msg.color_map_order i t prev);
             if c.x < 0. || c.y < 0. || c.z < 0. then fail l (Msg.color_map_negative i);
             (i + 1, t)
         | _ -> unchecked ())
       (1, 0.) args);
  tex "color_map" loc args

let fog loc args =
  let d = n args 1 in
  if not (d > 0. && d <= 1e150) then fail (snd args.(1)) (Msg.fog_distance d);
  tex "fog" loc args

let mix loc args =
  let t = n args 2 in
  match (fst args.(0), fst args.(1)) with
  | VNum a, VNum b -> vnum loc (a +. (t *. (b -. a)))
  | VVec a, VVec b -> vvec loc (Vec3.madd a t (Vec3.sub b a))
  | _ -> unchecked ()

let mix_type = function
  | [ Ty.Num; Num; _ ] -> Ok Ty.Num
  | [ Vec; Vec; _ ] -> Ok Ty.Vec
  | a :: b :: _ when Ty.known a && Ty.known b -> Error (Msg.mix a b)
  | _ -> Ok Ty.Unknown

(* ---- The table ---- *)

let f1 name usage doc f =
  {
    name;
    usage;
    doc;
    kind =
      Function
        { arity = Exactly 1; arg = all_of number; result = returns Ty.Num; impl = F1 f };
  }

let partial name usage doc ok what f =
  {
    name;
    usage;
    doc;
    kind =
      Function
        {
          arity = Exactly 1;
          arg = all_of number;
          result = returns Ty.Num;
          impl = Partial (ok, what, f);
        };
  }

let fn ?(arity = 1) ?(arg = all_of number) ?(result = returns Ty.Num) name usage doc impl
    =
  { name; usage; doc; kind = Function { arity = Exactly arity; arg; result; impl } }

let fn_arity arity arg result name usage doc impl =
  { name; usage; doc; kind = Function { arity; arg; result; impl } }

let texture ?(arity = Exactly 3) ?(arg = all_of Any) name usage doc impl =
  fn_arity arity arg (returns (Ty.Tex name)) name usage doc (Code impl)

let pattern name usage doc arity =
  texture ~arity:(Among ([ 2; 3 ], arity)) name usage doc (tex name)

(* [min] or [max] of two or more numbers, [pick] choosing between two. *)
let extremum name usage doc pick =
  fn_arity
    (At_least (2, Msg.at_least_two name))
    (all_of number) (returns Ty.Num) name usage doc
    (Code
       (fun _ args ->
         VNum
           (Array.fold_left
              (fun m (v, _) -> match v with VNum x -> pick m x | _ -> m)
              (n args 0) args)))

let unit_interval x = x >= -1. && x <= 1.
let in_unit = "a value in [-1, 1]"

let all =
  [
    f1 "sin" "sin(x)" "the sine of x radians" sin;
    f1 "cos" "cos(x)" "the cosine of x radians" cos;
    f1 "tan" "tan(x)" "the tangent of x radians" tan;
    partial "asin" "asin(x)" "the arcsine of x in [-1, 1], in radians" unit_interval
      in_unit asin;
    partial "acos" "acos(x)" "the arccosine of x in [-1, 1], in radians" unit_interval
      in_unit acos;
    f1 "atan" "atan(x)" "the arctangent of x, in radians" atan;
    fn ~arity:2 "atan2" "atan2(y, x)"
      "the angle of the point (x, y) from the x axis, in radians" (F2 Float.atan2);
    f1 "radians" "radians(d)" "d degrees in radians" (fun d -> d *. Float.pi /. 180.);
    f1 "degrees" "degrees(r)" "r radians in degrees" (fun r -> r *. 180. /. Float.pi);
    {
      name = "pi";
      usage = "pi";
      doc = "π, 3.14159…";
      kind =
        Number
          (let v = VNum Float.pi in
           fun _ -> v);
    };
    partial "sqrt" "sqrt(x)" "the square root of x ≥ 0"
      (fun x -> x >= 0.)
      "a value ≥ 0" sqrt;
    f1 "abs" "abs(x)" "the magnitude of x" Float.abs;
    f1 "floor" "floor(x)" "the largest whole number ≤ x" Float.floor;
    f1 "ceil" "ceil(x)" "the smallest whole number ≥ x" Float.ceil;
    f1 "round" "round(x)" "the nearest whole number, halves away from 0" Float.round;
    f1 "exp" "exp(x)" "e to the power x" exp;
    partial "log" "log(x)" "the natural logarithm of x > 0"
      (fun x -> x > 0.)
      "a value > 0" log;
    extremum "min" "min(a, b, …)" "the smallest of its arguments" Float.min;
    extremum "max" "max(a, b, …)" "the largest of its arguments" Float.max;
    fn ~arity:2 "pow" "pow(a, b)" "a to the power b" (F2 Float.pow);
    fn ~arity:3 "clamp" "clamp(x, lo, hi)" "x limited to [lo, hi] (lo ≤ hi)"
      (Code
         (fun loc args ->
           let x = n args 0 and lo = n args 1 and hi = n args 2 in
           if lo > hi then fail loc (Msg.clamp lo hi);
           VNum (Float.min hi (Float.max lo x))));
    fn ~arity:3
      ~arg:(fun i -> if i < 2 then Any else number)
      ~result:mix_type "mix" "mix(a, b, t)" "a + t·(b − a), of two numbers or two vectors"
      (Code mix);
    fn ~arity:2 ~arg:(all_of vector) "dot" "dot(v, w)" "the dot product of two vectors"
      (Code (fun loc args -> vnum loc (Vec3.dot (v args 0) (v args 1))));
    fn ~arity:2 ~arg:(all_of vector) ~result:(returns Ty.Vec) "cross" "cross(v, w)"
      "the cross product of two vectors"
      (Code (fun loc args -> vvec loc (Vec3.cross (v args 0) (v args 1))));
    fn ~arg:(all_of vector) "length" "length(v)" "the length of a vector"
      (Code (fun loc args -> vnum loc (Vec3.length (v args 0))));
    fn ~arg:(all_of vector) ~result:(returns Ty.Vec) "normalize" "normalize(v)"
      "the vector of length 1 along v; (0, 0, 0) has none"
      (Code
         (fun loc args ->
           let x = v args 0 in
           if Vec3.max_abs x = 0. then fail loc Msg.normalize_zero;
           vvec loc (Vec3.normalize x)));
    fn ~arg:(all_of list) "len" "len(l)" "the number of elements of a list"
      (Code
         (fun _ args ->
           match fst args.(0) with
           | VList l -> VNum (Float.of_int (Array.length l))
           | _ -> unchecked ()));
    fn ~arity:3 ~result:(returns Ty.Vec) "rgb" "rgb(r, g, b)"
      "the colour vector (linear, components usually in [0, 1])"
      (Code (fun _ args -> VVec (Vec3.v (n args 0) (n args 1) (n args 2))));
    fn ~arity:3 ~result:(returns Ty.Vec) "hsv" "hsv(h, s, v)"
      "h in [0, 1) (wraps), s and v in [0, 1], to a linear RGB vector"
      (Code (fun loc args -> vvec loc (hsv (n args 0) (n args 1) (n args 2))));
    fn "rand" "rand(seed)"
      "a deterministic hash of a number into [0, 1): the same on every run"
      (Code (fun _ args -> VNum (Hash.of_float (n args 0))));
    {
      name = "time";
      usage = "time";
      doc = "the seconds of the frame being evaluated (0 for a still)";
      kind = Number (fun h -> h.time_v);
    };
    {
      name = "frame";
      usage = "frame";
      doc = "the number of the frame being evaluated (0 for a still)";
      kind = Number (fun h -> h.frame_v);
    };
    texture "checker" "checker(c1, c2, size)" "a 3-D checkerboard of two colours"
      (tex "checker");
    texture "stripes" "stripes(c1, c2, size)" "stripes along x of two colours"
      (tex "stripes");
    pattern "noise" "noise(c1, c2, scale)"
      "Perlin noise between two colours (or a colour map: noise(MAP, scale)); \
       noise(scale, amount) is a bump map"
      Msg.noise_arity;
    pattern "marble" "marble(c1, c2, scale)"
      "marble veins between two colours (or marble(MAP, scale))"
      (Msg.marble_arity "marble");
    pattern "wood" "wood(c1, c2, scale)"
      "wood rings between two colours (or wood(MAP, scale))" (Msg.marble_arity "wood");
    texture ~arity:(Exactly 2)
      ~arg:(fun i -> if i = 0 then file_name else number)
      "image" "image(\"file.png\", scale)"
      "a PNG or PPM image on the surface's (u, v), or a height map as a bump map"
      (tex "image");
    texture ~arity:(Exactly 2)
      ~arg:(fun i -> if i = 0 then vector else map_or_colour)
      "gradient" "gradient(AXIS, MAP)"
      "a colour map along an axis (a texture); gradient(HORIZON, ZENITH), a sky (a \
       background)"
      (tex "gradient");
    texture
      ~arity:(At_least (1, fun _ -> Msg.color_map_empty))
      ~arg:(all_of Entry) "color_map" "color_map((t0, c0), (t1, c1), …)"
      "colours at values t in [0, 1], in order: the colours of gradient, noise, marble, \
       wood"
      color_map;
    texture ~arity:(Exactly 2)
      ~arg:(fun i -> if i = 0 then vector else number)
      "fog" "fog(COLOR, DISTANCE)"
      "fog of that colour, 37 % thick at that distance (settings)" fog;
  ]

module By_name = Map.Make (String)

let table = List.fold_left (fun m b -> By_name.add b.name b m) By_name.empty all
let find name = By_name.find_opt name table
let names = List.map (fun b -> b.name) all

(* ---- Checking a call ---- *)

let count_ok arity n =
  match arity with
  | Exactly k -> if n = k then None else Some (fun name -> Msg.arity name k n)
  | At_least (k, msg) -> if n >= k then None else Some (fun _ -> msg n)
  | Among (ks, msg) -> if List.mem n ks then None else Some (fun _ -> msg n)

(* The first argument whose known type is wrong. *)
let wrong_argument b (f : fn) args =
  let rec go i = function
    | [] -> None
    | ((t : Ty.t), l) :: rest -> (
        let next () = go (i + 1) rest in
        match (f.arg i, t) with
        | _, Unknown | Any, _ -> next ()
        | Of (ok, what), t ->
            if ok t then next () else Some (l, Msg.argument (i + 1) b.name what t)
        | Entry, Pair (Num, Vec) -> next ()
        | Entry, Pair (a, c) ->
            if Ty.known a && Ty.known c then
              Some (l, Msg.color_map_entry_types (i + 1) a c)
            else next ()
        | Entry, t -> Some (l, Msg.color_map_entry (i + 1) t))
  in
  go 0 args

let rec entry_known : Ty.t -> bool = function
  | Pair (a, b) -> entry_known a && entry_known b
  | t -> Ty.known t

let check b f loc args =
  match count_ok f.arity (List.length args) with
  | Some msg -> Error (loc, msg b.name)
  | None -> (
      match wrong_argument b f args with
      | Some e -> Error e
      | None -> (
          let tys = List.map fst args in
          match f.result tys with
          | Error m -> Error (loc, m)
          | Ok t -> Ok (if List.for_all entry_known tys then t else Ty.Unknown)))

let wrong what = invalid_arg ("Builtins: " ^ what ^ " of a type not checked")

let call b f loc args =
  match f.impl with
  | F1 g -> (
      match fst args.(0) with VNum x -> VNum (finite loc (g x)) | _ -> wrong b.name)
  | Partial (ok, what, g) -> (
      match fst args.(0) with
      | VNum x ->
          if not (ok x) then fail loc (Msg.domain b.name what x);
          VNum (finite loc (g x))
      | _ -> wrong b.name)
  | F2 g -> (
      match (fst args.(0), fst args.(1)) with
      | VNum x, VNum y -> VNum (finite loc (g x y))
      | _ -> wrong b.name)
  | Code g -> g loc args
