type v = { x : float; y : float; z : float }

type scene = {
  width : int;
  height : int;
  depth : int;
  horizon : v;
  zenith : v;
  eye : v;
  look_at : v;
  fov : float;
  light : v;
  center : v;
  radius : float;
  material : Lancer.Description.material;
}

let v x y z = { x; y; z }
let ( +| ) a b = v (a.x +. b.x) (a.y +. b.y) (a.z +. b.z)
let ( -| ) a b = v (a.x -. b.x) (a.y -. b.y) (a.z -. b.z)
let ( *| ) k a = v (k *. a.x) (k *. a.y) (k *. a.z)
let had a b = v (a.x *. b.x) (a.y *. b.y) (a.z *. b.z)
let dot a b = (a.x *. b.x) +. (a.y *. b.y) +. (a.z *. b.z)
let norm a = sqrt (dot a a)
let unit a = 1. /. norm a *| a

let cross a b =
  v
    ((a.y *. b.z) -. (a.z *. b.y))
    ((a.z *. b.x) -. (a.x *. b.z))
    ((a.x *. b.y) -. (a.y *. b.x))

let white = v 1. 1. 1.
let black = v 0. 0. 0.
let inf_norm a = Float.max (Float.abs a.x) (Float.max (Float.abs a.y) (Float.abs a.z))

(* tint(k) = (1 − k)·white + k·C *)
let tint k c = ((1. -. k) *| white) +| (k *| c)

(* The roots t in (lo, hi) of |o + t·d − c|² = r² for a unit d, in increasing order. *)
let roots s o d lo hi =
  let oc = o -| s.center in
  let b = dot oc d in
  let disc = (b *. b) -. (dot oc oc -. (s.radius *. s.radius)) in
  if disc < 0. then []
  else
    let q = sqrt disc in
    List.filter (fun t -> t > lo && t < hi) [ -.b -. q; -.b +. q ]

let sky s d =
  let t = Float.max 0. d.y in
  s.horizon +| (t *| (s.zenith -| s.horizon))

(* The scale-aware offset off the surface at p, reached from o. *)
let offset p o = 1e-9 *. Float.max (inf_norm p) (inf_norm o)

let rec trace s o d depth =
  match roots s o d 0. Float.infinity with
  | [] -> sky s d
  | t :: _ -> shade s o d (o +| (t *| d)) depth

and shade s o d p depth =
  let m = s.material in
  let c = v m.color.r m.color.g m.color.b in
  let n = unit (p -| s.center) in
  let entering = dot d n < 0. in
  let nf = if entering then n else -1. *| n in
  let vw = -1. *| d in
  let delta = offset p o in
  let above = p +| (delta *| nf) and below = p -| (delta *| nf) in
  (* Local light: ambient (the scene's ambient light is white), then the one light. *)
  let local = m.ambient *| c in
  let l = s.light -| p in
  let dist = norm l in
  let ldir = 1. /. dist *| l in
  let ndl = dot nf ldir in
  let local =
    if ndl <= 0. then local
    else
      (* Shadow transmittance: τ·C at every crossing of the sphere before the light. *)
      let crossings = roots s above ldir 0. dist in
      let tr =
        List.fold_left (fun acc _ -> had acc (m.transparency *| c)) white crossings
      in
      let e = tr in
      let r = (2. *. ndl *| nf) -| ldir in
      let rv = Float.max 0. (dot r vw) in
      local
      +| (m.diffuse *. ndl *| had c e)
      +| (m.specular *. (rv ** m.shininess) *| had e (tint m.metallic c))
  in
  let r = m.reflection and tau = m.transparency in
  if r = 0. && tau = 0. then local
  else
    let cos_in = -.dot d nf in
    let eta = if entering then 1. /. m.ior else m.ior in
    let k = 1. -. (eta *. eta *. (1. -. (cos_in *. cos_in))) in
    (* Total internal reflection gives τ to r; Fresnel gives τ·F. *)
    let r', tau' =
      if tau = 0. then (r, 0.)
      else if k < 0. then (r +. tau, 0.)
      else if m.fresnel then
        let f0 = ((m.ior -. 1.) /. (m.ior +. 1.)) ** 2. in
        let c' = if entering then cos_in else sqrt k in
        let f = f0 +. ((1. -. f0) *. ((1. -. c') ** 5.)) in
        (r +. (tau *. f), tau *. (1. -. f))
      else (r, tau)
    in
    let out = (1. -. r -. tau) *| local in
    if depth >= s.depth then out
    else
      let out =
        if r' > 0. then
          let refl = d -| (2. *. dot d nf *| nf) in
          out +| had (r' *| tint m.metallic c) (trace s above refl (depth + 1))
        else out
      in
      if tau' > 0. then
        let refr = (eta *| d) +| (((eta *. cos_in) -. sqrt k) *| nf) in
        out +| had (tau' *| tint m.filter c) (trace s below refr (depth + 1))
      else out

let srgb x =
  let x = Float.min 1. (Float.max 0. x) in
  let e = if x <= 0.0031308 then 12.92 *. x else (1.055 *. (x ** (1. /. 2.4))) -. 0.055 in
  Char.chr (int_of_float (Float.floor ((255. *. e) +. 0.5)))

let render s =
  let f = unit (s.look_at -| s.eye) in
  let r = unit (cross (v 0. 1. 0.) f) in
  let u = cross f r in
  let h = tan (s.fov *. Float.pi /. 360.) in
  let w = Float.of_int s.width and hh = Float.of_int s.height in
  let a = w /. hh in
  let b = Bytes.create (3 * s.width * s.height) in
  for j = 0 to s.height - 1 do
    for i = 0 to s.width - 1 do
      let x = Float.of_int i +. 0.5 and y = Float.of_int j +. 0.5 in
      let d =
        unit
          (f
          +| (((2. *. x /. w) -. 1.) *. h *. a *| r)
          +| ((1. -. (2. *. y /. hh)) *. h *| u))
      in
      let col = trace s s.eye d 1 in
      let k = 3 * ((j * s.width) + i) in
      Bytes.set b k (srgb col.x);
      Bytes.set b (k + 1) (srgb col.y);
      Bytes.set b (k + 2) (srgb col.z)
    done
  done;
  b

let rts s =
  let p a = Printf.sprintf "(%.17g, %.17g, %.17g)" a.x a.y a.z
  and n = Printf.sprintf "%.17g" in
  let m = s.material in
  let rgb (c : Lancer.Color.t) = p (v c.r c.g c.b) in
  String.concat "\n"
    [
      Printf.sprintf
        "settings { width: %d, height: %d, depth: %d, background: gradient(%s, %s) }"
        s.width s.height s.depth (p s.horizon) (p s.zenith);
      Printf.sprintf "camera { position: %s, look_at: %s, fov: %s }" (p s.eye)
        (p s.look_at) (n s.fov);
      Printf.sprintf "light { position: %s }" (p s.light);
      Printf.sprintf
        "sphere { center: %s, radius: %s, material: material { color: %s, ambient: %s, \
         diffuse: %s, specular: %s, shininess: %s, reflection: %s, transparency: %s, \
         ior: %s, fresnel: %b, metallic: %s, filter: %s } }"
        (p s.center) (n s.radius) (rgb m.color) (n m.ambient) (n m.diffuse) (n m.specular)
        (n m.shininess) (n m.reflection) (n m.transparency) (n m.ior) m.fresnel
        (n m.metallic) (n m.filter);
      "";
    ]
