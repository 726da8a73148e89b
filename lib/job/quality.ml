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
  Result.map
    (fun sc -> Scene.map_lights sc (light_samples lf))
    (Scene.with_settings sc settings)
