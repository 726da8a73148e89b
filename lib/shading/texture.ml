type t =
  | Solid of Color.t
  | Checker of { c1 : Color.t; c2 : Color.t; size : float }
  | Stripes of { c1 : Color.t; c2 : Color.t; size : float }
  | Noise of { c1 : Color.t; c2 : Color.t; scale : float }
  | Marble of { c1 : Color.t; c2 : Color.t; scale : float }
  | Wood of { c1 : Color.t; c2 : Color.t; scale : float }
  | Image of { img : Image.t; scale : float }

(* ⌊x⌋ as an int, clamped so that huge or non-finite coordinates cannot reach the
   unspecified cases of int_of_float; only the parity is used. *)
let ifloor x =
  let f = Float.floor x in
  if f >= 4e18 || f <= -4e18 || Float.is_nan f then 0 else int_of_float f

(* s in [0, 1] (NaN counts as 0) from c1 to c2. *)
let mix (c1 : Color.t) (c2 : Color.t) s =
  let s = if s > 0. then if s < 1. then s else 1. else 0. in
  Color.v (c1.r +. (s *. (c2.r -. c1.r))) (c1.g +. (s *. (c2.g -. c1.g))) (c1.b +. (s *. (c2.b -. c1.b)))

(* Wrap x into [0, n): integer coordinates of a tiled image. *)
let wrap i n =
  let k = i mod n in
  if k < 0 then k + n else k

let bilinear (img : Image.t) u v =
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

let eval t (p : Vec3.t) u v =
  match t with
  | Solid c -> c
  | Checker { c1; c2; size } ->
      let k = ifloor (p.x /. size) + ifloor (p.y /. size) + ifloor (p.z /. size) in
      if k land 1 = 0 then c1 else c2
  | Stripes { c1; c2; size } -> if ifloor (p.x /. size) land 1 = 0 then c1 else c2
  | Noise { c1; c2; scale } ->
      let s = 1. /. scale in
      mix c1 c2 (0.5 *. (1. +. Noise.perlin (p.x *. s) (p.y *. s) (p.z *. s)))
  | Marble { c1; c2; scale } ->
      let q = Vec3.smul (1. /. scale) p in
      let s = Float.sin (Float.pi *. (q.x +. (4. *. Noise.turbulence q))) in
      mix c1 c2 (0.5 *. (1. +. s))
  | Wood { c1; c2; scale } ->
      let q = Vec3.smul (1. /. scale) p in
      (* Rings around the y axis, wobbled by a third of a ring by noise that is slow along
         the axis (grain) and across it (irregular rings). *)
      let r = Float.sqrt ((q.x *. q.x) +. (q.z *. q.z)) +. (0.35 *. Noise.perlin (0.5 *. q.x) (0.1 *. q.y) (0.5 *. q.z)) in
      let f = if Float.is_finite r then r -. Float.floor r else 0. in
      (* A smooth ring profile: light wood rising to the dark late wood at the ring's end. *)
      mix c1 c2 (f *. f *. (3. -. (2. *. f)))
  | Image { img; scale } -> bilinear img (u *. scale) (v *. scale)

let needs_uv = function Image _ -> true | Solid _ | Checker _ | Stripes _ | Noise _ | Marble _ | Wood _ -> false

let name = function
  | Solid _ -> "solid"
  | Checker _ -> "checker"
  | Stripes _ -> "stripes"
  | Noise _ -> "noise"
  | Marble _ -> "marble"
  | Wood _ -> "wood"
  | Image _ -> "image"
