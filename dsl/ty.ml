type t =
  | Num
  | Bool
  | Vec
  | Str
  | Mat
  | Tex of string
  | Pair of t * t
  | Fun of int
  | Macro of int
  | Builtin of string
  | Body
  | Unknown

let known = function Unknown -> false | _ -> true

let rec equal a b =
  match (a, b) with
  | Tex x, Tex y | Builtin x, Builtin y -> String.equal x y
  | Pair (a1, a2), Pair (b1, b2) -> equal a1 b1 && equal a2 b2
  | Fun n, Fun m | Macro n, Macro m -> n = m
  | Num, Num | Bool, Bool | Vec, Vec | Str, Str | Mat, Mat | Body, Body -> true
  | Unknown, Unknown -> true
  | _ -> false

let name = function
  | Num -> "a number"
  | Bool -> "a boolean"
  | Vec -> "a vector"
  | Str -> "a string"
  | Mat -> "a material"
  | Tex "fog" -> "a fog (fog(colour, distance))"
  | Tex "color_map" -> "a colour map"
  | Tex _ -> "a texture"
  | Pair _ -> "a pair (t, colour)"
  | Fun _ -> "a function"
  | Macro _ -> "a scene macro"
  | Builtin _ -> "a built-in function"
  | Body -> "a body"
  | Unknown -> "a value"

let accepts (ty : Schema.ty) t =
  match (ty, t) with
  | (Number | Integer), Num
  | Boolean, Bool
  | (File | Choice _), Str
  | (Vector | Direction | Colour), Vec
  | (Material | Base_material), Mat
  | Texture, (Tex _ | Vec)
  | Bump, Tex _
  | Scale, (Num | Vec)
  | Background, (Vec | Tex "gradient")
  | Fog, Tex "fog"
  | Gamma, (Str | Num)
  | Interval, Pair ((Num | Unknown), (Num | Unknown)) ->
      true
  | _ -> false
