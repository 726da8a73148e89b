let angle_vector = "Vectors are written (x, y, z), not <x, y, z>."

let directive = function
  | "declare" | "local" ->
      "`#declare` is not used in .rts scripts: write `let NAME = value`"
  | "include" -> "`#include` is not used in .rts scripts: write `include \"file.rts\"`"
  | "if" | "ifdef" | "else" | "end" ->
      "`#if` is not used in .rts scripts: write `if CONDITION { … } else { … }`"
  | "while" | "for" ->
      "`#while` is not used in .rts scripts: write `for i in A to B { … }`"
  | "macro" -> "`#macro` is not used in .rts scripts: write `fn NAME(a, b) { … }`"
  | d ->
      Printf.sprintf
        "`#%s` is not used in .rts scripts: there are no `#` directives (comments are \
         `//` or `/* */`)"
        d

let keyword_as_name k =
  Printf.sprintf "`%s` is a keyword%s: it cannot be a name; choose another%s." k
    (if k = "step" then " (as in `for i in 0 to 10 step 2`)" else "")
    (if k = "step" then ", such as `dt`" else "")

let camera_up (view : Vec3.t) (up : Vec3.t) =
  (* Looking mostly up or down, z makes a good upright; otherwise y does. *)
  let ax = Float.abs view.x and ay = Float.abs view.y and az = Float.abs view.z in
  let suggestion = if ay >= ax && ay >= az then "(0, 0, 1)" else "(0, 1, 0)" in
  Printf.sprintf
    "the camera looks straight along its `up` direction (%g, %g, %g), so the image has \
     no upright; give an `up` across the view, such as `up: %s`"
    up.x up.y up.z suggestion

let defined_later x (def : Loc.t) =
  Printf.sprintf
    "`%s` is defined later, at line %d: a name can be used only after its definition" x
    def.line
