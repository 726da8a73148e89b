type t = Framebuffer.t Description.bump_of

(* Remove the gradient's component along n so the bump tilts the normal without
   changing which side it faces, then renormalise. *)
let tilt n g amount =
  let g = Vec3.madd g (-.Vec3.dot g n) n in
  let n' = Vec3.normalize (Vec3.madd n (-.amount) g) in
  if Vec3.dot n' n > 0. then n' else n

let height img u v =
  let c = Texture.bilinear img u v in
  (0.2126 *. c.r) +. (0.7152 *. c.g) +. (0.0722 *. c.b)

(* A difference of texture coordinates taken the short way round the period-1 wrap, so
   that a seam does not look like a cliff. *)
let wrap_diff d = d -. Float.round d

let perturb (b : t) ~uv (p : Vec3.t) n =
  match b with
  | Noise_bump { scale; amount } ->
      let s = 1. /. scale in
      tilt n (Noise.gradient (p.x *. s) (p.y *. s) (p.z *. s)) amount
  | Image_bump { image = img; amount } ->
      (* The surface directions of growing u and v: central differences of [uv] along a
         tangent frame (t1, t2), a step small against the object's scale. *)
      let helper = if Float.abs n.x < 0.9 then Vec3.x_axis else Vec3.y_axis in
      let t1 = Vec3.normalize (Vec3.madd helper (-.Vec3.dot helper n) n) in
      let t2 = Vec3.cross n t1 in
      let e = 1e-6 *. Float.max (Vec3.max_abs p) 1e-3 in
      let u0, v0 = uv Vec3.zero in
      let d t =
        let ua, va = uv (Vec3.smul e t) and ub, vb = uv (Vec3.smul (-.e) t) in
        (wrap_diff (ua -. ub) /. (2. *. e), wrap_diff (va -. vb) /. (2. *. e))
      in
      let du1, dv1 = d t1 and du2, dv2 = d t2 in
      let gu = Vec3.normalize (Vec3.add (Vec3.smul du1 t1) (Vec3.smul du2 t2)) in
      let gv = Vec3.normalize (Vec3.add (Vec3.smul dv1 t1) (Vec3.smul dv2 t2)) in
      let su = 1. /. Float.of_int (max 1 img.Framebuffer.width)
      and sv = 1. /. Float.of_int (max 1 img.Framebuffer.height) in
      let hu = 0.5 *. (height img (u0 +. su) v0 -. height img (u0 -. su) v0) in
      let hv = 0.5 *. (height img u0 (v0 +. sv) -. height img u0 (v0 -. sv)) in
      let g = Vec3.add (Vec3.smul hu gu) (Vec3.smul hv gv) in
      if Float.is_finite (Vec3.dot g g) then tilt n g amount else n
