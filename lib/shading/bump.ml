type t = Noise of { scale : float; amount : float }

(* Remove the gradient's component along n so the bump tilts the normal without
   changing which side it faces, then renormalise. *)
let perturb b (p : Vec3.t) n =
  match b with
  | Noise { scale; amount } ->
      let s = 1. /. scale in
      let g = Noise.gradient (p.x *. s) (p.y *. s) (p.z *. s) in
      let g = Vec3.madd g (-.Vec3.dot g n) n in
      Vec3.normalize (Vec3.madd n (-.amount) g)
