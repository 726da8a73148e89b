let mix z =
  let z = z lxor (z lsr 30) * 0x3f58476d1ce4e5b9 in
  let z = z lxor (z lsr 27) * 0x14d049bb133111eb in
  z lxor (z lsr 31)

let combine h x = mix (h + (x * 0x1e3779b97f4a7c15) + 0x2545f4914f6cdd1d)
let to_unit h = Float.of_int ((h land max_int) lsr 10) *. 0x1p-52

let of_float x =
  let x = if x = 0. then 0. else x in
  to_unit (mix (Int64.to_int (Int64.bits_of_float x)))
