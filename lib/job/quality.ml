type t = Draft | Preview | Final | Reference

let all =
  [ ("draft", Draft); ("preview", Preview); ("final", Final); ("reference", Reference) ]

let to_string q = fst (List.find (fun (_, q') -> q = q') all)

let light_samples f = function
  | Light.Point p when p.radius > 0. -> Light.Point { p with samples = f p.samples }
  | l -> l

let apply q (sc : Scene.t) =
  let s = sc.settings in
  let settings, lf =
    match q with
    | Draft -> ({ s with samples = 1; adaptive = 0.; depth = min s.depth 3 }, fun _ -> 1)
    | Preview -> ({ s with samples = 1; adaptive = 0. }, fun n -> min n 3)
    | Final -> ({ s with samples = 4; adaptive = 0.02; depth = max s.depth 8 }, Fun.id)
    | Reference ->
        ({ s with samples = 8; adaptive = 0.; depth = max s.depth 16 }, fun n -> max n 8)
  in
  let shutter_samples =
    match q with Draft -> 1 | Preview -> 4 | Final -> 8 | Reference -> 32
  in
  let c = sc.camera in
  let ( let* ) = Result.bind in
  let* sc = Scene.with_settings sc settings in
  let* sc =
    if Camera.motion_blur c && c.shutter_samples <> shutter_samples then
      Scene.with_camera sc (Camera.with_shutter_samples c shutter_samples)
    else Ok sc
  in
  Ok (Scene.map_lights sc (light_samples lf))
