module D = Description

let count_by key xs =
  let tbl = Hashtbl.create 8 and order = ref [] in
  List.iter
    (fun x ->
      let k = key x in
      match Hashtbl.find_opt tbl k with
      | Some n -> Hashtbl.replace tbl k (n + 1)
      | None ->
          Hashtbl.add tbl k 1;
          order := k :: !order)
    xs;
  List.rev_map (fun k -> (k, Hashtbl.find tbl k)) !order

let light_kind = function
  | Light.Point { spot = Some _; _ } as l when Light.is_area l -> "soft spot"
  | Light.Point { spot = Some _; _ } -> "spot"
  | Light.Point _ as l when Light.is_area l -> "area"
  | Light.Point p when p.radius > 0. -> "point (radius without samples: hard shadows)"
  | Light.Point _ -> "point"
  | Light.Directional _ -> "directional"

let warnings ~empty ~objects ~lights (d : D.t) =
  let file msg = Diagnostic.file_error ~kind:Diagnostic.Warning d.file msg in
  let scene =
    if empty then
      [ file "the scene is empty (no statements): it renders the background only" ]
    else
      (if objects = 0 then
         [ file "the scene has no objects: the image is the background only" ]
       else [])
      @
      if lights = 0 && objects > 0 then
        [
          file
            "the scene has no lights: objects show only their ambient colour (add light \
             { position: (x, y, z) })";
        ]
      else []
  in
  d.warnings @ scene

(* ---- Colours given as 0–255 ---- *)

let largest (c : Color.t) = Float.max c.r (Float.max c.g c.b)

(* The colours a material gives a surface: its texture's, or its own without one. *)
let surface_colours (m : D.material) =
  let map entries = List.map snd entries in
  match m.texture with
  | None -> [ m.color ]
  | Some (Solid c) -> [ c ]
  | Some
      ( Checker { c1; c2; _ }
      | Stripes { c1; c2; _ }
      | Noise { c1; c2; _ }
      | Marble { c1; c2; _ }
      | Wood { c1; c2; _ } ) ->
      [ c1; c2 ]
  | Some (Gradient { map = m; _ } | Mapped { map = m; _ }) -> map m
  | Some (Image _) -> []

let light_strength = function
  | Light.Point p -> p.intensity *. largest p.color
  | Light.Directional l -> l.intensity *. largest l.color

let colour_text (c : Color.t) = Printf.sprintf "(%g, %g, %g)" c.r c.g c.b

(* The colours above 1 of the objects noted so far: by colour, the first object's place
   and how many have it, in order of first appearance (newest first). *)
type colours = {
  seen : (float * float * float, Loc.t * int) Hashtbl.t;
  mutable order : ((float * float * float) * Color.t) list;
}

let colours () = { seen = Hashtbl.create 8; order = [] }

(* [largest c > 1.] without its calls, asked of every object: [Float.max] is NaN where
   any component is. *)
let above_one (c : Color.t) =
  (c.r > 1. || c.g > 1. || c.b > 1.)
  && not (Float.is_nan c.r || Float.is_nan c.g || Float.is_nan c.b)

let note_colour acc (o : D.obj) (c : Color.t) =
  if above_one c then
    let key = (c.r, c.g, c.b) in
    match Hashtbl.find_opt acc.seen key with
    | Some (loc, n) -> Hashtbl.replace acc.seen key (loc, n + 1)
    | None ->
        Hashtbl.add acc.seen key (o.loc, 1);
        acc.order <- (key, c) :: acc.order

(* The colours of [D.object_material o], read where they are: the object's own colour
   beside its material stands for the material's when it has no texture, so that no
   material is copied for each object of a loop that colours them. *)
let rec note_object acc (o : D.obj) =
  (match o.material with
  | None -> ()
  | Some { texture = None; _ } -> note_colour acc o o.color
  | Some m -> List.iter (note_colour acc o) (surface_colours m));
  match o.shape with Csg { members; _ } -> List.iter (note_object acc) members | _ -> ()

let colour_warnings_of ?(source = fun _ -> None) acc lights =
  let strengths = List.map light_strength lights in
  (* A light of strength s (intensity × its colour's largest component) makes up for a
     colour whose largest component is m > 1 when s·m ≤ 1. *)
  let made_up c =
    let m = largest c in
    List.exists (fun s -> s *. m <= 1.) strengths
  in
  (* [order] is newest first: folded from the left, the warnings come oldest first. *)
  List.fold_left
    (fun ws (key, c) ->
      if made_up c then ws
      else
        let (loc : Loc.t), n = Hashtbl.find acc.seen key in
        let c255 = Color.scale (1. /. 255.) c in
        Diagnostic.warning ?source:(source loc.file) loc
          (Printf.sprintf
             "colour %s has a component above 1 and no light is dim enough to make up \
              for it: this object reflects more light than it receives and shows flat \
              and saturated; colours go from 0 to 1 (for 0–255 values, divide by 255: \
              (%.3g, %.3g, %.3g))%s"
             (colour_text c) c255.r c255.g c255.b
             (match n - 1 with
             | 0 -> ""
             | 1 -> "; 1 more object has this colour"
             | k -> Printf.sprintf "; %d more objects have this colour" k))
        :: ws)
    [] acc.order

let colour_warnings ?source (d : D.t) =
  let acc = colours () in
  List.iter (note_object acc) d.objects;
  colour_warnings_of ?source acc d.lights

(* Which normals a mesh's triangles are shaded with, in words and as a JSON name. *)
let mesh_normals ~smooth (f : D.mesh_faces) =
  if (not smooth) || f.read + f.computed = 0 then ("flat", "flat (smooth: false)")
  else if f.computed = 0 then ("file", "normals from the file")
  else if f.read = 0 then
    ( "computed",
      Printf.sprintf "normals computed from the faces (split at edges sharper than %g°)"
        D.crease )
  else
    ( "file and computed",
      Printf.sprintf "normals from the file for %d, computed from the faces for %d" f.read
        f.computed )

let height_normals ~smooth =
  if smooth then
    ( "computed",
      Printf.sprintf "normals computed from the cells (split at edges sharper than %g°)"
        D.crease )
  else ("flat", "flat (smooth: false)")

(* The meshes and height fields the scene is made of, each file with each [smooth] once,
   by path: "mesh: PATH, N triangles, NORMALS". *)
let model_lines (r : D.rendered) =
  List.map
    (fun ((path, smooth), (f : D.mesh_faces)) ->
      Printf.sprintf "mesh: %s, %d triangle%s, %s" path f.triangles
        (if f.triangles = 1 then "" else "s")
        (snd (mesh_normals ~smooth f)))
    (List.sort compare r.r_meshes)
  @ List.map
      (fun ((path, smooth), (w, h)) ->
        Printf.sprintf "height field: %s, %d×%d pixels, %s" path w h
          (snd (height_normals ~smooth)))
      (List.sort compare r.r_rasters)

let summary ~empty (d : D.t) (r : D.rendered) =
  let s = r.r_settings in
  let kinds = r.r_kinds in
  let lights = count_by light_kind r.r_lights in
  let list l =
    String.concat ", " (List.map (fun (k, n) -> Printf.sprintf "%s %d" k n) l)
  in
  let b = Buffer.create 256 in
  let line fmt =
    Printf.ksprintf
      (fun x ->
        Buffer.add_string b x;
        Buffer.add_char b '\n')
      fmt
  in
  line "scene: %s" d.file;
  let adaptive =
    if s.adaptive > 0. then
      Printf.sprintf "adaptive %g: 2×2 samples, %d×%d where they differ by more"
        s.adaptive (max s.samples 4) (max s.samples 4)
    else "adaptive off"
  in
  line "image: %d×%d, %d×%d samples per pixel (jitter %s, %s), depth %d" s.width s.height
    s.samples s.samples
    (if s.jitter then "on" else "off")
    adaptive s.depth;
  (let c = d.camera in
   line "camera: %s%s%s%s" (Camera.kind_name c.kind)
     (match c.kind with
     | Camera.Orthographic { width } -> Printf.sprintf ", %g wide" width
     | Perspective | Fisheye -> Printf.sprintf ", fov %g°" c.fov)
     (if Camera.depth_of_field c then
        Printf.sprintf ", depth of field (aperture %g, focused at %g, %d×%d lens samples)"
          c.aperture c.focal_distance c.lens_samples c.lens_samples
      else "")
     (if Camera.motion_blur c then
        let o, cl = c.shutter in
        Printf.sprintf ", motion blur (shutter %g to %g frames, %d instants)" o cl
          c.shutter_samples
      else ""));
  (match d.animation with
  | Some (fps, n) ->
      line "animation: %d frames at %g fps (%g s); this is frame %d, time %g s" n fps
        (Float.of_int n /. fps)
        d.frame d.time
  | None -> line "animation: none (a still)");
  line "objects: %d%s"
    (List.fold_left (fun n (_, k) -> n + k) 0 kinds)
    (if kinds = [] then "" else " (" ^ list kinds ^ ")");
  (let trees = r.r_csg in
   let shown = 4 in
   match trees with
   | [] -> ()
   | ts ->
       line "csg: %d object%s: %s%s" (List.length ts)
         (if List.length ts = 1 then "" else "s")
         (String.concat "; " (List.filteri (fun i _ -> i < shown) ts))
         (if List.length ts > shown then
            Printf.sprintf "; … and %d more" (List.length ts - shown)
          else ""));
  (let shown = 4 in
   let models = model_lines r in
   List.iteri (fun i l -> if i < shown then line "%s" l) models;
   if List.length models > shown then
     line "… and %d more meshes and height fields" (List.length models - shown));
  line "lights: %d%s" (List.length r.r_lights)
    (if lights = [] then "" else " (" ^ list lights ^ ")");
  line "materials: %d distinct" r.r_materials;
  (match d.bodies with
  | [] -> ()
  | bs ->
      line "bodies: %d (%s)" (List.length bs)
        (String.concat ", " (List.map (fun (b : D.body) -> b.name) bs)));
  let feats = Features.to_list r.r_features @ [ ("bodies", d.bodies <> []) ] in
  let pick b =
    List.filter_map
      (fun (k, v) ->
        if v = b then Some (String.map (fun c -> if c = '_' then ' ' else c) k) else None)
      feats
  in
  let used = pick true and skipped = pick false in
  line "renderer uses: %s"
    (if used = [] then "nothing beyond direct light" else String.concat ", " used);
  line "renderer skips: %s"
    (if skipped = [] then "nothing" else String.concat ", " skipped);
  List.iter
    (fun w -> Buffer.add_string b (Diagnostic.to_string w))
    (warnings ~empty
       ~objects:(List.fold_left (fun n (_, k) -> n + k) 0 kinds)
       ~lights:(List.length r.r_lights) d);
  Buffer.contents b

let vj (v : Vec3.t) = `List [ `Float v.x; `Float v.y; `Float v.z ]
let cj (c : Color.t) = `List [ `Float c.r; `Float c.g; `Float c.b ]

let light_json = function
  | Light.Point p ->
      `Assoc
        ([
           ("kind", `String (if Option.is_some p.spot then "spot" else "point"));
           ("position", vj p.position);
           ("color", cj p.color);
           ("intensity", `Float p.intensity);
           ("attenuation", vj p.attenuation);
           ("radius", `Float p.radius);
           ("samples", `Int p.samples);
         ]
        @
        match p.spot with
        | None -> []
        | Some sp ->
            [
              ("point_at", vj sp.point_at);
              ("inner", `Float sp.inner);
              ("outer", `Float sp.outer);
            ])
  | Light.Directional d ->
      `Assoc
        [
          ("kind", `String "directional");
          ("direction", vj d.direction);
          ("color", cj d.color);
          ("intensity", `Float d.intensity);
        ]

let fl x = `Float x
let map_json map = `List (List.map (fun (x, c) -> `List [ `Float x; cj c ]) map)

let texture_json : D.texture -> Yojson.Safe.t = function
  | Solid c -> `Assoc [ ("kind", `String "solid"); ("color", cj c) ]
  | Checker { c1; c2; size } ->
      `Assoc
        [ ("kind", `String "checker"); ("c1", cj c1); ("c2", cj c2); ("size", fl size) ]
  | Stripes { c1; c2; size } ->
      `Assoc
        [ ("kind", `String "stripes"); ("c1", cj c1); ("c2", cj c2); ("size", fl size) ]
  | Noise { c1; c2; scale } ->
      `Assoc
        [ ("kind", `String "noise"); ("c1", cj c1); ("c2", cj c2); ("scale", fl scale) ]
  | Marble { c1; c2; scale } ->
      `Assoc
        [ ("kind", `String "marble"); ("c1", cj c1); ("c2", cj c2); ("scale", fl scale) ]
  | Wood { c1; c2; scale } ->
      `Assoc
        [ ("kind", `String "wood"); ("c1", cj c1); ("c2", cj c2); ("scale", fl scale) ]
  | Mapped { pattern; map } ->
      let kind, scale =
        match pattern with
        | Noise_pattern s -> ("noise", s)
        | Marble_pattern s -> ("marble", s)
        | Wood_pattern s -> ("wood", s)
      in
      `Assoc [ ("kind", `String kind); ("map", map_json map); ("scale", fl scale) ]
  | Gradient { axis; map } ->
      `Assoc [ ("kind", `String "gradient"); ("axis", vj axis); ("map", map_json map) ]
  | Image { image; scale } ->
      `Assoc
        [
          ("kind", `String "image"); ("file", `String image.written); ("scale", fl scale);
        ]

let bump_json : D.bump -> Yojson.Safe.t = function
  | Noise_bump { scale; amount } ->
      `Assoc [ ("kind", `String "noise"); ("scale", fl scale); ("amount", fl amount) ]
  | Image_bump { image; amount } ->
      `Assoc
        [
          ("kind", `String "image"); ("file", `String image.written); ("amount", fl amount);
        ]

let material_json (m : D.material) =
  `Assoc
    ([
       ("color", cj m.color);
       ("ambient", `Float m.ambient);
       ("diffuse", `Float m.diffuse);
       ("specular", `Float m.specular);
       ("shininess", `Float m.shininess);
       ("reflection", `Float m.reflection);
       ("transparency", `Float m.transparency);
       ("ior", `Float m.ior);
       ("fresnel", `Bool m.fresnel);
       ("metallic", `Float m.metallic);
       ("filter", `Float m.filter);
     ]
    @ (match m.texture with Some x -> [ ("texture", texture_json x) ] | None -> [])
    @ match m.bump with Some x -> [ ("bump", bump_json x) ] | None -> [])

let step_json : D.step -> Yojson.Safe.t = function
  | Translate v -> `Assoc [ ("translate", vj v) ]
  | Rotate v -> `Assoc [ ("rotate", vj v) ]
  | Scale v -> `Assoc [ ("scale", vj v) ]

(* An object's fields in object space, as written (and what its file held). *)
let rec fields_json (r : D.rendered) (s : D.shape) : (string * Yojson.Safe.t) list =
  match s with
  | Sphere { center; radius } -> [ ("center", vj center); ("radius", fl radius) ]
  | Plane { normal; offset } -> [ ("normal", vj normal); ("offset", fl offset) ]
  | Parallelogram { origin; edge1; edge2 } ->
      [ ("origin", vj origin); ("edge1", vj edge1); ("edge2", vj edge2) ]
  | Triangle { a; b; c } -> [ ("a", vj a); ("b", vj b); ("c", vj c) ]
  | Paraboloid { vertex; axis; radius; height } ->
      [
        ("vertex", vj vertex);
        ("axis", vj axis);
        ("radius", fl radius);
        ("height", fl height);
      ]
  | Box { min; max } -> [ ("min", vj min); ("max", vj max) ]
  | Cylinder { base; top; radius; caps } ->
      [ ("base", vj base); ("top", vj top); ("radius", fl radius); ("caps", `Bool caps) ]
  | Cone { base; base_radius; top; top_radius; caps } ->
      [
        ("base", vj base);
        ("base_radius", fl base_radius);
        ("top", vj top);
        ("top_radius", fl top_radius);
        ("caps", `Bool caps);
      ]
  | Torus { center; major; minor; axis } ->
      [
        ("center", vj center); ("major", fl major); ("minor", fl minor); ("axis", vj axis);
      ]
  | Disk { center; normal; radius } ->
      [ ("center", vj center); ("normal", vj normal); ("radius", fl radius) ]
  | Mesh { file; path; smooth; _ } -> (
      [ ("file", `String file); ("smooth", `Bool smooth) ]
      @
      match List.assoc_opt (path, smooth) r.r_meshes with
      | Some f ->
          [
            ("triangles", `Int f.triangles);
            ("normals", `String (fst (mesh_normals ~smooth f)));
          ]
      | None -> [])
  | Height_field { file; path; origin; size; smooth; _ } -> (
      [
        ("file", `String file);
        ("origin", vj origin);
        ("size", vj size);
        ("smooth", `Bool smooth);
        ("normals", `String (fst (height_normals ~smooth)));
      ]
      @
      match List.assoc_opt (path, smooth) r.r_rasters with
      | Some (w, h) ->
          [
            ("width", `Int w);
            ("height", `Int h);
            ("triangles", `Int (2 * (w - 1) * (h - 1)));
          ]
      | None -> [])
  | Csg { members; _ } ->
      let member (o : D.obj) =
        `Assoc
          ([
             ("kind", `String o.kind);
             ("fields", `Assoc (fields_json r o.shape));
             ("transforms", `List (List.map step_json o.steps));
           ]
          @
          match D.object_material o with
          | Some m -> [ ("material", material_json m) ]
          | None -> [])
      in
      [ ("members", `List (List.map member members)) ]

let json ?state (d : D.t) (r : D.rendered) =
  let s = r.r_settings and c = d.camera in
  let now (b : D.body) =
    match Option.bind state (fun f -> f b.name d.time) with
    | Some (p, v) -> [ ("position", vj p); ("velocity_now", vj v) ]
    | None -> [ ("position", vj b.center); ("velocity_now", vj b.velocity) ]
  in
  let objects =
    List.map
      (fun (o : D.obj) ->
        `Assoc
          ([ ("kind", `String o.kind) ]
          @ fields_json r o.shape
          @ [
              ("transforms", `List (List.map step_json o.steps));
              ( "material",
                material_json
                  (Option.value (D.object_material o) ~default:D.default_material) );
            ]
          @ match o.body with Some n -> [ ("body", `String n) ] | None -> []))
      d.objects
  in
  let method_name : D.physics_method -> string = function
    | Exact -> "exact"
    | Verlet -> "verlet"
    | Euler -> "euler"
  in
  `Assoc
    [
      ("file", `String d.file);
      ("time", `Float d.time);
      ("frame", `Int d.frame);
      ( "settings",
        `Assoc
          [
            ("width", `Int s.width);
            ("height", `Int s.height);
            ("depth", `Int s.depth);
            ("samples", `Int s.samples);
            ("jitter", `Bool s.jitter);
            ("adaptive", `Float s.adaptive);
            ("shadows", `Bool s.shadows);
            ( "background",
              match s.sky with
              | None -> cj s.background
              | Some sk ->
                  `Assoc
                    [
                      ("kind", `String "gradient");
                      ("horizon", cj sk.horizon);
                      ("zenith", cj sk.zenith);
                    ] );
            ( "fog",
              match s.fog with
              | None -> `Null
              | Some f ->
                  `Assoc [ ("color", cj f.color); ("distance", `Float f.distance) ] );
            ("ambient", cj s.ambient);
            ( "gamma",
              match s.gamma with
              | Settings.Srgb -> `String "srgb"
              | Settings.Power g -> `Float g );
          ] );
      ( "camera",
        `Assoc
          ([
             ("kind", `String (Camera.kind_name c.kind));
             ("position", vj c.position);
             ("look_at", vj c.look_at);
             ("up", vj c.up);
           ]
          @ (match c.kind with
            | Camera.Orthographic { width } -> [ ("width", `Float width) ]
            | Perspective | Fisheye -> [ ("fov", `Float c.fov) ])
          @ [
              ("aperture", `Float c.aperture);
              ("focal_distance", `Float c.focal_distance);
              ("lens_samples", `Int c.lens_samples);
            ]
          @
          if Camera.motion_blur c then
            [
              ("shutter", `List [ `Float (fst c.shutter); `Float (snd c.shutter) ]);
              ("shutter_samples", `Int c.shutter_samples);
            ]
          else []) );
      ( "animation",
        match d.animation with
        | Some (fps, n) -> `Assoc [ ("fps", `Float fps); ("frames", `Int n) ]
        | None -> `Null );
      ("lights", `List (List.map light_json r.r_lights));
      ("objects", `List objects);
      ( "bodies",
        `List
          (List.map
             (fun (b : D.body) ->
               `Assoc
                 ([
                    ("name", `String b.name);
                    ("center", vj b.center);
                    ("radius", `Float b.radius);
                    ("velocity", vj b.velocity);
                    ("mass", `Float b.mass);
                    ("restitution", `Float b.restitution);
                  ]
                 @ now b))
             d.bodies) );
      ( "physics",
        match d.physics with
        | Some p ->
            `Assoc
              [
                ("gravity", vj p.gravity);
                ("method", `String (method_name p.method_));
                ("step", `Float p.step);
              ]
        | None -> `Null );
      ( "features",
        `Assoc (List.map (fun (k, v) -> (k, `Bool v)) (Features.to_list r.r_features)) );
    ]
