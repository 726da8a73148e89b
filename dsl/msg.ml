let sp = Printf.sprintf

let fmt_num x =
  if Float.is_integer x && Float.abs x < 1e15 then sp "%.0f" x else sp "%g" x

let num = fmt_num

let grouped n =
  let s = string_of_int n in
  let len = String.length s in
  String.concat ""
    (List.init len (fun i ->
         (if i > 0 && (len - i) mod 3 = 0 then " " else "") ^ String.make 1 s.[i]))

(* ---- Did you mean ---- *)

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
  match suggest x candidates with Some c -> sp "; did you mean `%s`?" c | None -> ""

(* The last word of a name ([blue] of [sky_blue], or of [SkyBlue]), lowercase. *)
let last_word x =
  let n = String.length x in
  let rec start i =
    if i <= 0 then 0
    else if x.[i - 1] = '_' then i
    else if Char.uppercase_ascii x.[i] = x.[i] && Char.lowercase_ascii x.[i] <> x.[i] then
      i
    else start (i - 1)
  in
  let i = start (n - 1) in
  String.lowercase_ascii (String.sub x i (n - i))

let library_hint x ~file library =
  let lx = String.lowercase_ascii x in
  let limit = max 1 (min 3 (String.length x / 3)) in
  let close =
    List.filter_map
      (fun c ->
        let d = edit_distance lx c in
        if c <> x && (d <= limit || String.equal (last_word x) (last_word c)) then
          Some (d, c)
        else None)
      library
  in
  match List.stable_sort (fun (d, _) (e, _) -> Int.compare d e) close with
  | [] -> ""
  | l ->
      let names =
        List.map (fun (_, c) -> sp "`%s`" c) (List.filteri (fun i _ -> i < 3) l)
      in
      let rec words = function
        | [] -> ""
        | [ a ] -> a
        | [ a; b ] -> a ^ " or " ^ b
        | a :: r -> a ^ ", " ^ words r
      in
      sp "; did you mean %s (of `include \"%s\"`)?" (words names) file

(* ---- Types ---- *)

let tn = Ty.name

let cannot_combine op a b =
  sp "`%s` cannot combine %s and %s" (Ast.binop_name op) (tn a) (tn b)

let needs_booleans op t = sp "`%s` needs booleans, got %s" (Ast.binop_name op) (tn t)
let neg_needs t = sp "`-` needs a number or a vector, got %s" (tn t)
let not_needs t = sp "`not` needs a boolean, got %s" (tn t)
let condition t = sp "the condition of `if` must be a boolean, got %s" (tn t)
let component t = sp "a vector component must be a number, got %s" (tn t)
let vector_component x = sp "a vector has components `x`, `y` and `z`, not `%s`" x

let body_member x =
  sp "a body has `position` and `velocity`, not `%s`%s" x
    (hint x [ "position"; "velocity" ])

let dot_needs x t = sp "`.%s` needs a vector or a body, got %s" x (tn t)
let loop_bound what t = sp "the %s of a `for` loop must be a number, got %s" what (tn t)

let for_each_needs t =
  sp
    "`for NAME in` goes over a list (`for p in [a, b] { … }`) or a range (`for i in A to \
     B { … }`), got %s"
    (tn t)

let list_element i t first =
  sp "the elements of a list must be of one type: element %d is %s, the first %s" i (tn t)
    (tn first)

let index_needs t = sp "`[…]` takes an element of a list, got %s" (tn t)
let index_type t = sp "a list index must be a number, got %s" (tn t)
let index_whole x = sp "a list index must be a whole number, got %s" (num x)

let index_range x n =
  if n = 0 then sp "index %s is out of range: the list is empty" (num x)
  else
    sp "index %s is out of range: the list has %d element%s, indices 0 to %d" (num x) n
      (if n = 1 then "" else "s")
      (n - 1)

let field_type (fl : Schema.field) (t : Ty.t) =
  let must what = sp "`%s` must be %s, got %s" fl.name what (tn t) in
  match fl.ty with
  | Number | Integer -> must "a number"
  | Boolean -> must "true or false"
  | File -> must "a file name string"
  | Choice l -> must (sp "a string (%s)" (Schema.quoted l))
  | Vector | Direction | Colour -> must "a vector (x, y, z)"
  | Material -> must "a material (material { … })"
  | Base_material -> must "a material"
  | Texture -> must "a texture (checker(…), stripes(…), …)"
  | Bump -> must "noise(scale, amount) or image(\"file.png\", amount)"
  | Scale -> must "a number or a vector"
  | Background -> (
      match t with
      | Tex _ -> must "a colour (r, g, b) or gradient(HORIZON, ZENITH)"
      | _ -> must "a vector (x, y, z)")
  | Fog -> must "fog(COLOR, DISTANCE)"
  | Gamma ->
      sp "`%s` must be \"srgb\" or a number in %s" fl.name (Schema.range_text fl.range)
  | Interval -> must "a pair of numbers (a, b)"

let interval_order name a b = sp "`%s` must be (a, b) with a ≤ b, got (%g, %g)" name a b

(* ---- Names and calls ---- *)

let unknown_name x hint = sp "unknown name `%s`%s" x hint
let unknown_name_later x def = sp "unknown name `%s`: %s" x (Hints.defined_later x def)

let macro_in_expression f =
  sp
    "`%s` is a scene macro (fn %s(…) { … }): call it as a statement, not in an expression"
    f f

let not_a_function f t = sp "`%s` is %s, not a function" f (tn t)

let function_as_statement f =
  sp
    "`%s` is an expression function (fn %s(…) = …): use it in an expression, e.g. let x \
     = %s(…)"
    f f f

let builtin_as_statement f = sp "`%s` is a built-in function: use it in an expression" f
let not_a_macro f t = sp "`%s` is %s, not a scene macro" f (tn t)
let arity f k n = sp "`%s` takes %d argument%s, got %d" f k (if k = 1 then "" else "s") n
let param_twice p = sp "parameter `%s` is named twice" p

(* ---- Built-in functions ---- *)

let argument i f what t = sp "argument %d of `%s` must be %s, got %s" i f what (tn t)
let at_least_two f n = sp "`%s` takes at least 2 arguments, got %d" f n

let marble_arity f n =
  sp "`%s` takes 3 arguments (c1, c2, scale), or 2 (color_map(…), scale); got %d" f n

let noise_arity n =
  sp
    "`noise` takes 3 arguments (c1, c2, scale) or 2 (color_map(…), scale) as a texture, \
     or 2 (scale, amount) as a bump map; got %d"
    n

let color_map_empty = "`color_map` needs at least one entry (t, colour)"
let domain f what x = sp "`%s` needs %s, got %s" f what (num x)
let clamp lo hi = sp "`clamp` needs lo ≤ hi, got %s > %s" (num lo) (num hi)
let mix a b = sp "`mix` mixes two numbers or two vectors, got %s and %s" (tn a) (tn b)
let normalize_zero = "`normalize` of the zero vector"

let gradient_argument t =
  argument 2 "gradient"
    "a color_map(…) (a texture along an axis) or a colour (a background from horizon to \
     zenith)"
    t

let color_map_t i t =
  sp "entry %d of `color_map` has t = %s; t must be in [0, 1]" i (num t)

let color_map_order i t prev =
  sp
    "entry %d of `color_map` has t = %s, below the %s before it: entries go in \
     increasing t"
    i (num t) (num prev)

let color_map_negative i =
  sp "entry %d of `color_map` has a colour with a negative component" i

let color_map_entry_types i a b =
  sp
    "entry %d of `color_map` must be (t, colour) with t a number and colour (r, g, b), \
     got (%s, %s)"
    i (tn a) (tn b)

let color_map_entry i t =
  sp "entry %d of `color_map` must be a pair (t, colour), e.g. (0.5, (1, 0, 0)), got %s" i
    (tn t)

let fog_distance d = sp "the distance of `fog` must be in (0, 1e150], got %s" (num d)

(* ---- Numbers and operators ---- *)

let nan = "this expression is not a number (NaN)"
let overflow = "this expression overflows to infinity"
let division_by_zero = "division by zero"
let modulo_by_zero = "modulo by zero"
let not_real x y = sp "%s ^ %s is not a real number" (num x) (num y)

(* ---- Blocks and fields ---- *)

let given_twice n kind line =
  sp "`%s` is given twice in this %s (first at line %d)" n kind line

let holds_only_fields ?inner kind =
  match Option.bind inner (fun w -> Hints.pov_word w) with
  | Some h -> sp "a %s holds only `field: value` pairs (and `let`): %s" kind h
  | None ->
      sp "a %s holds only `field: value` pairs (and `let`); objects go in a `group`" kind

let unknown_field n kind hint =
  match Hints.pov_word ~block:kind n with
  | Some h -> sp "unknown field `%s` in %s: %s" n kind h
  | None -> sp "unknown field `%s` in %s%s" n kind hint

let needs_field kind n = sp "%s needs a `%s` field" kind n

let out_of_range (fl : Schema.field) x =
  sp "`%s` %s, got %s" fl.name (Schema.must fl) (num x)

let top_level_only k =
  sp
    "`%s` cannot be inside a group: a group's transforms and material apply to objects \
     only; write it at top level"
    k

let material_statement =
  "a material is a value: write `material: material { … }` inside an object, or `let m = \
   material { … }`"

let unknown_block x =
  match Hints.pov_word x with
  | Some h -> sp "unknown block `%s`: %s" x h
  | None -> sp "unknown block `%s`%s" x (hint x Schema.keywords)

let once what (l : Loc.t) =
  sp "%s is given twice (the first is at %s:%d:%d)" what l.file l.line l.col

let coordinates n =
  sp "the coordinates of `%s` must be %s" n (Schema.range_text Schema.coordinate)

let non_zero n = sp "`%s` must be a non-zero vector" n

let negative_colour n (v : Vec3.t) =
  sp "a colour has no negative component; `%s` is (%s, %s, %s)" n (num v.x) (num v.y)
    (num v.z)

let scale_factors = "`scale` factors must be non-zero, with magnitudes in [1e-150, 1e150]"

let light_choice_both =
  "a light has a `position` (point light) or a `direction` (directional light), not both"

let light_choice_none =
  "a light needs a `position` (point light) or a `direction` (directional light)"

let spot_only n = sp "`%s` is for a spot light: give it a `point_at`" n
let attenuation = "`attenuation` (a0, a1, a2) must be non-negative and not all zero"
let zero_direction = "the `direction` of a light must not be (0, 0, 0)"
let not_parallel = "the edges of a parallelogram must not be parallel"
let not_in_line = "the corners of a triangle must not be in a line"
let box_order = "a box needs min < max on every axis"
let cylinder_ends = "the base and top of a cylinder must differ"
let cone_ends = "the base and top of a cone must differ"
let cone_radii = "a cone needs a `base_radius` or a `top_radius` greater than 0"

let height_field_size =
  "the `size` (sx, sy, sz) of a height field must be positive on every axis"

let invalid what why = sp "invalid %s: %s" what why

(* ---- Settings, camera, animation, physics ---- *)

let gamma r = sp "`gamma` must be \"srgb\" or a number in %s" (Schema.range_text r)

let background_gradient =
  "a background gradient(HORIZON, ZENITH) takes two colours (r, g, b) with no negative \
   component"

let fog_colour = "the colour of `fog` has no negative component"

let camera_kind s kinds =
  match suggest s kinds with
  | Some k -> sp "unknown camera kind \"%s\"; did you mean \"%s\"?" s k
  | None -> sp "unknown camera kind \"%s\"; use %s" s (Schema.quoted kinds)

let fisheye_fov must x = sp "a fisheye's `fov` %s, got %s" must (num x)

let orthographic_fov =
  "an orthographic camera has no `fov`: its `width` sets how much it sees"

let fov must x wider =
  sp "`fov` %s, got %s%s" must (num x)
    (if wider then " (a wider view needs kind: \"fisheye\")" else "")

let width_not_orthographic =
  "`width` is for an orthographic camera (kind: \"orthographic\")"

let orthographic_width =
  "an orthographic camera needs a `width` (world units across the image)"

let aperture_focal =
  "a camera with an `aperture` needs a `focal_distance` (the distance that is in focus)"

let fps_low lo x = sp "`fps` must be greater than %s, got %s" (num lo) (num x)
let fps_high hi = sp "`fps` must be at most %s" (num hi)
let frames_or_duration = "give `frames` or `duration`, not both"
let too_many_frames n = sp "this animation would have more than %s frames" (grouped n)

let physics_method s methods =
  sp "unknown physics method \"%s\"%s; use %s" s (hint s methods) (Schema.quoted methods)

(* ---- Materials and textures ---- *)

let reflection_transparency r t =
  sp "reflection + transparency must be at most 1, got %s + %s = %s" (num r) (num t)
    (num (r +. t))

let texture_size what f x =
  sp "the %s of `%s` must be in [1e-150, 1e150], got %s" what f (num x)

let mapped_arguments f = sp "%s(color_map(…), scale) takes a colour map and a number" f
let marble_arguments f = sp "%s takes (c1, c2, scale) or (color_map(…), scale)" f

let noise_texture =
  "noise(scale, amount) is a bump map: use it as `bump:`; as a texture, noise takes (c1, \
   c2, scale)"

let gradient_axis = "the axis of `gradient` must be a non-zero vector within ±1e150"

let gradient_texture =
  "gradient(HORIZON, ZENITH) with two colours is a background (settings { background: … \
   }); as a texture, write gradient(AXIS, color_map(…))"

let color_map_texture =
  "a color_map is the colours of a texture, not a texture itself: write gradient(AXIS, \
   color_map(…))"

let image_scale x = sp "the scale of `image` must be in [1e-150, 1e150], got %s" (num x)

let image_needs_scale =
  "image(\"file.png\", scale) needs a scale (1 maps the picture once onto the surface's \
   (u, v))"

let image_arguments = "image(\"file.png\", scale) takes a file name and a number"
let image_file = "image(…) needs a file name"
let not_a_texture f = sp "`%s` is not a texture" f

let noise_bump_scale x =
  sp "the scale of a noise bump must be in [1e-150, 1e150], got %s" (num x)

let noise_bump_amount = "the amount of a noise bump is out of range"
let noise_bump_arguments = "a noise bump map takes two numbers: noise(scale, amount)"

let image_bump_arguments =
  "an image bump map takes a file name and an amount: image(\"h.png\", amount)"

let not_a_bump f =
  sp "`%s(…)` is not a bump map: use noise(scale, amount) or image(\"file.png\", amount)"
    f

(* ---- Groups, CSG, bodies ---- *)

let csg_empty what = sp "%s needs at least one object inside" what

let difference_needs_two =
  "a `difference` needs a solid to subtract from and at least one to subtract"

let height_field_not_solid kind block =
  sp "a %s is not a solid: `%s` combines solids" kind block

let not_solid kind block =
  sp
    "%s is not a solid: %s combines solids (sphere, box, torus, cylinder or cone with \
     caps, closed mesh, plane as a half-space, CSG of solids)%s"
    (match kind with
    | "mesh" -> "this mesh"
    | "cylinder" -> "a cylinder without caps"
    | "cone" -> "a cone without caps"
    | kd -> sp "a %s" kd)
    (if block = "group" then "a CSG block" else sp "`%s`" block)
    (if kind = "cylinder" || kind = "cone" then "; give it `caps: true`" else "")

let body_in_group = "a body cannot be inside a group or another body"
let body_twice n = sp "body `%s` is defined twice" n

let body_scaled n sx sy sz =
  sp
    "the sphere of body `%s` is scaled differently along its axes (%s, %s, %s): a body \
     must stay a sphere"
    n (num sx) (num sy) (num sz)

let body_one_sphere = "a body holds exactly one sphere { … }"

(* ---- Limits ---- *)

let steps_limit n =
  sp
    "this scene takes more than %d evaluation steps (loop iterations and calls); that is \
     the limit"
    n

let depth_limit n = sp "calls are nested more than %d deep (runaway recursion?)" n
let objects_limit n = sp "this scene builds more than %d objects; that is the limit" n

let memory ~objects ~limit ~baseline ~per_object =
  sp
    "%s objects need about %.0f MB of memory; this process may use %.0f MB in all \
     (ulimit -v), room for about %d objects: raise the limit or build fewer objects"
    (if objects >= 1_000_000 then sp "%.1f million" (Float.of_int objects /. 1e6)
     else string_of_int objects)
    (Float.of_int objects *. Float.of_int per_object /. 1e6)
    (Float.of_int limit /. 1e6)
    (max 0 ((limit - baseline) / per_object))

let loop_runs ~count ~loops ~total ~steps ~objects =
  sp
    "this loop would run %s times%s; a scene may take at most %d loop iterations and \
     calls, and build at most %d objects"
    (num count)
    (if loops > 1. then
       sp " inside loops that have %s iterations left (%s in all)" (num loops) (num total)
     else "")
    steps objects

let loop_builds ~total ~each ~count ~loops ~built ~objects =
  sp
    "this loop would build %s objects (%s an iteration, %s iterations%s)%s; a scene may \
     build at most %d objects"
    (num (total *. each))
    (num each) (num count)
    (if loops > 1. then sp " inside loops that have %s iterations left" (num loops)
     else "")
    (if built > 0 then sp ", after the %d already built" built else "")
    objects

let loop_zero a b st =
  sp "this loop runs zero times: it counts from %s to %s in steps of %s%s" (num a) (num b)
    (num st)
    (if st > 0. then " (to count down, give a negative step: `step -1`)"
     else " (to count up, give a positive step)")

let loop_step_zero = "the step of a `for` loop must not be 0"
