type t =
  | Point of {
      position : Vec3.t;
      color : Color.t;
      intensity : float;
      attenuation : Vec3.t;
      radius : float;
      samples : int;
    }
  | Directional of { direction : Vec3.t; color : Color.t; intensity : float }

let point ?(color = Color.white) ?(intensity = 1.) ?(attenuation = Vec3.v 1. 0. 0.) ?(radius = 0.)
    ?(samples = 1) position =
  Point { position; color; intensity; attenuation; radius; samples }

let directional ?(color = Color.white) ?(intensity = 1.) d =
  Directional { direction = Vec3.normalize d; color; intensity }

let is_area = function Point { radius; samples; _ } -> radius > 0. && samples > 1 | Directional _ -> false
