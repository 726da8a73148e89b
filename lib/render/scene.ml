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

let derive_features (s : Settings.t) (c : Camera.t) lights objects accel =
  (* Over the objects themselves: no list or array of a million materials beside them. *)
  let any f =
    Array.exists
      (fun (o : Primitive.t) ->
        if Primitive.is_csg o then List.exists f (Primitive.materials o) else f o.material)
      objects
  in
  {
    Features.shadows = s.shadows && Array.length lights > 0;
    soft_shadows = s.shadows && Array.exists Light.is_area lights;
    reflection =
      any (fun m -> m.Material.reflection > 0. || (m.fresnel && m.transparency > 0.));
    refraction = any (fun m -> m.Material.transparency > 0.);
    textures = any (fun m -> Option.is_some m.Material.texture);
    bump = any (fun m -> Option.is_some m.Material.bump);
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
    color_maps =
      any (fun m ->
          match m.Material.texture with
          | Some (Texture.Gradient _ | Texture.Mapped _) -> true
          | _ -> false);
  }

let ( let* ) = Result.bind

(* The first error of a sequence of checks, running none after it. *)
let rec first_error s =
  match s () with
  | Seq.Nil -> Ok ()
  | Seq.Cons (Ok (), rest) -> first_error rest
  | Seq.Cons ((Error _ as e), _) -> e

let make ?(settings = Settings.default) ?(camera = Camera.default) ?(time = 0.)
    ?(frame = 0) ~lights objects =
  let* () = Settings.validate settings in
  let* () = Camera.validate camera in
  let* () =
    first_error
      (List.to_seq objects
      |> Seq.concat_map (fun o -> List.to_seq (Primitive.materials o))
      |> Seq.map Material.validate)
  in
  let lights = Array.of_list lights and objects = Array.of_list objects in
  let origin = origin_of camera in
  let objects =
    if is_zero origin then objects
    else Array.map (Primitive.translate (Vec3.neg origin)) objects
  in
  let accel = Accel.build objects in
  let features = derive_features settings camera lights objects accel in
  let view = view_camera origin camera and view_lights = view_lights origin lights in
  Ok
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
      view;
      view_lights;
    }

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
      features = derive_features settings t.camera t.lights t.objects t.accel;
    }

let with_camera t camera =
  let* () = Camera.validate camera in
  Ok
    {
      t with
      camera;
      view = view_camera t.origin camera;
      features = derive_features t.settings camera t.lights t.objects t.accel;
    }

let map_lights t f =
  let lights = Array.map f t.lights in
  {
    t with
    lights;
    view_lights = view_lights t.origin lights;
    features = derive_features t.settings t.camera lights t.objects t.accel;
  }
