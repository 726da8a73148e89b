type ty =
  | Number
  | Integer
  | Boolean
  | File
  | Choice of string list
  | Vector
  | Direction
  | Colour
  | Material
  | Base_material
  | Texture
  | Bump
  | Scale
  | Background
  | Fog
  | Gamma
  | Interval

type bound = Incl of float | Excl of float | Unbounded
type range = Any | Real of bound * bound | Whole of int * int
type default = Required | Value of string | Absent of string
type condition = Always | Kind_in of string list | With of string | Without of string

type field = {
  name : string;
  ty : ty;
  range : range;
  default : default;
  repeats : bool;
  condition : condition;
  noun : string;
  unit : string;
  doc : string;
}

type block = {
  id : string;
  keyword : string;
  chosen_by : string option;
  holds_objects : bool;
  doc : string;
  fields : field list;
}

(* Ranges as the evaluator checks them. *)
let big = 1e150
let non_negative = Real (Incl 0., Incl big)
let positive = Real (Excl 0., Incl big)
let unit_interval = Real (Incl 0., Incl 1.)
let length = Real (Incl 1e-150, Incl big)
let coordinate = Real (Incl (-.big), Incl big)

(* A number in the range of a length is called a length in messages. *)
let f ?(range = Any) ?(default = Required) ?(repeats = false) ?(condition = Always)
    ?(noun = if range = length then "a length" else "") ?(unit = "") name ty doc =
  { name; ty; range; default; repeats; condition; noun; unit; doc }

let opt v = Value v

(* Fields every object, group and CSG block takes, after its own. *)
let common =
  [
    f "material" Material
      ~default:(Absent "the enclosing group's, or the default material")
      "the object's material (`material { … }` or a name bound to one)";
    f "translate" Vector ~repeats:true ~default:(Absent "none")
      "moves the object by (x, y, z)";
    f "rotate" Vector ~repeats:true ~default:(Absent "none")
      "rotates by (ax, ay, az) degrees about X, then Y, then Z";
    f "scale" Scale ~repeats:true ~default:(Absent "none")
      "scales by s, or by (sx, sy, sz); factors non-zero, magnitudes in [1e-150, 1e150]";
  ]

let shape ?(doc = "") id own =
  {
    id;
    keyword = id;
    chosen_by = None;
    holds_objects = false;
    doc;
    fields = own @ common;
  }

let shape_blocks =
  [
    shape "sphere"
      [ f "center" Vector "the centre"; f "radius" Number ~range:length "the radius" ];
    shape "plane" ~doc:"the plane n̂·P = offset, two-sided, infinite"
      [
        f "normal" Direction "the normal n";
        f "offset" Number ~range:coordinate ~default:(opt "0")
          "its signed distance from the origin along n̂";
      ];
    shape "parallelogram" ~doc:"A + a·E1 + b·E2, a, b ∈ [0, 1]"
      [
        f "origin" Vector "the corner A";
        f "edge1" Direction "the first edge E1";
        f "edge2" Direction "the second edge E2, not parallel to E1";
      ];
    shape "triangle"
      [
        f "a" Vector "a corner";
        f "b" Vector "a corner";
        f "c" Vector "a corner, not in line with the other two";
      ];
    shape "paraboloid" ~doc:"open cup, two-sided"
      [
        f "vertex" Vector "the lowest point of the cup";
        f "axis" Direction ~default:(opt "(0, 1, 0)") "the direction it opens towards";
        f "radius" Number ~range:length "the radius of the rim";
        f "height" Number ~range:length "the height of the rim above the vertex";
      ];
    shape "box" ~doc:"axis-aligned before transforms"
      [
        f "min" Vector "the lowest corner";
        f "max" Vector "the highest corner: min < max on every axis";
      ];
    shape "cylinder"
      [
        f "base" Vector "the centre of one end";
        f "top" Vector "the centre of the other end";
        f "radius" Number ~range:length "the radius";
        f "caps" Boolean ~default:(opt "true") "closed by two disks (a solid)";
      ];
    shape "disk"
      [
        f "center" Vector "the centre";
        f "normal" Direction "the normal";
        f "radius" Number ~range:length "the radius";
      ];
    shape "mesh"
      [
        f "file" File "a Wavefront OBJ file, relative to the scene";
        f "smooth" Boolean ~default:(opt "true")
          "interpolate vertex normals: the file's, or where it has none normals computed \
           from the faces (split at edges sharper than 60°)";
      ];
    shape "cone" ~doc:"either radius may be 0 (a point)"
      [
        f "base" Vector "the centre of one end";
        f "base_radius" Number ~range:non_negative ~noun:"a radius"
          "the radius at the base";
        f "top" Vector "the centre of the other end";
        f "top_radius" Number ~range:non_negative ~noun:"a radius" "the radius at the top";
        f "caps" Boolean ~default:(opt "true") "closed by disks (a solid)";
      ];
    shape "torus"
      [
        f "center" Vector "the centre";
        f "major" Number ~range:length "the ring radius R";
        f "minor" Number ~range:length "the tube radius r";
        f "axis" Direction ~default:(opt "(0, 1, 0)") "the axis through the hole";
      ];
    shape "height_field"
      [
        f "file" File "a PNG or PPM image of heights, relative to the scene";
        f "origin" Vector ~default:(opt "(0, 0, 0)") "the corner of pixel (0, 0)";
        f "size" Vector "(sx, sy, sz): the extent along each axis, positive";
        f "smooth" Boolean ~default:(opt "false")
          "interpolate vertex normals computed from the cells (false: flat facets)";
      ];
  ]

let holder id doc fields =
  { id; keyword = id; chosen_by = None; holds_objects = true; doc; fields }

let csg_blocks =
  [
    holder "union" "every member's surface, as a group" common;
    holder "merge" "the boundary of the union of its members" common;
    holder "intersection" "the points inside every member" common;
    holder "difference" "the points inside its first member and inside none of the others"
      common;
  ]

let top ?chosen_by ?(keyword = "") id doc fields =
  {
    id;
    keyword = (if keyword = "" then id else keyword);
    chosen_by;
    holds_objects = false;
    doc;
    fields;
  }

(* Defaults that the scene description has values for are those values, written as a
   scene writes them: a number in the fewest digits that read back as it. *)
let number x =
  let rec go p =
    let s = Printf.sprintf "%.*g" p x in
    let exact = Float.equal (float_of_string s) x && not (String.contains s 'e') in
    if p >= 17 || exact then s else go (p + 1)
  in
  let decimal = go 1 in
  (* A unit fraction (a step of 1/240 s) as the scene writes it, where that is shorter. *)
  let n = if x > 0. then Float.round (1. /. x) else 0. in
  if n >= 2. && n <= 1e6 && Float.equal (1. /. n) x then
    let fraction = Printf.sprintf "1/%.0f" n in
    if String.length fraction < String.length decimal then fraction else decimal
  else decimal

let num x = opt (number x)
let whole n = opt (string_of_int n)
let flag b = opt (string_of_bool b)

let vec (v : Vec3.t) =
  opt (Printf.sprintf "(%s, %s, %s)" (number v.x) (number v.y) (number v.z))

let rgb (c : Color.t) = vec (Vec3.v c.r c.g c.b)
let settings = Settings.default
let camera = Camera.default
let material = Description.default_material
let physics = Description.default_physics
let camera_kinds = Camera.kind_names
let fps, frames = Description.default_animation
let text x = opt (Printf.sprintf "%S" x)
let gamma = match settings.gamma with Settings.Srgb -> text "srgb" | Power g -> num g

let blocks =
  [
    top "settings" "the image and the renderer"
      [
        f "width" Integer
          ~range:(Whole (1, 65536))
          ~default:(whole settings.width) "image width in pixels";
        f "height" Integer
          ~range:(Whole (1, 65536))
          ~default:(whole settings.height) "image height in pixels";
        f "depth" Integer
          ~range:(Whole (1, Settings.max_depth))
          ~default:(whole settings.depth) "maximum ray depth (primary rays are depth 1)";
        f "samples" Integer
          ~range:(Whole (1, 64))
          ~default:(whole settings.samples) "n: n×n samples per pixel";
        f "jitter" Boolean ~default:(flag settings.jitter)
          "move samples inside their sub-cells deterministically";
        f "adaptive" Number ~range:non_negative ~default:(num settings.adaptive)
          "θ: refine pixels whose corner samples differ by more than θ (0: off)";
        f "shadows" Boolean ~default:(flag settings.shadows) "trace shadow rays";
        f "background" Background ~default:(rgb settings.background)
          "what a ray that hits nothing sees";
        f "ambient" Colour ~default:(rgb settings.ambient) "the ambient light's colour";
        f "gamma" Gamma
          ~range:(Real (Excl 0., Incl 1000.))
          ~default:gamma "output encoding: \"srgb\" or a number g (v^(1/g))";
        f "fog" Fog ~default:(Absent "no fog") "fog along every ray but shadow rays";
      ];
    top "camera" "where the image is seen from"
      [
        f "kind" (Choice camera_kinds)
          ~default:(text (Camera.kind_name camera.kind))
          "the projection";
        f "position" Vector ~default:(vec camera.position) "the eye";
        f "look_at" Vector ~default:(vec camera.look_at) "the point at the image's centre";
        f "up" Vector ~default:(vec camera.up) "the image's upright; not along the view";
        f "fov" Number
          ~range:(Real (Excl 0., Excl 180.))
          ~unit:"degrees" ~default:(num camera.fov) ~condition:(Kind_in [ "perspective" ])
          "vertical field of view, degrees";
        f "fov" Number
          ~range:(Real (Excl 0., Incl 360.))
          ~unit:"degrees" ~default:(num camera.fov) ~condition:(Kind_in [ "fisheye" ])
          "angle across the image's inscribed circle, degrees";
        f "width" Number ~range:length ~condition:(Kind_in [ "orthographic" ])
          "width of the view in world units";
        f "aperture" Number ~range:non_negative ~default:(num camera.aperture)
          "radius of the lens (0: a pinhole)";
        f "focal_distance" Number ~range:length
          ~default:(Absent "required with an aperture") "the distance that is in focus";
        f "lens_samples" Integer
          ~range:(Whole (1, 64))
          ~default:(whole camera.lens_samples) "n: n×n rays through the lens per sample";
        f "shutter" Interval
          ~range:(Real (Incl (-.Camera.max_shutter), Incl Camera.max_shutter))
          ~unit:"frames" ~default:(Absent "closed: no motion blur")
          "(open, close): the part of each frame the image gathers, in frames";
        f "shutter_samples" Integer
          ~range:(Whole (1, Camera.max_shutter_samples))
          ~default:(whole Camera.default_shutter_samples)
          ~condition:(With "shutter") "how many instants of the shutter are rendered";
      ];
    top "point_light" ~keyword:"light" ~chosen_by:"position"
      "a point light (a spot light with `point_at`, an area light with `radius` and \
       `samples`)"
      [
        f "position" Vector "where the light is";
        f "color" Colour ~default:(rgb Light.default_color) "its colour";
        f "intensity" Number ~range:non_negative ~default:(num Light.default_intensity)
          "its strength";
        f "attenuation" Vector
          ~default:(vec Light.default_attenuation)
          "(a0, a1, a2): divides by a0 + a1·d + a2·d²; non-negative, not all zero";
        f "radius" Number ~range:non_negative ~default:(num Light.default_radius)
          "radius of an area light";
        f "samples" Integer
          ~range:(Whole (1, 64))
          ~default:(whole Light.default_samples) "n: n×n shadow rays of an area light";
        f "point_at" Vector ~default:(Absent "none: not a spot")
          "makes a spot light pointing there";
        f "inner" Number
          ~range:(Real (Incl 0., Incl 180.))
          ~noun:"an angle" ~unit:"degrees" ~default:(num Light.default_inner)
          ~condition:(With "point_at") "full light within this angle of the axis, degrees";
        f "outer" Number
          ~range:(Real (Incl 0., Incl 180.))
          ~noun:"an angle" ~unit:"degrees" ~default:(num Light.default_outer)
          ~condition:(With "point_at")
          "no light beyond this angle, degrees; at least `inner`";
      ];
    top "directional_light" ~keyword:"light" ~chosen_by:"direction"
      "a light infinitely far away"
      [
        f "direction" Direction "the direction the light travels";
        f "color" Colour ~default:(rgb Light.default_color) "its colour";
        f "intensity" Number ~range:non_negative ~default:(num Light.default_intensity)
          "its strength";
      ];
    top "animation" "the frames of an animation"
      [
        f "fps" Number
          ~range:(Real (Excl 0., Incl 1000.))
          ~default:(num fps) "frames per second";
        f "frames" Integer
          ~range:(Whole (1, 10_000_000))
          ~default:(whole frames) ~condition:(Without "duration") "how many frames";
        f "duration" Number ~range:positive ~default:(Absent "`frames` decides")
          ~condition:(Without "frames") "seconds, rounded to whole frames";
      ];
    top "physics" "how bodies move"
      [
        f "gravity" Vector ~default:(vec physics.gravity) "acceleration, m/s²";
        f "method"
          (Choice (List.map fst Description.physics_methods))
          ~default:
            (text
               (fst
                  (List.find
                     (fun (_, m) -> m = physics.method_)
                     Description.physics_methods)))
          "the integrator";
        f "step" Number ~range:length ~default:(num physics.step)
          "seconds per step of \"verlet\" and \"euler\"";
      ];
    top "material" "how a surface looks (a value: `material { … }`)"
      [
        f "color" Colour ~default:(rgb material.color) "the surface colour";
        f "texture" Texture ~default:(Absent "none")
          "a texture (checker(…), …) or a colour; overrides `color`";
        f "ambient" Number ~range:non_negative ~default:(num material.ambient)
          "weight of the ambient light";
        f "diffuse" Number ~range:non_negative ~default:(num material.diffuse)
          "diffuse weight";
        f "specular" Number ~range:non_negative ~default:(num material.specular)
          "Phong highlight weight";
        f "shininess" Number ~range:non_negative ~default:(num material.shininess)
          "Phong exponent";
        f "reflection" Number ~range:unit_interval ~default:(num material.reflection)
          "mirror weight; reflection + transparency at most 1";
        f "transparency" Number ~range:unit_interval ~default:(num material.transparency)
          "refraction weight";
        f "ior" Number ~range:positive ~default:(num material.ior) "index of refraction";
        f "fresnel" Boolean ~default:(flag material.fresnel)
          "Schlick's approximation of Fresnel moves transparency × F to reflection";
        f "metallic" Number ~range:unit_interval ~default:(num material.metallic)
          "tints the highlight and the reflection by the surface colour: 0 white, 1 the \
           colour";
        f "filter" Number ~range:unit_interval ~default:(num material.filter)
          "tints the light seen through the surface by its colour: 0 white, 1 the colour";
        f "bump" Bump ~default:(Absent "none") "perturbs the normal";
        f "base" Base_material ~default:(Absent "the default material")
          "a material to copy before the other fields apply";
      ];
  ]
  @ shape_blocks
  @ [ holder "group" "objects sharing a material and transforms" common ]
  @ csg_blocks
  @ [
      {
        id = "body";
        keyword = "body";
        chosen_by = None;
        holds_objects = true;
        doc = "a dynamic sphere: `body NAME { sphere { … } … }`";
        fields =
          [
            f "velocity" Vector ~default:(opt "(0, 0, 0)") "initial velocity, m/s";
            f "mass" Number ~range:positive ~default:(opt "1") "kg";
            f "restitution" Number ~range:unit_interval ~default:(opt "0.9")
              "share of the speed kept in a bounce";
          ];
      };
    ]

let find id = List.find_opt (fun b -> b.id = id) blocks
let for_keyword k = List.filter (fun b -> b.keyword = k) blocks

let names_of (b : block) =
  List.fold_left
    (fun acc (fl : field) -> if List.mem fl.name acc then acc else acc @ [ fl.name ])
    [] b.fields

let field_names id = match find id with Some b -> names_of b | None -> []
let shapes = List.map (fun b -> b.id) shape_blocks
let csg = List.map (fun b -> b.id) csg_blocks
let is_shape k = List.exists (String.equal k) shapes

let keywords =
  [ "settings"; "camera"; "animation"; "physics"; "light"; "group" ] @ csg @ shapes

let repeatable =
  List.sort_uniq compare
    (List.concat_map
       (fun b ->
         List.filter_map (fun fl -> if fl.repeats then Some fl.name else None) b.fields)
       blocks)

let fields_named (b : block) name = List.filter (fun fl -> fl.name = name) b.fields

let choose ~keyword present =
  match for_keyword keyword with
  | [ b ] -> Some b
  | bs -> (
      match
        List.filter
          (fun b -> match b.chosen_by with Some n -> present n | None -> false)
          bs
      with
      | [ b ] -> Some b
      | _ -> None)

let in_range r x =
  match r with
  | Any -> true
  | Real (a, b) -> (
      (match a with Incl a -> x >= a | Excl a -> x > a | Unbounded -> true)
      && match b with Incl b -> x <= b | Excl b -> x < b | Unbounded -> true)
  | Whole (a, b) -> Float.is_integer x && x >= Float.of_int a && x <= Float.of_int b

let num x =
  if Float.is_integer x && Float.abs x < 1e15 then Printf.sprintf "%.0f" x
  else
    let s = Printf.sprintf "%g" x in
    match String.index_opt s '+' with
    | Some i when i > 0 && s.[i - 1] = 'e' ->
        String.sub s 0 i ^ String.sub s (i + 1) (String.length s - i - 1)
    | _ -> s

let range_text = function
  | Any -> ""
  | Whole (a, b) -> Printf.sprintf "[%d, %d]" a b
  | Real (Incl a, Incl b) when a = -.b -> Printf.sprintf "within ±%s" (num b)
  | Real (a, b) ->
      let l = function
        | Incl a -> "[" ^ num a
        | Excl a -> "(" ^ num a
        | Unbounded -> "(-∞"
      in
      let r = function
        | Incl b -> num b ^ "]"
        | Excl b -> num b ^ ")"
        | Unbounded -> "∞)"
      in
      Printf.sprintf "%s, %s" (l a) (r b)

let quoted l =
  match List.rev_map (Printf.sprintf "\"%s\"") l with
  | [] -> ""
  | [ x ] -> x
  | last :: rest -> String.concat ", " (List.rev rest) ^ " or " ^ last

let type_text = function
  | Number -> "number"
  | Integer -> "whole number"
  | Boolean -> "true or false"
  | File -> "file name string"
  | Choice l -> quoted l
  | Vector -> "vector (x, y, z)"
  | Direction -> "non-zero vector"
  | Colour -> "colour (r, g, b), no negative component"
  | Material | Base_material -> "material"
  | Texture -> "texture, or a colour"
  | Bump -> "noise(scale, amount) or image(\"file.png\", amount)"
  | Scale -> "number or vector"
  | Background -> "colour, or gradient(HORIZON, ZENITH)"
  | Fog -> "fog(COLOR, DISTANCE)"
  | Gamma -> "\"srgb\", or a number"
  | Interval -> "pair (a, b) of numbers, a ≤ b,"

let value_text (fl : field) =
  let r = range_text fl.range in
  let t = type_text fl.ty in
  if r = "" then t
  else if String.starts_with ~prefix:"within" r then t ^ " " ^ r
  else t ^ " in " ^ r

let must (fl : field) =
  let noun = if fl.ty = Integer then "a whole number" else fl.noun in
  match fl.range with
  | Real (Excl a, Incl b) when b = big && noun = "" ->
      (* Every number is within ±1e150: a positive one is only said to be positive. *)
      "must be greater than " ^ num a
  | r ->
      let r = range_text r in
      String.concat " "
        (List.filter
           (fun w -> w <> "")
           [
             "must be";
             noun;
             (if String.starts_with ~prefix:"within" r then r else "in " ^ r);
             fl.unit;
           ])

let condition_text = function
  | Always -> ""
  | Kind_in ks -> "with `kind`: " ^ quoted ks
  | With n -> Printf.sprintf "with `%s`" n
  | Without n -> Printf.sprintf "without `%s`" n
