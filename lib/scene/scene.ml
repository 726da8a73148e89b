type t = {
  settings : Settings.t;
  camera : Camera.t;
  lights : Light.t array;
  objects : Primitive.t array;
  accel : Accel.t;
  features : Features.t;
  time : float;
  frame : int;
}

let derive_features (s : Settings.t) (c : Camera.t) lights objects accel =
  let mats = Array.map (fun (o : Primitive.t) -> o.material) objects in
  let any f = Array.exists f mats in
  { Features.shadows = s.shadows && Array.length lights > 0;
    soft_shadows = s.shadows && Array.exists Light.is_area lights;
    reflection = any (fun m -> m.Material.reflection > 0. || (m.fresnel && m.transparency > 0.));
    refraction = any (fun m -> m.Material.transparency > 0.);
    textures = any (fun m -> Option.is_some m.Material.texture);
    bump = any (fun m -> Option.is_some m.Material.bump);
    supersampling = s.samples > 1 || s.adaptive > 0.;
    bvh = Accel.uses_bvh accel;
    orthographic = (match c.kind with Camera.Orthographic _ -> true | Perspective | Fisheye -> false);
    fisheye = (match c.kind with Camera.Fisheye -> true | Perspective | Orthographic _ -> false);
    depth_of_field = Camera.depth_of_field c;
    spot_lights = Array.exists Light.is_spot lights;
    sky = Option.is_some s.sky;
    fog = Option.is_some s.fog;
    color_maps = any (fun m -> match m.Material.texture with Some (Texture.Gradient _ | Texture.Mapped _) -> true | _ -> false) }

let ( let* ) = Result.bind

let rec first_error = function
  | [] -> Ok ()
  | (Ok () :: rest) -> first_error rest
  | (Error _ as e) :: _ -> e

let make ?(settings = Settings.default) ?(camera = Camera.default) ?(time = 0.) ?(frame = 0) ~lights objects =
  let* () = Settings.validate settings in
  let* () = Camera.validate camera in
  let* () = first_error (List.map (fun (o : Primitive.t) -> Material.validate o.material) objects) in
  let lights = Array.of_list lights and objects = Array.of_list objects in
  let accel = Accel.build objects in
  let features = derive_features settings camera lights objects accel in
  Ok { settings; camera; lights; objects; accel; features; time; frame }

let make_exn ?settings ?camera ?time ?frame ~lights objects =
  match make ?settings ?camera ?time ?frame ~lights objects with
  | Ok s -> s
  | Error m -> invalid_arg ("Scene.make: " ^ m)

let with_settings t settings =
  let* () = Settings.validate settings in
  Ok { t with settings; features = derive_features settings t.camera t.lights t.objects t.accel }

let with_camera t camera =
  let* () = Camera.validate camera in
  Ok { t with camera; features = derive_features t.settings camera t.lights t.objects t.accel }

let map_lights t f =
  let lights = Array.map f t.lights in
  { t with lights; features = derive_features t.settings t.camera lights t.objects t.accel }
