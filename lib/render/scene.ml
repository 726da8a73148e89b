type t = {
  settings : Settings.t;
  camera : Camera.t;
  lights : Light.t array;
  objects : Primitive.t array;
  accel : Accel.t;
  features : Features.t;
  time : float;
  frame : int;
  origin : Vec3.t;
  view : Camera.t;
  view_lights : Light.t array;
  moments : t array;
}

(* Rendering happens in coordinates centred near the camera: the world point [origin], the
   camera's position rounded to a multiple of a grid G, becomes the origin. Far from the
   world's origin the rounding of hit points, and the shadow-ray offset δ (relative to the
   coordinates' magnitude), would otherwise grow with the distance. G is the power of two
   at least 1024 times the camera's distance to its look_at point (in its largest
   coordinate): a camera closer than G/2 to the world's origin moves nothing, so such a
   scene renders exactly as it always did, and scaling a whole scene by a power of two
   scales G with it, so that the scaled scene still renders the same bits. A multiple of a
   power of two keeps the move exact wherever the moved coordinate is representable. *)
let origin_of (c : Camera.t) =
  let d = Vec3.max_abs (Vec3.sub c.look_at c.position) in
  if not (Float.is_finite d && d > 0.) then Vec3.zero
  else
    let g = Float.ldexp 1. (snd (Float.frexp d) + 10) in
    let r x =
      if Float.is_finite x && Float.is_finite g then Float.round (x /. g) *. g else 0.
    in
    let p = c.position in
    Vec3.v (r p.x) (r p.y) (r p.z)

let is_zero (v : Vec3.t) = v.x = 0. && v.y = 0. && v.z = 0.

let view_camera origin c =
  if is_zero origin then c else Camera.translate (Vec3.neg origin) c

let view_lights origin lights =
  if is_zero origin then lights else Array.map (Light.translate (Vec3.neg origin)) lights

(* What the materials of some primitives use, for their features. *)
type uses = {
  u_reflection : bool;
  u_refraction : bool;
  u_textures : bool;
  u_bump : bool;
  u_color_maps : bool;
}

let uses_of objects =
  (* Over the objects themselves: no list or array of a million materials beside them. *)
  let r = ref false
  and t = ref false
  and x = ref false
  and b = ref false
  and c = ref false in
  let see (m : Material.t) =
    if m.reflection > 0. || (m.fresnel && m.transparency > 0.) then r := true;
    if m.transparency > 0. then t := true;
    (match m.texture with
    | Some tex -> (
        x := true;
        match (tex : Texture.t) with Gradient _ | Mapped _ -> c := true | _ -> ())
    | None -> ());
    if Option.is_some m.bump then b := true
  in
  Array.iter
    (fun (o : Primitive.t) ->
      if Primitive.is_csg o then List.iter see (Primitive.materials o) else see o.material)
    objects;
  {
    u_reflection = !r;
    u_refraction = !t;
    u_textures = !x;
    u_bump = !b;
    u_color_maps = !c;
  }

let either a b =
  {
    u_reflection = a.u_reflection || b.u_reflection;
    u_refraction = a.u_refraction || b.u_refraction;
    u_textures = a.u_textures || b.u_textures;
    u_bump = a.u_bump || b.u_bump;
    u_color_maps = a.u_color_maps || b.u_color_maps;
  }

let features_of (s : Settings.t) (c : Camera.t) lights u accel =
  {
    Features.shadows = s.shadows && Array.length lights > 0;
    soft_shadows = s.shadows && Array.exists Light.is_area lights;
    reflection = u.u_reflection;
    refraction = u.u_refraction;
    textures = u.u_textures;
    bump = u.u_bump;
    supersampling = s.samples > 1 || s.adaptive > 0.;
    bvh = Accel.uses_bvh accel;
    orthographic =
      (match c.kind with Camera.Orthographic _ -> true | Perspective | Fisheye -> false);
    fisheye =
      (match c.kind with Camera.Fisheye -> true | Perspective | Orthographic _ -> false);
    depth_of_field = Camera.depth_of_field c;
    spot_lights = Array.exists Light.is_spot lights;
    sky = Option.is_some s.sky;
    fog = Option.is_some s.fog;
    color_maps = u.u_color_maps;
  }

let derive_features s c lights objects accel =
  features_of s c lights (uses_of objects) accel

(* What the materials use, as a scene's features already say: a new camera, lights or
   settings do not look at the objects again. *)
let uses_in (f : Features.t) =
  {
    u_reflection = f.reflection;
    u_refraction = f.refraction;
    u_textures = f.textures;
    u_bump = f.bump;
    u_color_maps = f.color_maps;
  }

let ( let* ) = Result.bind

(* The error of the first invalid material, the objects taken in order (a CSG object's
   leaves in theirs), as [Description.validate_material] says it; none is checked after it. A material
   that is physically the last one found valid is not checked again: a million spheres of
   one material check it once, with nothing allocated for each. *)
let first_error objects =
  let exception Invalid of string in
  let last = ref None in
  let check m =
    match !last with
    | Some l when l == m -> ()
    | _ -> (
        match Description.validate_material m with
        | Ok () -> last := Some m
        | Error e -> raise (Invalid e))
  in
  match
    Array.iter
      (fun (o : Primitive.t) ->
        if Primitive.is_csg o then List.iter check (Primitive.materials o)
        else check o.material)
      objects
  with
  | () -> Ok ()
  | exception Invalid e -> Error e

(* The scene of these parts, with the camera and lights as seen from [origin]. *)
let assemble ~settings ~camera ~lights ~time ~frame ~origin objects accel features =
  {
    settings;
    camera;
    lights;
    objects;
    accel;
    features;
    time;
    frame;
    origin;
    view = view_camera origin camera;
    view_lights = view_lights origin lights;
    moments = [||];
  }

let mover camera =
  let origin = origin_of camera in
  if is_zero origin then Primitive.baked else Primitive.mover (Vec3.neg origin)

let of_gen ~moved ?(index = true) ?(checked = false) ?(settings = Settings.default)
    ?(camera = Camera.default) ?(time = 0.) ?(frame = 0) ~lights objects =
  let* () = Settings.validate settings in
  let* () = Camera.validate camera in
  let* () = if checked then Ok () else first_error objects in
  let lights = Array.of_list lights in
  let origin = origin_of camera in
  let objects = if moved then objects else Array.map (mover camera) objects in
  let accel = if index then Accel.build objects else Accel.unindexed objects in
  let features = derive_features settings camera lights objects accel in
  Ok (assemble ~settings ~camera ~lights ~time ~frame ~origin objects accel features)

let of_array ?checked ?settings ?camera ?time ?frame ~lights objects =
  of_gen ~moved:false ?checked ?settings ?camera ?time ?frame ~lights objects

let of_moved = of_gen ~moved:true

let make ?checked ?settings ?camera ?time ?frame ~lights objects =
  of_array ?checked ?settings ?camera ?time ?frame ~lights (Array.of_list objects)

(* ---------------------------------------------------------------------------------- *)
(* A part that does not change between frames *)

type fixed = {
  f_key : int array;
  f_origin : Vec3.t;
  f_prims : Primitive.t array;  (** moved by −[f_origin] *)
  f_accel : Accel.t;
  f_valid : bool Lazy.t;  (** whether every material of them is valid *)
  f_uses : uses;
  f_placed : (int * int array) option Atomic.t;
      (** the last [fixed_idx] of the part placed whole after that many moving objects (k
          ↦ that count + k), which the frames of an animation share *)
}

let materials_valid prims = Result.is_ok (first_error prims)

let fixed ~key ~origin prims =
  let prims =
    if is_zero origin then Array.map Primitive.baked prims
    else Array.map (Primitive.translate (Vec3.neg origin)) prims
  in
  {
    f_key = key;
    f_origin = origin;
    f_prims = prims;
    f_accel = Accel.build prims;
    f_valid = lazy (materials_valid prims);
    f_uses = uses_of prims;
    f_placed = Atomic.make None;
  }

let fixed_origin f = f.f_origin

let same_point (a : Vec3.t) (b : Vec3.t) =
  let bits = Int64.bits_of_float in
  bits a.x = bits b.x && bits a.y = bits b.y && bits a.z = bits b.z

type piece = Fixed of int * int | Moving of Primitive.t list

let make_layered ?(checked = false) ?(settings = Settings.default)
    ?(camera = Camera.default) ?(time = 0.) ?(frame = 0) ~lights ~fixed:f pieces =
  let origin = origin_of camera in
  if not (same_point origin f.f_origin) then
    invalid_arg "Scene.make_layered: the fixed part is for another origin";
  let nf = Array.length f.f_prims in
  let moving =
    Array.of_list (List.concat_map (function Moving ps -> ps | Fixed _ -> []) pieces)
  in
  let moving =
    if is_zero origin then Array.map Primitive.baked moving
    else Array.map (Primitive.translate (Vec3.neg origin)) moving
  in
  let nm = Array.length moving in
  (* The moving objects before the fixed part when it is placed whole, in one piece (an
     animation's usual frame), else −1. *)
  let whole_at =
    let rec go before = function
      | Fixed (0, n) :: rest
        when n = nf && List.for_all (function Moving _ -> true | Fixed _ -> false) rest ->
          before
      | Moving ps :: rest -> go (before + List.length ps) rest
      | _ -> -1
    in
    if nf > 0 then go 0 pieces else -1
  in
  let moving_idx = Array.make nm 0 in
  let fixed_idx =
    if whole_at >= 0 then (
      (* Every fixed primitive once, in order, by construction. *)
      Array.iteri
        (fun j _ -> moving_idx.(j) <- (if j < whole_at then j else j + nf))
        moving_idx;
      match Atomic.get f.f_placed with
      | Some (a, idx) when a = whole_at -> idx
      | _ ->
          let idx = Array.init nf (fun k -> whole_at + k) in
          Atomic.set f.f_placed (Some (whole_at, idx));
          idx)
    else
      let fixed_idx = Array.make nf (-1) in
      let at = ref 0 and j = ref 0 in
      let place = function
        | Fixed (first, n) ->
            for m = 0 to n - 1 do
              fixed_idx.(first + m) <- !at + m
            done;
            at := !at + n
        | Moving ps ->
            List.iter
              (fun _ ->
                moving_idx.(!j) <- !at;
                incr j;
                incr at)
              ps
      in
      List.iter place pieces;
      (* Each fixed primitive once, in their order: the parts' ties then go as in one. *)
      let increasing = ref (nf = 0 || fixed_idx.(0) >= 0) in
      for k = 1 to nf - 1 do
        if fixed_idx.(k) <= fixed_idx.(k - 1) then increasing := false
      done;
      if (not !increasing) || !at <> nf + nm then
        invalid_arg
          "Scene.make_layered: the pieces do not place every fixed primitive once";
      fixed_idx
  in
  let objects =
    if whole_at >= 0 then
      (* Put together from the fixed part's array and the moving objects around it,
         with no write barrier per fixed primitive. *)
      let m0 = whole_at in
      Array.concat [ Array.sub moving 0 m0; f.f_prims; Array.sub moving m0 (nm - m0) ]
    else
      let objects =
        if nf > 0 then Array.make (nf + nm) f.f_prims.(0)
        else if nm > 0 then Array.make nm moving.(0)
        else [||]
      in
      List.iter
        (function
          | Fixed (first, n) -> Array.blit f.f_prims first objects fixed_idx.(first) n
          | Moving _ -> ())
        pieces;
      Array.iteri (fun j i -> objects.(i) <- moving.(j)) moving_idx;
      objects
  in
  let* () = Settings.validate settings in
  let* () = Camera.validate camera in
  let* () =
    if checked then Ok ()
    else first_error (if Lazy.force f.f_valid then moving else objects)
  in
  let lights = Array.of_list lights in
  (* A shadow ray's transmittance multiplies its crossings in the order of their values,
     not of the structure's walk (Shade.transparent_into), so transparent objects are
     layered like the others. *)
  let uses = either f.f_uses (uses_of moving) in
  let accel =
    Accel.layered objects ~key:f.f_key ~fixed:f.f_accel ~fixed_idx
      ~moving:(Accel.build moving) ~moving_idx
  in
  let features = features_of settings camera lights uses accel in
  Ok (assemble ~settings ~camera ~lights ~time ~frame ~origin objects accel features)

let make_exn ?settings ?camera ?time ?frame ~lights objects =
  match make ?settings ?camera ?time ?frame ~lights objects with
  | Ok s -> s
  | Error m -> invalid_arg ("Scene.make: " ^ m)

let with_settings t settings =
  let* () = Settings.validate settings in
  Ok
    {
      t with
      settings;
      features = features_of settings t.camera t.lights (uses_in t.features) t.accel;
    }

let with_camera t camera =
  let* () = Camera.validate camera in
  Ok
    {
      t with
      camera;
      view = view_camera t.origin camera;
      features = features_of t.settings camera t.lights (uses_in t.features) t.accel;
    }

let rec map_lights t f =
  let lights = Array.map f t.lights in
  {
    t with
    lights;
    view_lights = view_lights t.origin lights;
    features = features_of t.settings t.camera lights (uses_in t.features) t.accel;
    moments = Array.map (fun m -> map_lights m f) t.moments;
  }

(* [change] on the scene and on each of its moments. *)
let and_moments t change =
  let* t' = change t in
  let rec all acc k =
    if k < 0 then Ok acc
    else
      let* m = change t.moments.(k) in
      all (m :: acc) (k - 1)
  in
  let* ms = all [] (Array.length t.moments - 1) in
  Ok { t' with moments = Array.of_list ms }

let map_settings t f = and_moments t (fun s -> with_settings s (f s.settings))
let map_camera t f = and_moments t (fun s -> with_camera s (f s.camera))

let with_moments t moments =
  if Camera.motion_blur t.camera then
    if Array.length moments <> t.camera.shutter_samples then
      Error
        (Printf.sprintf "the shutter has %d samples, but %d scenes were given"
           t.camera.shutter_samples (Array.length moments))
    else if
      Array.exists
        (fun m ->
          m.settings.width <> t.settings.width || m.settings.height <> t.settings.height)
        moments
    then Error "the scenes at the shutter's instants differ in image size"
    else Ok { t with moments = Array.map (fun m -> { m with moments = [||] }) moments }
  else if Array.length moments = 0 then Ok t
  else Error "scenes at other instants were given for a closed shutter"

let object_count t = Array.fold_left (fun n o -> n + Primitive.faces o) 0 t.objects
