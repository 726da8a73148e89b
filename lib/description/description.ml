type image = { written : string; path : string; at : Loc.t }
type pattern = Noise_pattern of float | Marble_pattern of float | Wood_pattern of float

type ('image, 'map) texture_of =
  | Solid of Color.t
  | Checker of { c1 : Color.t; c2 : Color.t; size : float }
  | Stripes of { c1 : Color.t; c2 : Color.t; size : float }
  | Noise of { c1 : Color.t; c2 : Color.t; scale : float }
  | Marble of { c1 : Color.t; c2 : Color.t; scale : float }
  | Wood of { c1 : Color.t; c2 : Color.t; scale : float }
  | Gradient of { axis : Vec3.t; map : 'map }
  | Mapped of { pattern : pattern; map : 'map }
  | Image of { image : 'image; scale : float }

type color_map = (float * Color.t) list
type texture = (image, color_map) texture_of

type 'image bump_of =
  | Noise_bump of { scale : float; amount : float }
  | Image_bump of { image : 'image; amount : float }

type bump = image bump_of

type ('texture, 'bump) material_of = {
  color : Color.t;
  texture : 'texture option;
  ambient : float;
  diffuse : float;
  specular : float;
  shininess : float;
  reflection : float;
  transparency : float;
  ior : float;
  fresnel : bool;
  metallic : float;
  filter : float;
  bump : 'bump option;
}

type material = (texture, bump) material_of

let default_material =
  {
    color = Color.white;
    texture = None;
    ambient = 0.1;
    diffuse = 0.9;
    specular = 0.;
    shininess = 50.;
    reflection = 0.;
    transparency = 0.;
    ior = 1.;
    fresnel = false;
    metallic = 0.;
    filter = 0.;
    bump = None;
  }

let shared_materials = 4096

let material_hash number (m : (_, _) material_of) =
  let mix h x = h * 1_000_003 lxor number x in
  let h = Hashtbl.hash m.texture lxor (31 * Hashtbl.hash m.bump) in
  let h = if m.fresnel then h lxor 0x5bd1e995 else h in
  let h = mix (mix (mix (mix h m.ambient) m.diffuse) m.specular) m.shininess in
  let h = mix (mix (mix h m.reflection) m.transparency) m.ior in
  mix (mix h m.metallic) m.filter land max_int

let validate_material m =
  (* The weights in [0, 1], after the other coefficients, which are only non-negative. *)
  let weights =
    [
      ("reflection", m.reflection);
      ("transparency", m.transparency);
      ("metallic", m.metallic);
      ("filter", m.filter);
    ]
  in
  let coefficients =
    [
      ("ambient", m.ambient);
      ("diffuse", m.diffuse);
      ("specular", m.specular);
      ("shininess", m.shininess);
    ]
    @ weights
  in
  let negative (name, v) =
    if Float.is_finite v && v >= 0. then None
    else Some (Printf.sprintf "%s must be a finite number >= 0 (got %g)" name v)
  and above_one (name, v) = if v > 1. then Some (name ^ " must be at most 1") else None in
  match List.find_map negative coefficients with
  | Some e -> Error e
  | None -> (
      match List.find_map above_one weights with
      | Some e -> Error e
      | None ->
          if m.reflection +. m.transparency > 1. then
            Error
              (Printf.sprintf "reflection + transparency must be at most 1 (got %g + %g)"
                 m.reflection m.transparency)
          else if not (Float.is_finite m.ior && m.ior > 0.) then
            Error (Printf.sprintf "ior must be > 0 (got %g)" m.ior)
          else Ok ())

let color_map_problem entries =
  let ok_color (c : Color.t) = Color.is_finite c && c.r >= 0. && c.g >= 0. && c.b >= 0. in
  if entries = [] then Some "a color_map needs at least one entry (t, colour)"
  else
    let rec check prev k = function
      | [] -> None
      | (t, c) :: rest ->
          if not (t >= 0. && t <= 1.) then
            Some
              (Printf.sprintf "entry %d of the color_map has t = %g; t must be in [0, 1]"
                 k t)
          else if t < prev then
            Some
              (Printf.sprintf
                 "entry %d of the color_map has t = %g, below the t = %g before it: \
                  entries go in increasing t"
                 k t prev)
          else if not (ok_color c) then
            Some
              (Printf.sprintf
                 "entry %d of the color_map has a colour with a negative or non-finite \
                  component"
                 k)
          else check t (k + 1) rest
    in
    check 0. 1 entries

let max_objects = 10_000_000
let crease = 60.

type csg_op = Union | Merge | Intersection | Difference
type step = Translate of Vec3.t | Rotate of Vec3.t | Scale of Vec3.t

type shape =
  | Sphere of { center : Vec3.t; radius : float }
  | Plane of { normal : Vec3.t; offset : float }
  | Parallelogram of { origin : Vec3.t; edge1 : Vec3.t; edge2 : Vec3.t }
  | Triangle of { a : Vec3.t; b : Vec3.t; c : Vec3.t }
  | Paraboloid of { vertex : Vec3.t; axis : Vec3.t; radius : float; height : float }
  | Box of { min : Vec3.t; max : Vec3.t }
  | Cylinder of { base : Vec3.t; top : Vec3.t; radius : float; caps : bool }
  | Disk of { center : Vec3.t; normal : Vec3.t; radius : float }
  | Cone of {
      base : Vec3.t;
      base_radius : float;
      top : Vec3.t;
      top_radius : float;
      caps : bool;
    }
  | Torus of { center : Vec3.t; major : float; minor : float; axis : Vec3.t }
  | Mesh of { file : string; path : string; smooth : bool; at : Loc.t }
  | Height_field of {
      file : string;
      path : string;
      origin : Vec3.t;
      size : Vec3.t;
      smooth : bool;
      at : Loc.t;
    }
  | Csg of { op : csg_op; block : string; members : obj list; solid : bool }

and obj = {
  kind : string;
  shape : shape;
  transform : Transform.t;
  steps : step list;
  material : material option;
  color : Color.t;
  loc : Loc.t;
  body : string option;
}

let object_material o =
  match o.material with
  | Some m when m.color != o.color && m.color <> o.color ->
      Some { m with color = o.color }
  | m -> m

let rec is_solid = function
  | Sphere _ | Plane _ | Box _ | Torus _ | Mesh _ -> true
  | Cone { caps; _ } | Cylinder { caps; _ } -> caps
  | Csg { members; _ } -> List.for_all (fun o -> is_solid o.shape) members
  | Parallelogram _ | Triangle _ | Paraboloid _ | Disk _ | Height_field _ -> false

type physics_method = Exact | Verlet | Euler
type physics = { gravity : Vec3.t; method_ : physics_method; step : float }

let default_animation = (24., 48)
let physics_methods = [ ("exact", Exact); ("verlet", Verlet); ("euler", Euler) ]

let default_physics =
  { gravity = Vec3.v 0. (-9.81) 0.; method_ = Exact; step = 1. /. 240. }

type body = {
  name : string;
  center : Vec3.t;
  radius : float;
  velocity : Vec3.t;
  mass : float;
  restitution : float;
  loc : Loc.t;
}

type file_use =
  | Picture of image
  | Model of {
      file : string;
      path : string;
      smooth : bool;
      at : Loc.t;
      solid_in : (string * Loc.t) option;
    }
  | Heights of { file : string; path : string; at : Loc.t }

type t = {
  file : string;
  time : float;
  frame : int;
  settings : Settings.t;
  camera : Camera.t;
  lights : Light.t list;
  objects : obj list;
  animation : (float * int) option;
  physics : physics option;
  physics_loc : Loc.t option;
  bodies : body list;
  warnings : Diagnostic.t list;
  files : string list;
}

type static = (int * obj list) list
type part = Static of int | Built of obj list
type mesh_faces = { triangles : int; read : int; computed : int }

type rendered = {
  r_settings : Settings.t;
  r_lights : Light.t list;
  r_features : Features.t;
  r_kinds : (string * int) list;
  r_csg : string list;
  r_materials : int;
  r_meshes : ((string * bool) * mesh_faces) list;
  r_rasters : ((string * bool) * (int * int)) list;
}
