type t =
  | Num
  | Bool
  | Vec
  | Str
  | Mat
  | Tex of string
  | Pair of t * t
  | List of t
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
  | List a, List b -> equal a b
  | Fun n, Fun m | Macro n, Macro m -> n = m
  | Num, Num | Bool, Bool | Vec, Vec | Str, Str | Mat, Mat | Body, Body -> true
  | Unknown, Unknown -> true
  | _ -> false

let rec join a b =
  match (a, b) with
  | Unknown, _ | _, Unknown -> Some Unknown
  | List x, List y -> Option.map (fun t -> List t) (join x y)
  | Pair (a1, a2), Pair (b1, b2) -> (
      match (join a1 b1, join a2 b2) with
      | Some x, Some y -> Some (Pair (x, y))
      | _ -> None)
  | _ when equal a b -> Some a
  | _ when String.equal (name a) (name b) -> Some Unknown
  | _ -> None

and name = function
  | Num -> "a number"
  | Bool -> "a boolean"
  | Vec -> "a vector"
  | Str -> "a string"
  | Mat -> "a material"
  | Tex "fog" -> "a fog (fog(colour, distance))"
  | Tex "color_map" -> "a colour map"
  | Tex _ -> "a texture"
  | Pair _ -> "a pair (t, colour)"
  | List t -> ( match plural t with "" -> "a list" | p -> "a list of " ^ p)
  | Fun _ -> "a function"
  | Macro _ -> "a scene macro"
  | Builtin _ -> "a built-in function"
  | Body -> "a body"
  | Unknown -> "a value"

(* What a list of values of the type holds, as messages say it; "" where not known. *)
and plural = function
  | Num -> "numbers"
  | Bool -> "booleans"
  | Vec -> "vectors"
  | Str -> "strings"
  | Mat -> "materials"
  | Tex "fog" -> "fogs"
  | Tex "color_map" -> "colour maps"
  | Tex _ -> "textures"
  | Pair _ -> "pairs (t, colour)"
  | List _ -> "lists"
  | Fun _ -> "functions"
  | Macro _ -> "scene macros"
  | Builtin _ -> "built-in functions"
  | Body -> "bodies"
  | Unknown -> ""

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
