(* Float.min and Float.max, bit for bit: two equal floats other than zeros have the same
   bits, so only zeros of either sign and NaN go to them (a C call for the sign). *)
let[@inline] min (x : float) y =
  if x < y then x else if y < x then y else if x = y && x <> 0. then x else Float.min x y

let[@inline] max (x : float) y =
  if x > y then x else if y > x then y else if x = y && x <> 0. then x else Float.max x y

(* For a positive normal t, t·2⁻⁵² is between one and two of its ulps: t plus it rounds
   to t + ulp or t + 2 ulps (or overflows to +∞). Anything else, where it would round
   back to t, takes [Float.succ]. *)
let[@inline] above (t : float) =
  let b = t +. (t *. 0x1p-52) in
  if b > t then b else Float.succ t
