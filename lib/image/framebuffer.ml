type t = { width : int; height : int; data : Float.Array.t }

let create width height =
  { width; height; data = Float.Array.make (3 * width * height) 0. }

let get fb i j =
  let k = 3 * ((j * fb.width) + i) in
  Color.v (Float.Array.get fb.data k)
    (Float.Array.get fb.data (k + 1))
    (Float.Array.get fb.data (k + 2))

let set fb i j (c : Color.t) =
  let k = 3 * ((j * fb.width) + i) in
  Float.Array.set fb.data k c.r;
  Float.Array.set fb.data (k + 1) c.g;
  Float.Array.set fb.data (k + 2) c.b

let[@inline] set_rgb fb i j r g b =
  let k = 3 * ((j * fb.width) + i) in
  Float.Array.set fb.data k r;
  Float.Array.set fb.data (k + 1) g;
  Float.Array.set fb.data (k + 2) b
