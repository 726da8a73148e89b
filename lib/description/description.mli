(** A scene as its program states it, at one instant: plain data between the language and
    the renderer.

    The evaluator produces it; the renderer compiles it (reading the images and meshes it
    names, building shapes, primitives and the acceleration structure); [lancer check]
    prints it. It holds no decoded image, no mesh triangles and no function: textures,
    bump maps, meshes and height fields are named by file, with the place that named them
    (where a problem reading the file is reported). Shapes are in object space, as
    written, each object with the transform that places it. *)

(** {1 Materials} *)

type image = {
  written : string;  (** the file name as the scene wrote it *)
  path : string;  (** resolved relative to the file that names it *)
  at : Loc.t;  (** the [image(…)] call, where a problem reading it is shown *)
}

type pattern =
  | Noise_pattern of float
  | Marble_pattern of float
  | Wood_pattern of float  (** each with its scale *)

(** A texture: an albedo as a function of the object-space point P (solid textures) or of
    the surface's (u, v) (images). Its images are ['image] and its colour maps ['map]:
    files and entry lists here ({!type-texture}), decoded images and arrays in the
    renderer, whose [Texture.t] is this type. Solid textures are evaluated at P − δ·N (N
    the geometric normal, δ the scale-aware ray offset) so that a surface lying exactly on
    a cell boundary does not flicker. All colours are linear RGB. *)
type ('image, 'map) texture_of =
  | Solid of Color.t
  | Checker of { c1 : Color.t; c2 : Color.t; size : float }
      (** k = ⌊x/s⌋ + ⌊y/s⌋ + ⌊z/s⌋; c1 where k is even, c2 where odd *)
  | Stripes of { c1 : Color.t; c2 : Color.t; size : float }  (** along x: ⌊x/s⌋ parity *)
  | Noise of { c1 : Color.t; c2 : Color.t; scale : float }
      (** mix c1 c2 by ½(1 + perlin(P/scale)), clamped to [0, 1] *)
  | Marble of { c1 : Color.t; c2 : Color.t; scale : float }
      (** veins along x: mix c1 c2 by ½(1 + sin(π·(x/scale + 4·turbulence(P/scale)))) *)
  | Wood of { c1 : Color.t; c2 : Color.t; scale : float }
      (** rings around the y axis, [scale] apart: the fraction of r/scale +
          0.35·perlin(x/2s, y/10s, z/2s) (s = scale, r = √(x² + z²)), mixed smoothly from
          c1 (ring start) to c2 *)
  | Gradient of { axis : Vec3.t; map : 'map }
      (** value fract(P·axis) = P·axis − ⌊P·axis⌋ (object space), coloured by the map *)
  | Mapped of { pattern : pattern; map : 'map }
      (** a noise, marble or wood pattern coloured by a map: the value that would mix c1
          and c2, clamped to [0, 1], looked up in the map *)
  | Image of { image : 'image; scale : float }
      (** an image on (u, v): u left to right, v bottom to top, [scale] copies across the
          unit square in each direction, bilinear filtering, wrapping at the edges *)

type color_map = (float * Color.t) list
(** Entries (t_k, c_k) with 0 ≤ t_0 ≤ t_1 ≤ … ≤ 1, at least one ({!color_map_problem}):
    the colour at v is c_0 below t_0, the last colour from the last t on, and in between
    linear between the bracketing entries. *)

type texture = (image, color_map) texture_of

(** A bump map: a perturbation of the shading normal. *)
type 'image bump_of =
  | Noise_bump of { scale : float; amount : float }
      (** gradient of 3-D Perlin noise at P/scale, times amount *)
  | Image_bump of { image : 'image; amount : float }
      (** a height map on (u, v): the luminance of the image, sampled bilinearly with
          wrapping; the normal tilts by amount × (height change per texel) along the
          surface directions in which u and v grow *)

type bump = image bump_of

type ('texture, 'bump) material_of = {
  color : Color.t;  (** linear albedo when there is no texture; default white *)
  texture : 'texture option;  (** albedo texture; overrides [color]; default none *)
  ambient : float;  (** default 0.1 *)
  diffuse : float;  (** default 0.9 *)
  specular : float;  (** Phong weight; default 0 *)
  shininess : float;  (** Phong exponent; default 50 *)
  reflection : float;  (** mirror weight r in [0, 1]; default 0 *)
  transparency : float;  (** refraction weight τ in [0, 1]; default 0 *)
  ior : float;  (** index of refraction; default 1 *)
  fresnel : bool;  (** Schlick's approximation moves τ·F to r; default false *)
  metallic : float;
      (** μ in [0, 1]: the highlight and the reflected light are multiplied by tint(μ) =
          (1 − μ)·white + μ·C, C the albedo; default 0 *)
  filter : float;
      (** φ in [0, 1]: the refracted light is multiplied by tint(φ); default 0 *)
  bump : 'bump option;  (** normal perturbation; default none *)
}
(** A surface material: the description's ([material]) and the renderer's ([Material.t],
    with decoded textures) are this one record. Invariants, checked by
    {!validate_material}: coefficients finite and non-negative, reflection + transparency
    ≤ 1, ior > 0, metallic and filter in [0, 1]. *)

type material = (texture, bump) material_of

val default_material : ('texture, 'bump) material_of
(** Every default above: white, ambient 0.1, diffuse 0.9, no specular (shininess 50),
    opaque, ior 1, untinted (metallic and filter 0), no texture or bump. The language's
    defaults and the renderer's are this value. *)

val shared_materials : int
(** 4096: the most materials a table of shared materials keeps (the language's records of
    a run, the renderer's materials of a compile), so that a scene whose every object has
    another material keeps no table of them beside its objects. *)

val material_hash : (float -> int) -> ('texture, 'bump) material_of -> int
(** [material_hash number m]: a hash of every field of [m] but its colour, each number
    hashed by [number], the texture and bump map by [Hashtbl.hash]. Tables of materials
    equal but for their colour hash their keys by it: with [number] a hash of the bits
    where numbers compare by their bits, [Hashtbl.hash] where they compare by [=] (−0 and
    0 alike). [Hashtbl.hash] of a whole material reads its first ten values only.

    The tables' equalities list the same fields (the language's [Value.same_but_color],
    the renderer's [Compile.same_record]), each written out: with the comparison of
    numbers as a function argument, a million spheres whose materials each compute a
    specular load in 16.1 G instructions instead of 15.0 G. A field added to
    {!material_of} is added to the three. *)

val validate_material : ('texture, 'bump) material_of -> (unit, string) result
(** The checks of a material's numbers (non-negative, finite, reflection + transparency ≤
    1, ior > 0, metallic and filter at most 1), with their messages. *)

val color_map_problem : (float * Color.t) list -> string option
(** Why these entries are not a colour map (none, a t outside [0, 1], decreasing, a colour
    that is negative or not finite); [None] when they are one. *)

(** {1 Shapes and objects} *)

val crease : float
(** 60: the angle in degrees between two faces above which the normals computed for a mesh
    without normals (or a smooth height field) do not smooth across their edge. *)

val max_objects : int
(** 10 000 000: the most objects a scene may build (a mesh's triangles and a height
    field's each count). *)

type csg_op = Union | Merge | Intersection | Difference

type step =
  | Translate of Vec3.t
  | Rotate of Vec3.t
  | Scale of Vec3.t
      (** A transform as written; an object's are applied in order, its groups' after. *)

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
      (** an OBJ file ([file] as written, [path] resolved); [at] is the [file] field's
          value, where a problem reading it is shown *)
  | Height_field of {
      file : string;
      path : string;
      origin : Vec3.t;
      size : Vec3.t;
      smooth : bool;
      at : Loc.t;
    }
      (** an image's luminance as heights over [size] from [origin]; [smooth]: vertex
          normals computed from the cells and interpolated, as a mesh's without normals
          are *)
  | Csg of { op : csg_op; block : string; members : obj list; solid : bool }
      (** members in order, each with its own transform and material; [block] as written
          ("group" for a group inside a CSG block); [solid] when the members must have an
          inside (every operation but a union at top level) *)

and obj = {
  kind : string;
      (** "sphere", "plane", …, "mesh", "height_field"; a CSG object's operation ("union"
          for a group inside a CSG block) *)
  shape : shape;
  transform : Transform.t;  (** object space → world space, groups' transforms included *)
  steps : step list;  (** the transforms applied, in order (groups' last) *)
  material : material option;
      (** [None]: the default material (or a CSG leaf's parent's). Its [color] is not
          read: [color] below is the object's, so that objects whose materials differ in
          their colour alone share one record (as a loop that colours each object makes
          them) *)
  color : Color.t;
      (** the colour of its material (white without one: a CSG member without a material
          takes its parent's material and colour). See {!object_material} *)
  loc : Loc.t;  (** where the object's block starts *)
  body : string option;  (** the body this sphere is, if any *)
}

val object_material : obj -> material option
(** [object_material o] is [o]'s material with its own colour ([o.material] where that has
    it already; a copy otherwise). *)

val is_solid : shape -> bool
(** Whether the shape has an inside: sphere, box, torus, capped cylinder and cone, a CSG
    whose members all have one, and the plane as a half-space; a mesh counts as one here
    (whether it is closed only its file tells, which the renderer reads). *)

(** {1 Physics} *)

type physics_method = Exact | Verlet | Euler

type physics = {
  gravity : Vec3.t;  (** m/s²; default (0, −9.81, 0) *)
  method_ : physics_method;  (** default [Exact] *)
  step : float;  (** seconds, for the fixed-step methods; default 1/240 *)
}

val default_animation : float * int
(** An animation's frames per second and frames when a scene gives neither: 24, 48. *)

val physics_methods : (string * physics_method) list
(** Each method by the name a scene gives it: ["exact"], ["verlet"], ["euler"]. *)

val default_physics : physics
(** Gravity (0, −9.81, 0), the exact method, step 1/240 s. *)

type body = {
  name : string;
  center : Vec3.t;  (** initial world-space centre (transforms applied) *)
  radius : float;  (** world-space radius (the sphere's radius times the largest scale) *)
  velocity : Vec3.t;  (** initial velocity, m/s; default 0 *)
  mass : float;  (** kg, > 0; default 1 *)
  restitution : float;  (** in [0, 1]; default 0.9; a pair uses the product *)
  loc : Loc.t;  (** where the body is defined *)
}

(** {1 The files a scene names} *)

(** A use of a file, as the evaluator meets it: what reading it can find wrong is shown at
    [at] (or for an open mesh where a solid is needed, at the member). *)
type file_use =
  | Picture of image  (** an image texture's or bump map's file *)
  | Model of {
      file : string;
      path : string;
      smooth : bool;
      at : Loc.t;
      solid_in : (string * Loc.t) option;
          (** for a member of a CSG block that needs a solid: the block as written and the
              member's own block, where an open mesh is reported *)
    }  (** a mesh's OBJ file *)
  | Heights of { file : string; path : string; at : Loc.t }  (** a height field's image *)

(** {1 A scene} *)

type t = {
  file : string;  (** the main file of the program *)
  time : float;  (** seconds *)
  frame : int;
  settings : Settings.t;
  camera : Camera.t;
  lights : Light.t list;
  objects : obj list;
      (** static objects in program order, then one sphere per body (at its position at
          [time]) *)
  animation : (float * int) option;  (** fps, frames *)
  physics : physics option;
  physics_loc : Loc.t option;  (** where the [physics] block is *)
  bodies : body list;  (** in program order, at their initial state *)
  warnings : Diagnostic.t list;
      (** what is legal but likely a mistake (a loop that runs zero times), in source
          order *)
  files : string list;
      (** the image and mesh files the objects name, resolved, sorted, each once *)
}

(** {1 What the instants of a program share}

    A program's top-level statements (its includes' statements each counted, in order) are
    known by their position: 0 for the first. A statement that cannot build anything else
    at another instant is static; the objects the static statements built are the
    program's {!static} part, made once, and a scene at any instant is that part joined
    with what the other statements build then ({!part}). *)

type static = (int * obj list) list
(** The objects each static statement built, by its position, in program order. *)

(** A piece of a scene's objects: a scene's objects are its parts' objects in order. *)
type part =
  | Static of int
      (** the objects of the static statement at this position, as {!static} has them *)
  | Built of obj list  (** objects this instant built, in program order *)

(** {1 What the renderer made of it}

    For [lancer check], which prints a description beside what rendering it involves. *)

type mesh_faces = {
  triangles : int;
  read : int;  (** how many of them have the file's normals *)
  computed : int;
      (** how many have normals computed from the faces; the others are flat *)
}

type rendered = {
  r_settings : Settings.t;  (** as rendered: command-line overrides applied *)
  r_lights : Light.t list;
  r_features : Features.t;
  r_kinds : (string * int) list;
      (** the objects by kind, in order of first appearance (a mesh's triangles each
          count) *)
  r_csg : string list;  (** each CSG object's tree on one line: difference(box, sphere) *)
  r_materials : int;  (** distinct materials *)
  r_meshes : ((string * bool) * mesh_faces) list;
      (** the triangles of each mesh file read (path, smooth) *)
  r_rasters : ((string * bool) * (int * int)) list;
      (** width and height of each height field's image (path, smooth) *)
}
