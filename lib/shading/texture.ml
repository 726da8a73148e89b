type t =
  | Solid of Color.t
  | Checker of { c1 : Color.t; c2 : Color.t; size : float }
  | Stripes of { c1 : Color.t; c2 : Color.t; size : float }

(* ⌊x⌋ as an int, clamped so that huge or non-finite coordinates cannot reach the
   unspecified cases of int_of_float; only the parity is used. *)
let ifloor x =
  let f = Float.floor x in
  if f >= 4e18 || f <= -4e18 || Float.is_nan f then 0 else int_of_float f

let eval t (p : Vec3.t) _u _v =
  match t with
  | Solid c -> c
  | Checker { c1; c2; size } ->
      let k = ifloor (p.x /. size) + ifloor (p.y /. size) + ifloor (p.z /. size) in
      if k land 1 = 0 then c1 else c2
  | Stripes { c1; c2; size } -> if ifloor (p.x /. size) land 1 = 0 then c1 else c2

let needs_uv = function Solid _ | Checker _ | Stripes _ -> false
let name = function Solid _ -> "solid" | Checker _ -> "checker" | Stripes _ -> "stripes"
