let[@inline] min (x : float) y = if x < y then x else if y < x then y else Float.min x y
let[@inline] max (x : float) y = if x > y then x else if y > x then y else Float.max x y
