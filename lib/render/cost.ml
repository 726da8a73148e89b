let samples_per_pixel (s : Settings.t) =
  if s.adaptive > 0. then 4 + (max s.samples 4 * max s.samples 4)
  else s.samples * s.samples

let shadow_rays_per_hit (sc : Scene.t) =
  if not sc.features.shadows then 0
  else
    Array.fold_left
      (fun n l ->
        match l with
        | Light.Point { radius; samples; _ } when radius > 0. && samples > 1 ->
            n + (samples * samples)
        | Light.Point _ | Light.Directional _ -> n + 1)
      0 sc.lights

type t = {
  primary : float;
  primary_low : float;
  direct : float;
  direct_low : float;
  bound : float;
}

let estimate (sc : Scene.t) =
  let s = sc.settings in
  let pixels = Float.of_int s.width *. Float.of_int s.height in
  (* Depth of field traces each sample n×n times through the lens. *)
  let lens =
    if Camera.depth_of_field sc.camera then
      Float.of_int (sc.camera.lens_samples * sc.camera.lens_samples)
    else 1.
  in
  let primary = pixels *. Float.of_int (samples_per_pixel s) *. lens in
  let primary_low = if s.adaptive > 0. then pixels *. 4. *. lens else primary in
  let per_hit = 1. +. Float.of_int (shadow_rays_per_hit sc) in
  (* A ray that hits may spawn a reflected and a refracted ray, down to the depth: the
     rays of one primary path number at most 1 + b + b² + … + b^(depth−1). *)
  let branches =
    Bool.to_int sc.features.reflection + Bool.to_int sc.features.refraction
  in
  let path =
    match branches with
    | 0 -> 1.
    | 1 -> Float.of_int s.depth
    | b ->
        (Float.pow (Float.of_int b) (Float.of_int s.depth) -. 1.) /. Float.of_int (b - 1)
  in
  (* A camera sample casts at most Shade.max_secondary secondary rays. *)
  let path = Float.min path (Float.of_int (1 + Shade.max_secondary)) in
  {
    primary;
    primary_low;
    direct = primary *. per_hit;
    direct_low = primary_low *. per_hit;
    bound = primary *. path *. per_hit;
  }
