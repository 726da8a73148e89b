type color_map = { ts : float array; cs : Color.t array }

let color_map entries =
  { ts = Array.of_list (List.map fst entries); cs = Array.of_list (List.map snd entries) }

(* The last k with t_k ≤ v (−1 when v < t_0); a binary search would pay only for long maps. *)
let lookup m v =
  let ts = m.ts and cs = m.cs in
  let n = Array.length ts in
  let k = ref (-1) in
  while !k + 1 < n && ts.(!k + 1) <= v do
    incr k
  done;
  if !k < 0 then cs.(0)
  else if !k = n - 1 then cs.(n - 1)
  else
    let t0 = ts.(!k) and t1 = ts.(!k + 1) in
    let c0 = cs.(!k) and c1 = cs.(!k + 1) in
    let s = (v -. t0) /. (t1 -. t0) in
    Color.v
      (c0.r +. (s *. (c1.r -. c0.r)))
      (c0.g +. (s *. (c1.g -. c0.g)))
      (c0.b +. (s *. (c1.b -. c0.b)))

type t = (Framebuffer.t, color_map) Description.texture_of

(* ⌊x⌋ as an int, clamped so that huge or non-finite coordinates cannot reach the
   unspecified cases of int_of_float; only the parity is used. *)
let[@inline] ifloor x =
  let f = Float.floor x in
  if f >= 4e18 || f <= -4e18 || Float.is_nan f then 0 else int_of_float f

(* s in [0, 1] (NaN counts as 0) from c1 to c2. *)
let mix (c1 : Color.t) (c2 : Color.t) s =
  let s = if s > 0. then if s < 1. then s else 1. else 0. in
  Color.v
    (c1.r +. (s *. (c2.r -. c1.r)))
    (c1.g +. (s *. (c2.g -. c1.g)))
    (c1.b +. (s *. (c2.b -. c1.b)))

(* Wrap x into [0, n): integer coordinates of a tiled image. *)
let wrap i n =
  let k = i mod n in
  if k < 0 then k + n else k

let bilinear (img : Framebuffer.t) u v =
  let w = img.width and h = img.height in
  if w <= 0 || h <= 0 then Color.black
  else
    let u = if Float.is_finite u then u -. Float.floor u else 0. in
    let v = if Float.is_finite v then v -. Float.floor v else 0. in
    (* Pixel centres at (i + ½)/w; row 0 is the top, v = 0 the bottom. *)
    let x = (u *. Float.of_int w) -. 0.5 and y = ((1. -. v) *. Float.of_int h) -. 0.5 in
    let fx = Float.floor x and fy = Float.floor y in
    let ax = x -. fx and ay = y -. fy in
    let i0 = wrap (int_of_float fx) w and j0 = wrap (int_of_float fy) h in
    let i1 = wrap (i0 + 1) w and j1 = wrap (j0 + 1) h in
    let d = img.data in
    let ch i j k = Float.Array.get d ((3 * ((j * w) + i)) + k) in
    let lerp k =
      let top = ch i0 j0 k +. (ax *. (ch i1 j0 k -. ch i0 j0 k)) in
      let bot = ch i0 j1 k +. (ax *. (ch i1 j1 k -. ch i0 j1 k)) in
      top +. (ay *. (bot -. top))
    in
    Color.v (lerp 0) (lerp 1) (lerp 2)

(* The value in [0, 1] (before clamping) that mixes the two colours of a noise, marble or
   wood texture, or indexes a colour map. *)
let pattern_value (pat : Description.pattern) (p : Vec3.t) =
  match pat with
  | Noise_pattern scale ->
      let s = 1. /. scale in
      0.5 *. (1. +. Noise.perlin (p.x *. s) (p.y *. s) (p.z *. s))
  | Marble_pattern scale ->
      let q = Vec3.smul (1. /. scale) p in
      let s = Float.sin (Float.pi *. (q.x +. (4. *. Noise.turbulence q))) in
      0.5 *. (1. +. s)
  | Wood_pattern scale ->
      let q = Vec3.smul (1. /. scale) p in
      (* Rings around the y axis, wobbled by a third of a ring by noise that is slow along
         the axis (grain) and across it (irregular rings). *)
      let r =
        Float.sqrt ((q.x *. q.x) +. (q.z *. q.z))
        +. (0.35 *. Noise.perlin (0.5 *. q.x) (0.1 *. q.y) (0.5 *. q.z))
      in
      let f = if Float.is_finite r then r -. Float.floor r else 0. in
      (* A smooth ring profile: light wood rising to the dark late wood at the ring's end. *)
      f *. f *. (3. -. (2. *. f))

let eval (t : t) (p : Vec3.t) u v =
  match t with
  | Solid c -> c
  | Checker { c1; c2; size } ->
      let k = ifloor (p.x /. size) + ifloor (p.y /. size) + ifloor (p.z /. size) in
      if k land 1 = 0 then c1 else c2
  | Stripes { c1; c2; size } -> if ifloor (p.x /. size) land 1 = 0 then c1 else c2
  (* The two-colour forms compute their value in line (no boxed float on the way); the
     same formulas as pattern_value, which a test holds them to. *)
  | Noise { c1; c2; scale } ->
      let s = 1. /. scale in
      mix c1 c2 (0.5 *. (1. +. Noise.perlin (p.x *. s) (p.y *. s) (p.z *. s)))
  | Marble { c1; c2; scale } ->
      let q = Vec3.smul (1. /. scale) p in
      let s = Float.sin (Float.pi *. (q.x +. (4. *. Noise.turbulence q))) in
      mix c1 c2 (0.5 *. (1. +. s))
  | Wood { c1; c2; scale } ->
      let q = Vec3.smul (1. /. scale) p in
      let r =
        Float.sqrt ((q.x *. q.x) +. (q.z *. q.z))
        +. (0.35 *. Noise.perlin (0.5 *. q.x) (0.1 *. q.y) (0.5 *. q.z))
      in
      let f = if Float.is_finite r then r -. Float.floor r else 0. in
      mix c1 c2 (f *. f *. (3. -. (2. *. f)))
  | Mapped { pattern; map } ->
      let s = pattern_value pattern p in
      lookup map (if s > 0. then if s < 1. then s else 1. else 0.)
  | Gradient { axis; map } ->
      let x = Vec3.dot p axis in
      (* fract; a non-finite coordinate takes the map's start rather than NaN. *)
      let f = if Float.is_finite x then x -. Float.floor x else 0. in
      lookup map f
  | Image { image; scale } -> bilinear image (u *. scale) (v *. scale)

(* [mix] into the fragment's colour. *)
let[@inline] mix_into (f : Frag.t) (c1 : Color.t) (c2 : Color.t) s =
  let s = if s > 0. then if s < 1. then s else 1. else 0. in
  f.r <- c1.r +. (s *. (c2.r -. c1.r));
  f.g <- c1.g +. (s *. (c2.g -. c1.g));
  f.b <- c1.b +. (s *. (c2.b -. c1.b))

(* [eval] in scalars for the textures that pick or mix two colours; the others build the
   point and their colour. *)
let eval_into (t : t) (f : Frag.t) =
  match t with
  | Solid c -> Frag.set_color f c
  | Checker { c1; c2; size } ->
      let k = ifloor (f.x /. size) + ifloor (f.y /. size) + ifloor (f.z /. size) in
      Frag.set_color f (if k land 1 = 0 then c1 else c2)
  | Stripes { c1; c2; size } ->
      Frag.set_color f (if ifloor (f.x /. size) land 1 = 0 then c1 else c2)
  | Noise { c1; c2; scale } ->
      let s = 1. /. scale in
      mix_into f c1 c2 (0.5 *. (1. +. Noise.perlin (f.x *. s) (f.y *. s) (f.z *. s)))
  | Marble _ | Wood _ | Mapped _ | Gradient _ | Image _ ->
      Frag.set_color f (eval t (Frag.point f) f.u f.v)

let needs_uv : t -> bool = function
  | Image _ -> true
  | Solid _ | Checker _ | Stripes _ | Noise _ | Marble _ | Wood _ | Gradient _ | Mapped _
    ->
      false

let name : t -> string = function
  | Solid _ -> "solid"
  | Checker _ -> "checker"
  | Stripes _ -> "stripes"
  | Noise _ -> "noise"
  | Marble _ -> "marble"
  | Wood _ -> "wood"
  | Gradient _ -> "gradient"
  | Mapped { pattern = Noise_pattern _; _ } -> "noise"
  | Mapped { pattern = Marble_pattern _; _ } -> "marble"
  | Mapped { pattern = Wood_pattern _; _ } -> "wood"
  | Image _ -> "image"
