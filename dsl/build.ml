module D = Description
open Value
open Fields

(* ------------------------------------------------------------------------------------ *)
(* Materials *)

(* [material { }]: every field at its default. *)
let default_material site =
  let d name = site.entries.(slot site name).default in
  let wrong n = invalid_arg ("Build: the schema's material " ^ n) in
  let num n = match d n with VNum x -> x | _ -> wrong n in
  ({
     color = (match d "color" with VVec v -> Color.of_vec3 v | _ -> wrong "color");
     texture = None;
     ambient = num "ambient";
     diffuse = num "diffuse";
     specular = num "specular";
     shininess = num "shininess";
     reflection = num "reflection";
     transparency = num "transparency";
     ior = num "ior";
     fresnel = (match d "fresnel" with VBool x -> x | _ -> wrong "fresnel");
     metallic = num "metallic";
     filter = num "filter";
     bump = None;
   }
    : D.material)

let material site =
  let base = slot site "base" and color_ = slot site "color" in
  let ambient = slot site "ambient" and diffuse = slot site "diffuse" in
  let specular = slot site "specular" and shininess = slot site "shininess" in
  let reflection = slot site "reflection" and transparency = slot site "transparency" in
  let ior = slot site "ior" and fresnel = slot site "fresnel" in
  let metallic = slot site "metallic" and filter = slot site "filter" in
  let texture = slot site "texture" and bump = slot site "bump" in
  let default = default_material site in
  let default_some = Some default in
  (* Whether the block writes no field but its base and its colour, whatever fields the
     schema gives: known from the block as written, once. *)
  let colour_only =
    let only = ref true in
    Array.iteri
      (fun i written -> if written && i <> base && i <> color_ then only := false)
      site.given;
    !only
  in
  fun b ->
    (* A field left out keeps the base's value; without a base, the schema's default. *)
    let d, d_some =
      if not (live b base) then (default, default_some)
      else
        match value b base with
        | VMat m -> (full_material ~some:m.some ~color:m.color, m.some)
        | v ->
            bad b b.site.vlocs.(base) (Msg.field_type b.site.entries.(base).sch (ty v));
            (default, default_some)
    in
    if colour_only then
      (* Its colour alone written (a material made in a loop, a colour each): the base's
         option and that colour, no record made; an object of it holds them both. *)
      Value.colored d_some (color_or b color_ d.color)
    else
      let m : D.material =
        {
          color = color_or b color_ d.color;
          texture = d.texture;
          ambient = number_or b ambient d.ambient;
          diffuse = number_or b diffuse d.diffuse;
          specular = number_or b specular d.specular;
          shininess = number_or b shininess d.shininess;
          reflection = number_or b reflection d.reflection;
          transparency = number_or b transparency d.transparency;
          ior = number_or b ior d.ior;
          fresnel =
            (if given b fresnel then boolean b fresnel ~default:d.fresnel else d.fresnel);
          metallic = number_or b metallic d.metallic;
          filter = number_or b filter d.filter;
          bump = d.bump;
        }
      in
      (* A texture-like value read as [f] reads it (a texture, a bump map); [other]
         reads any other value, or refuses it. *)
      let read i f other =
        if not (live b i) then None
        else
          match value b i with
          | VTex t -> (
              match f ~use:b.out.use t with
              | Ok x -> Some x
              | Error msg ->
                  bad b (Textures.at t b.site.vlocs.(i)) msg;
                  None)
          | v -> (
              match other v with
              | Some x -> Some x
              | None ->
                  bad b b.site.vlocs.(i) (Msg.field_type b.site.entries.(i).sch (ty v));
                  None)
      in
      let solid = function VVec v -> Some (D.Solid (Color.of_vec3 v)) | _ -> None in
      let m =
        match read texture Textures.texture solid with
        | Some tex -> { m with texture = Some tex }
        | None -> m
      in
      let m =
        match read bump Textures.bump (fun _ -> None) with
        | Some bm -> { m with bump = Some bm }
        | None -> m
      in
      if
        (given b reflection || given b transparency)
        && m.reflection +. m.transparency > 1.
        && not b.failed
      then
        bad b
          b.site.vlocs.(if given b transparency then transparency else reflection)
          (Msg.reflection_transparency m.reflection m.transparency);
      (* What the description requires of a material ({!D.validate_material}) holds: each
       number is in its field's range, or the base's or the schema's (the tests check
       that these ranges are within the description's), and the sum is checked above. *)
      (* A record equal to the base's, or to one the run has made, but for its colour is
         that one's option, its colour beside it ({!Value.sink}). *)
      Value.material ~some:(if same_but_color m d then d_some else b.out.share m) m

(* ------------------------------------------------------------------------------------ *)
(* Settings, camera, lights, animation, physics *)

let settings b =
  let s name = slot b.site name in
  let gamma =
    let i = s "gamma" in
    let e = b.site.entries.(i) in
    let gamma = function
      | VStr x when String.lowercase_ascii x = "srgb" -> Some Settings.Srgb
      | VNum g when Schema.in_range e.sch.range g -> Some (Settings.Power g)
      | _ -> None
    in
    let default = Option.get (gamma e.default) in
    if not (live b i) then default
    else
      match gamma (value b i) with
      | Some g -> g
      | None ->
          bad b b.site.vlocs.(i) (Msg.gamma e.sch.range);
          default
  in
  let background = s "background" and fog = s "fog" in
  let st : Settings.t =
    {
      width = integer b (s "width");
      height = integer b (s "height");
      depth = integer b (s "depth");
      samples = integer b (s "samples");
      jitter = boolean b (s "jitter");
      adaptive = number b (s "adaptive");
      shadows = boolean b (s "shadows");
      background =
        (match (live b background, value b background) with
        | true, VTex _ ->
            (* a gradient's horizon, once the sky below has read it *)
            Color.of_vec3 (Option.get (as_vector b.site.entries.(background).default))
        | _ -> color b background);
      sky = None;
      fog = None;
      ambient = color b (s "ambient");
      gamma;
    }
  in
  (* A gradient background and fog. *)
  let colour_arg = function
    | VVec c when c.x >= 0. && c.y >= 0. && c.z >= 0. -> Some (Color.of_vec3 c)
    | _ -> None
  in
  let st =
    match (live b background, value b background) with
    | true, VTex { tname = "gradient"; targs = [ h; z ]; _ } -> (
        match (colour_arg h, colour_arg z) with
        | Some horizon, Some zenith ->
            { st with background = horizon; sky = Some { horizon; zenith } }
        | _ ->
            bad b b.site.vlocs.(background) Msg.background_gradient;
            st)
    | true, (VTex _ as v) ->
        bad b b.site.vlocs.(background)
          (Msg.field_type b.site.entries.(background).sch (ty v));
        st
    | _ -> st
  in
  let st =
    if not (live b fog) then st
    else
      match value b fog with
      | VTex { tname = "fog"; targs = [ VVec c; VNum distance ]; _ } ->
          if c.x < 0. || c.y < 0. || c.z < 0. then (
            bad b b.site.vlocs.(fog) Msg.fog_colour;
            st)
          else { st with fog = Some { color = Color.of_vec3 c; distance } }
      | v ->
          bad b b.site.vlocs.(fog) (Msg.field_type b.site.entries.(fog).sch (ty v));
          st
  in
  if not (finish b) then None
  else
    match Settings.validate st with
    | Ok () -> Some st
    | Error m ->
        bad b b.site.kloc (Msg.invalid "settings" m);
        None

(* A pair (a, b) of numbers in the field's range, a ≤ b; [default] where left out. *)
let interval b i ~default =
  if not (live b i) then default
  else
    let e = b.site.entries.(i) and at = b.site.vlocs.(i) in
    match value b i with
    | VPair (VNum x, VNum y) ->
        if not (Schema.in_range e.sch.range x && Schema.in_range e.sch.range y) then (
          bad b at
            (Msg.out_of_range e.sch (if Schema.in_range e.sch.range x then y else x));
          default)
        else if x > y then (
          bad b at (Msg.interval_order e.sch.name x y);
          default)
        else (x, y)
    | v ->
        bad b at (Msg.field_type e.sch (ty v));
        default

let camera b =
  let site = b.site in
  let s name = slot site name in
  let kind = s "kind" and fov = s "fov" and width = s "width" in
  let up = s "up" and look_at_ = s "look_at" in
  let aperture_ = s "aperture" and focal = s "focal_distance" in
  (* An unknown kind is reported once; the fields that depend on the kind are then not
     checked against a guess. *)
  let kind_name =
    if site.wrong.(kind) || (given b kind && not (live b kind)) then "unknown"
    else if not (given b kind) then
      match site.entries.(kind).default with VStr x -> x | _ -> "perspective"
    else
      match value b kind with
      | VStr x when List.mem x Camera.kind_names -> x
      | VStr x ->
          bad b site.vlocs.(kind) (Msg.camera_kind x Camera.kind_names);
          "unknown"
      | v ->
          bad b site.vlocs.(kind) (Msg.field_type site.entries.(kind).sch (ty v));
          "unknown"
  in
  let position = point b (s "position") in
  let look_at = point b look_at_ in
  let up_v = point b up in
  (* The default and the range of `fov` depend on the kind (the range is checked below). *)
  let fov_of k =
    List.find_opt
      (fun (fl : Schema.field) ->
        match fl.condition with Kind_in ks -> List.mem k ks | _ -> false)
      site.kind_.named.(fov)
  in
  let fov_v =
    let d =
      match Option.map Kind.entry (fov_of kind_name) with
      | Some { default = VNum x; _ } -> x
      | _ -> ( match site.entries.(fov).default with VNum x -> x | _ -> 60.)
    in
    number b fov ~default:d ~check:(fun _ x -> x)
  in
  let perspective = Option.get (fov_of "perspective")
  and fisheye = Option.get (fov_of "fisheye") in
  (* A field whose value failed (reported) is not reported again where it stands. *)
  (if live b fov then
     let at = site.vlocs.(fov) in
     match kind_name with
     | "fisheye" when not (Schema.in_range fisheye.range fov_v) ->
         bad b at (Msg.fisheye_fov (Schema.must fisheye) fov_v)
     | "orthographic" -> if not site.kind_known then bad b at Msg.orthographic_fov
     | "perspective" when not (Schema.in_range perspective.range fov_v) ->
         bad b at
           (Msg.fov (Schema.must perspective) fov_v (Schema.in_range fisheye.range fov_v))
     | _ -> ());
  let width_v =
    match (given b width, kind_name) with
    | true, ("perspective" | "fisheye") ->
        if live b width && not site.kind_known then
          bad b site.vlocs.(width) Msg.width_not_orthographic;
        b.failed <- true;
        1.
    | false, "orthographic" ->
        if not site.kind_known then bad b site.kloc Msg.orthographic_width;
        b.failed <- true;
        1.
    | _ -> number b width
  in
  let aperture = number b aperture_ in
  (* Without an aperture, the focal distance is the camera's own default (unused). *)
  let focal_distance = number b focal ~default:Camera.default.focal_distance in
  let lens_samples = integer b (s "lens_samples") in
  let shutter = interval b (s "shutter") ~default:Camera.default.shutter in
  let shutter_samples = integer b (s "shutter_samples") in
  if given b aperture_ && (not (given b focal)) && aperture > 0. then
    bad b site.kloc Msg.aperture_focal;
  if not (finish b) then None
  else
    let view = Vec3.sub look_at position in
    if
      Vec3.max_abs view > 0.
      && Vec3.max_abs up_v > 0.
      &&
      let cos = Vec3.dot view up_v /. (Vec3.length view *. Vec3.length up_v) in
      Float.abs cos > 1. -. 1e-12
    then (
      let at =
        if given b up then site.vlocs.(up)
        else if given b look_at_ then site.vlocs.(look_at_)
        else site.kloc
      in
      bad b at (Hints.camera_up view up_v);
      None)
    else
      let kind =
        match kind_name with
        | "orthographic" -> Camera.Orthographic { width = width_v }
        | "fisheye" -> Camera.Fisheye
        | _ -> Camera.Perspective
      in
      let c =
        Camera.make ~kind ~position ~look_at ~up:up_v ~fov:fov_v ~aperture ~focal_distance
          ~lens_samples ~shutter ~shutter_samples ()
      in
      match Camera.validate c with
      | Ok () -> Some c
      | Error m ->
          bad b site.kloc (Msg.invalid "camera" m);
          None

let animation b =
  let s name = slot b.site name in
  let fps_ = s "fps" and frames_ = s "frames" and duration = s "duration" in
  (* A rate above its limit is told as such, not as a range. *)
  let fps =
    let e = b.site.entries.(fps_) in
    number b fps_ ~check:(fun at x ->
        (match e.sch.range with
        | Real (Excl lo, Incl hi) ->
            if not (x > lo && x <= Schema.big) then bad b at (Msg.fps_low lo x);
            if x > hi then bad b at (Msg.fps_high hi)
        | _ -> check_range b e fps_ x);
        x)
  in
  let frames =
    match (given b frames_, given b duration) with
    | _, false -> integer b frames_
    | _, true ->
        let d = number b duration in
        let n = Float.round (d *. fps) in
        let most =
          match b.site.entries.(frames_).sch.range with
          | Whole (_, hi) -> hi
          | _ -> max_int
        in
        if n > Float.of_int most then (
          bad b b.site.vlocs.(duration) (Msg.too_many_frames most);
          1)
        else max 1 (int_of_float n)
  in
  if finish b then Some (fps, frames) else None

let physics b =
  let s name = slot b.site name in
  let m = s "method" in
  let method_of x = List.assoc_opt x D.physics_methods in
  let gravity = point b (s "gravity") in
  let method_ =
    let default =
      match b.site.entries.(m).default with
      | VStr x -> Option.value (method_of x) ~default:D.Exact
      | _ -> D.Exact
    in
    if not (live b m) then default
    else
      match value b m with
      | VStr x -> (
          match method_of x with
          | Some k -> k
          | None ->
              bad b b.site.vlocs.(m)
                (Msg.physics_method x (List.map fst D.physics_methods));
              default)
      | v ->
          bad b b.site.vlocs.(m) (Msg.field_type b.site.entries.(m).sch (ty v));
          default
  in
  let step = number b (s "step") in
  if finish b then Some ({ gravity; method_; step } : D.physics) else None

let light b =
  let site = b.site in
  let s name = slot site name in
  match site.block.id with
  | "point_light" ->
      let position = point b (s "position") in
      let color_ = color b (s "color") in
      let intensity = number b (s "intensity") in
      let att = s "attenuation" in
      let attenuation = point b att in
      if
        given b att
        && (attenuation.x < 0. || attenuation.y < 0. || attenuation.z < 0.
           || Vec3.max_abs attenuation = 0.)
      then bad b site.vlocs.(att) Msg.attenuation;
      let radius = number b (s "radius") in
      let samples = integer b (s "samples") in
      let pa = s "point_at" in
      let spot =
        if not (given b pa) then None
        else
          let point_at = point b pa in
          let inner = s "inner" and outer = s "outer" in
          let inner_v = number b inner and outer_v = number b outer in
          if b.failed then None
          else
            match Light.spot ~position ~point_at ~inner:inner_v ~outer:outer_v with
            | Ok sp -> Some sp
            | Error m ->
                (* At point_at when it is the position, else at the angle written last. *)
                let at =
                  match List.filter (given b) [ outer; inner ] with
                  | i :: _ when Vec3.max_abs (Vec3.sub point_at position) > 0. ->
                      site.vlocs.(i)
                  | _ -> site.vlocs.(pa)
                in
                bad b at m;
                None
      in
      if finish b then
        Some
          (Light.point ~color:color_ ~intensity ~attenuation ~radius ~samples ?spot
             position)
      else None
  | _ ->
      let d = s "direction" in
      let direction = point b d in
      if given b d && Vec3.max_abs direction = 0. then
        bad b site.vlocs.(d) Msg.zero_direction;
      let color_ = color b (s "color") in
      let intensity = number b (s "intensity") in
      if finish b then Some (Light.directional ~color:color_ ~intensity direction)
      else None

(* ------------------------------------------------------------------------------------ *)
(* Objects *)

let step_field b name = b.site.entries.(slot b.site name).sch

(* translate / rotate / scale, in the order written: the transform (each one checked),
   and the steps (read from the last, into a list in order; none for a block that
   failed, which is not built). *)
let transforms b =
  let steps = b.site.steps and big = Schema.big in
  let n = Array.length steps in
  let within (v : Vec3.t) =
    Float.abs v.x <= big && Float.abs v.y <= big && Float.abs v.z <= big
  in
  let factor x = Float.abs x >= 1e-150 && Float.abs x <= 1e150 in
  let scale = function VNum x -> Vec3.v x x x | VVec v -> v | _ -> Vec3.one in
  let rec compose k t =
    if k = n then t
    else
      let name, at = steps.(k) in
      match (name, b.svals.(k)) with
      | _, VPoison -> compose (k + 1) t (* its value failed, already reported *)
      | "translate", VVec v ->
          if not (within v) then bad b at (Msg.coordinates name);
          compose (k + 1) (Transform.then_ t (Transform.translate v))
      | "rotate", VVec v ->
          if not (within v) then bad b at (Msg.coordinates name);
          compose (k + 1) (Transform.then_ t (Transform.rotate v))
      | "scale", ((VNum _ | VVec _) as s) ->
          let v = scale s in
          if not (factor v.x && factor v.y && factor v.z) then (
            bad b at Msg.scale_factors;
            compose (k + 1) t)
          else compose (k + 1) (Transform.then_ t (Transform.scale v))
      | _, v ->
          bad b at (Msg.field_type (step_field b name) (ty v));
          compose (k + 1) t
  in
  let rec listed k js =
    if k < 0 then js
    else
      match (fst steps.(k), b.svals.(k)) with
      | "translate", VVec v -> listed (k - 1) (D.Translate v :: js)
      | "rotate", VVec v -> listed (k - 1) (D.Rotate v :: js)
      | "scale", s -> listed (k - 1) (D.Scale (scale s) :: js)
      | _ -> listed (k - 1) js
  in
  let t = compose 0 Transform.identity in
  (t, if b.failed then [] else listed (n - 1) [])

let no_material = (None, D.default_material.color)

let object_material b =
  match b.site.kind_.material with
  | i when i < 0 || not (live b i) -> no_material
  | i -> (
      match value b i with
      | VMat m -> (m.some, m.color)
      | v ->
          bad b b.site.vlocs.(i) (Msg.field_type b.site.entries.(i).sch (ty v));
          no_material)

(* What the shape of a block that failed is taken to be: it is not used. *)
let unused = D.Sphere { center = Vec3.zero; radius = 1. }

let file_use b i make =
  let file = file b i in
  if b.failed then unused
  else
    let path = Loc.relative_to b.site.kloc.file file in
    let at = b.site.vlocs.(i) in
    let u, sh = make file path at in
    b.out.use u;
    sh

(* The shape a block of kind [k] states, read from its fields (made for the kind, not
   for one block: what it says of a block it reads from the block's site). *)
let shape_of (k : Kind.t) : t -> D.shape =
  let s name =
    match Kind.slot k name with
    | -1 -> invalid_arg ("Build: no field " ^ name ^ " of " ^ k.block.id)
    | i -> i
  in
  let check b cond msg = if (not b.failed) && cond then bad b b.site.kloc msg in
  match k.block.id with
  | "sphere" ->
      let c = s "center" and r = s "radius" in
      fun b ->
        let center = point b c in
        let radius = number b r in
        D.Sphere { center; radius }
  | "plane" ->
      let n = s "normal" and o = s "offset" in
      fun b ->
        let normal = direction b n in
        let offset = number b o in
        D.Plane { normal; offset }
  | "parallelogram" ->
      let o = s "origin" and e1 = s "edge1" and e2 = s "edge2" in
      fun b ->
        let origin = point b o in
        let edge1 = direction b e1 in
        let edge2 = direction b e2 in
        check b (Vec3.length (Vec3.cross edge1 edge2) < 1e-300) Msg.not_parallel;
        D.Parallelogram { origin; edge1; edge2 }
  | "triangle" ->
      let ia = s "a" and ib = s "b" and ic = s "c" in
      fun b ->
        let a = point b ia in
        let bb = point b ib in
        let c = point b ic in
        check b
          (Vec3.length (Vec3.cross (Vec3.sub bb a) (Vec3.sub c a)) < 1e-300)
          Msg.not_in_line;
        D.Triangle { a; b = bb; c }
  | "paraboloid" ->
      let v = s "vertex" and ax = s "axis" and r = s "radius" and h = s "height" in
      fun b ->
        let vertex = point b v in
        let axis = direction b ax in
        let radius = number b r in
        let height = number b h in
        D.Paraboloid { vertex; axis; radius; height }
  | "box" ->
      let lo = s "min" and hi = s "max" in
      fun b ->
        let mn = point b lo in
        let mx = point b hi in
        check b (not (mn.x < mx.x && mn.y < mx.y && mn.z < mx.z)) Msg.box_order;
        D.Box { min = mn; max = mx }
  | "cylinder" ->
      let ba = s "base" and t = s "top" and r = s "radius" and c = s "caps" in
      fun b ->
        let base = point b ba in
        let top = point b t in
        let radius = number b r in
        let caps = boolean b c in
        check b (Vec3.length (Vec3.sub top base) < 1e-150) Msg.cylinder_ends;
        D.Cylinder { base; top; radius; caps }
  | "cone" ->
      let ba = s "base" and t = s "top" and c = s "caps" in
      let r0 = s "base_radius" and r1 = s "top_radius" in
      fun b ->
        let base = point b ba in
        let top = point b t in
        let base_radius = number b r0 and top_radius = number b r1 in
        let caps = boolean b c in
        check b (Vec3.length (Vec3.sub top base) < 1e-150) Msg.cone_ends;
        check b (base_radius < 1e-150 && top_radius < 1e-150) Msg.cone_radii;
        D.Cone { base; top; base_radius; top_radius; caps }
  | "torus" ->
      let c = s "center" and ma = s "major" and mi = s "minor" and ax = s "axis" in
      fun b ->
        let center = point b c in
        let major = number b ma in
        let minor = number b mi in
        let axis = direction b ax in
        D.Torus { center; axis; major; minor }
  | "disk" ->
      let c = s "center" and n = s "normal" and r = s "radius" in
      fun b ->
        let center = point b c in
        let normal = direction b n in
        let radius = number b r in
        D.Disk { center; normal; radius }
  | "mesh" ->
      let f = s "file" and sm = s "smooth" in
      fun b ->
        let smooth = boolean b sm in
        file_use b f (fun file path at ->
            ( D.Model { file; path; smooth; at; solid_in = None },
              D.Mesh { file; path; smooth; at } ))
  | "height_field" ->
      let f = s "file" and o = s "origin" and sz = s "size" and sm = s "smooth" in
      fun b ->
        let origin = point b o in
        let smooth = boolean b sm in
        let size =
          point b sz ~check:(fun at (size : Vec3.t) ->
              if not (size.x >= 1e-150 && size.y >= 1e-150 && size.z >= 1e-150) then
                bad b at Msg.height_field_size;
              size)
        in
        file_use b f (fun file path at ->
            ( D.Heights { file; path; at },
              D.Height_field { file; path; origin; size; smooth; at } ))
  | k -> invalid_arg ("Build: " ^ k ^ " is not a shape")

let shape site = shape_of site.kind_
let untransformed = (Transform.identity, [])

let object_ site =
  let shape = shape site and kind = site.kind and loc = site.kloc in
  let plain = step_count site = 0 in
  fun b ->
    let transform, steps = if plain then untransformed else transforms b in
    let material, color = object_material b in
    let shape = shape b in
    { D.kind; shape; transform; steps; material; color; loc; body = None }

let group_members t tj (mat, color) members onto =
  if Transform.is_identity t && match (tj, mat) with [], None -> true | _ -> false then
    members @ onto (* each object would be itself again *)
  else
    let member (o : D.obj) =
      {
        o with
        transform = Transform.then_ o.transform t;
        steps = o.steps @ tj;
        material = (match o.material with Some _ -> o.material | None -> mat);
        color = (match o.material with Some _ -> o.color | None -> color);
      }
    in
    let rec map_onto = function
      | [] -> onto
      | o :: rest -> member o :: map_onto rest
        [@@tail_mod_cons]
    in
    map_onto members

(* A CSG block: its members are combined into one object. A group inside a CSG block is
   one member, the union of its own. *)
let csg b ~keyword ~loc ~in_csg members =
  let t, tj = transforms b in
  let mat, color = object_material b in
  let op : D.csg_op =
    match keyword with
    | "merge" -> Merge
    | "intersection" -> Intersection
    | "difference" -> Difference
    | _ -> Union
  in
  let what =
    if keyword = "group" then "a group inside a CSG block"
    else Printf.sprintf "a `%s`" keyword
  in
  if members = [] && not b.failed then bad b loc (Msg.csg_empty what);
  if op = Difference && List.length members = 1 then bad b loc Msg.difference_needs_two;
  (* A union shows every member's surface; the other operations (and a union that is
     itself a member of one) need each member to have an inside (a mesh's, closed, is
     checked when its file is read). *)
  let need_solid = op <> Union || in_csg in
  List.iter
    (fun (o : D.obj) ->
      match o.shape with
      | D.Mesh _ -> ()
      | D.Height_field _ ->
          bad b o.loc
            (Msg.height_field_not_solid
               (String.map (function '_' -> ' ' | c -> c) o.kind)
               keyword)
      | sh when D.is_solid sh || not need_solid -> ()
      | _ -> bad b o.loc (Msg.not_solid o.kind keyword))
    members;
  (* A mesh member must be closed: its file tells. *)
  if need_solid then
    List.iter
      (fun (o : D.obj) ->
        match o.shape with
        | D.Mesh { file; path; smooth; at } ->
            b.out.use
              (D.Model { file; path; smooth; at; solid_in = Some (keyword, o.loc) })
        | _ -> ())
      members;
  if not (finish b) then None
  else
    let member (o : D.obj) = { o with body = None } in
    Some
      {
        D.kind = (if keyword = "group" then "union" else keyword);
        shape =
          D.Csg
            { op; block = keyword; members = List.map member members; solid = need_solid };
        transform = t;
        steps = tj;
        material = mat;
        color;
        loc;
        body = None;
      }

let body b ~name ~loc ~at members =
  let s n = slot b.site n in
  let velocity = point b (s "velocity") in
  let mass = number b (s "mass") in
  let restitution = number b (s "restitution") in
  if not (finish b) then None
  else
    Some
      (match members with
      | [ ({ D.shape = D.Sphere { center; radius }; _ } as o) ] ->
          let c0 = Transform.point o.transform center in
          (* The simulated sphere is the rendered one: its radius is scaled by the length
             of the transformed axes, which must agree (a rotation keeps them; a
             non-uniform scale would draw an ellipsoid that the physics cannot follow). *)
          let axis a = Vec3.length (Transform.vector o.transform a) in
          let sx = axis Vec3.x_axis and sy = axis Vec3.y_axis and sz = axis Vec3.z_axis in
          let lo = Float.min sx (Float.min sy sz)
          and hi = Float.max sx (Float.max sy sz) in
          if hi > lo *. (1. +. 1e-9) then Error (at, Msg.body_scaled name sx sy sz)
          else
            Ok
              ( ({
                   name;
                   center = c0;
                   radius = radius *. hi;
                   velocity;
                   mass;
                   restitution;
                   loc;
                 }
                  : D.body),
                o )
      | _ -> Error (at, Msg.body_one_sphere))
