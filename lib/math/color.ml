type t = { r : float; g : float; b : float }

let[@inline] v r g b = { r; g; b }
let black = { r = 0.; g = 0.; b = 0. }
let white = { r = 1.; g = 1.; b = 1. }
let[@inline] add a c = { r = a.r +. c.r; g = a.g +. c.g; b = a.b +. c.b }
let[@inline] mul a c = { r = a.r *. c.r; g = a.g *. c.g; b = a.b *. c.b }
let[@inline] scale s a = { r = s *. a.r; g = s *. a.g; b = s *. a.b }

let[@inline] madd a s c =
  { r = a.r +. (s *. c.r); g = a.g +. (s *. c.g); b = a.b +. (s *. c.b) }

let of_vec3 (p : Vec3.t) = { r = p.x; g = p.y; b = p.z }
let[@inline] to_vec3 c = Vec3.v c.r c.g c.b

let[@inline] is_finite c =
  Float.is_finite c.r && Float.is_finite c.g && Float.is_finite c.b
