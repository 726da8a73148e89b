let angle_vector = "Vectors are written (x, y, z), not <x, y, z>."

(* Each POV-Ray directive named as written, with what a .rts script writes instead. *)
let directive d =
  let instead =
    match d with
    | "declare" -> "write `let NAME = value`"
    | "local" ->
        "write `let NAME = value` (a `let` inside a block, a loop or a `fn` is seen only \
         there)"
    | "undef" ->
        "a name cannot be undefined; a later `let NAME = …` hides the earlier one"
    | "include" -> "write `include \"file.rts\"`"
    | "if" -> "write `if CONDITION { … } else { … }`"
    | "ifdef" | "ifndef" ->
        "a name is always defined before it is used; give it a value with `let` and test \
         it with `if CONDITION { … }`"
    | "else" -> "write `} else {` after `if CONDITION { …`"
    | "elseif" -> "write `} else if CONDITION {`"
    | "switch" | "case" | "range" | "break" ->
        "write `if A { … } else if B { … } else { … }`"
    | "end" -> "`if`, `for` and `fn` bodies are closed by `}`"
    | "for" -> "write `for i in A to B step S { … }` (`step` is optional, 1 by default)"
    | "while" ->
        "write `for i in A to B { … }`: a loop runs over a range known when it starts"
    | "macro" -> "write `fn NAME(a, b) { … }` (a scene macro) or `fn NAME(a, b) = EXPR`"
    | "version" -> "a scene needs no version line: delete it"
    | "default" ->
        "give each object its `material`, or a `group { material: …, … }` its objects"
    | "debug" | "warning" | "error" ->
        "a scene cannot print; `lancer check` lists what it makes"
    | _ -> "there are no `#` directives (comments are `//` or `/* */`)"
  in
  Printf.sprintf "`#%s` is not used in .rts scripts: %s" d instead

(* POV-Ray's words for what lancer writes otherwise, met as an unknown block or field:
   in a material, the field of its own to write; elsewhere, the material to write. *)
let pov_word ?block w =
  let in_material = block = Some "material" in
  match w with
  | "light_source" ->
      Some
        "POV-Ray's `light_source` is `light { position: (x, y, z), color: (r, g, b) }` \
         here"
  | "angle" ->
      Some
        "POV-Ray's `angle` is the horizontal field of view; lancer's camera takes `fov`, \
         the vertical one, in degrees: fov = 2·atan(tan(angle/2)·height/width) (angle 90 \
         on a 4:3 image is `fov: 73.74`)"
  | "pigment" when in_material ->
      Some "POV-Ray's `pigment` is `color: (r, g, b)` (or `texture: …`) here"
  | "pigment" ->
      Some
        "POV-Ray's `pigment` is a material's `color` (or `texture`) here: `material: \
         material { color: (r, g, b) }`"
  | "finish" when in_material ->
      Some
        "POV-Ray's `finish` is this material's own fields here: `ambient`, `diffuse`, \
         `specular`, `shininess`, `reflection`"
  | "finish" ->
      Some
        "POV-Ray's `finish` is the material itself here: `material: material { ambient: \
         …, diffuse: …, specular: …, shininess: …, reflection: … }`"
  | "normal" when in_material ->
      Some "POV-Ray's `normal` is `bump: noise(scale, amount)` here"
  | "normal" ->
      Some
        "POV-Ray's `normal` is a material's `bump` here: `material: material { bump: \
         noise(scale, amount) }`"
  | ("filter" | "transmit") when in_material ->
      Some
        (Printf.sprintf
           "POV-Ray's `%s` is `transparency: T` here (the share of light refracted \
            through, with `ior`)"
           w)
  | "filter" | "transmit" ->
      Some
        (Printf.sprintf
           "POV-Ray's `%s` is written in a material here: `material: material { \
            transparency: 0.9, ior: 1.5, … }` (the glass of `include \
            \"lancer/materials.rts\"` is ready: `material: glass`)"
           w)
  | "metallic" ->
      Some
        "POV-Ray's `metallic` metals are ready here: those of `include \
         \"lancer/materials.rts\"` (`gold`, `copper`, `silver`, `chrome`), as `material: \
         gold` or, in a material, `base: gold`"
  | _ -> None

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
