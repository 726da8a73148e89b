type spot = {
  point_at : Vec3.t;
  axis : Vec3.t;
  inner : float;
  outer : float;
  cos_inner : float;
  cos_outer : float;
}

type t =
  | Point of {
      position : Vec3.t;
      color : Color.t;
      intensity : float;
      attenuation : Vec3.t;
      radius : float;
      samples : int;
      spot : spot option;
    }
  | Directional of { direction : Vec3.t; color : Color.t; intensity : float }

let default_color = Color.white
let default_intensity = 1.
let default_attenuation = Vec3.v 1. 0. 0.
let default_radius = 0.
let default_samples = 1
let default_inner = 30.
let default_outer = 45.

let point ?(color = default_color) ?(intensity = default_intensity)
    ?(attenuation = default_attenuation) ?(radius = default_radius)
    ?(samples = default_samples) ?spot position =
  Point { position; color; intensity; attenuation; radius; samples; spot }

let spot ~position ~point_at ~inner ~outer =
  let d = Vec3.sub point_at position in
  if Vec3.max_abs d = 0. then
    Error "a spot light's point_at must differ from its position"
  else if not (inner >= 0. && inner <= outer && outer <= 180.) then
    Error
      (Printf.sprintf
         "a spot light needs 0 ≤ inner ≤ outer ≤ 180 degrees (got inner %g, outer %g)"
         inner outer)
  else
    let rad a = a *. Float.pi /. 180. in
    Ok
      {
        point_at;
        axis = Vec3.normalize d;
        inner;
        outer;
        cos_inner = Float.cos (rad inner);
        cos_outer = Float.cos (rad outer);
      }

(* θ ≤ inner ⇔ cos θ ≥ cos inner (cos falls on [0°, 180°]); the smooth step between is
   continuous at both ends, so comparing cosines rather than angles changes nothing. *)
let[@inline] spot_factor s cos_theta =
  if cos_theta >= s.cos_inner then 1.
  else if cos_theta <= s.cos_outer then 0.
  else
    let t = (cos_theta -. s.cos_outer) /. (s.cos_inner -. s.cos_outer) in
    t *. t *. (3. -. (2. *. t))

let is_spot = function
  | Point { spot = Some _; _ } -> true
  | Point _ | Directional _ -> false

let directional ?(color = default_color) ?(intensity = default_intensity) d =
  Directional { direction = Vec3.normalize d; color; intensity }

let is_area = function
  | Point { radius; samples; _ } -> radius > 0. && samples > 1
  | Directional _ -> false

let translate (d : Vec3.t) = function
  | Point l ->
      let spot =
        Option.map (fun s -> { s with point_at = Vec3.add s.point_at d }) l.spot
      in
      Point { l with position = Vec3.add l.position d; spot }
  | Directional _ as l -> l
