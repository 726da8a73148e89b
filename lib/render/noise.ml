(* The permutation of 0..255 by a Fisher–Yates shuffle driven by a fixed 64-bit LCG:
   deterministic across runs and platforms, unlike Random. *)
let perm =
  let p = Array.init 256 Fun.id in
  let s = ref 0x2545F4914F6CDD1DL in
  for i = 255 downto 1 do
    s := Int64.add (Int64.mul !s 6364136223846793005L) 1442695040888963407L;
    let j = Int64.to_int (Int64.shift_right_logical !s 33) mod (i + 1) in
    let t = p.(i) in
    p.(i) <- p.(j);
    p.(j) <- t
  done;
  Array.init 512 (fun i -> p.(i land 255))

let[@inline] fade t = t *. t *. t *. ((t *. ((t *. 6.) -. 15.)) +. 10.)
let[@inline] lerp t a b = a +. (t *. (b -. a))

let[@inline] grad h x y z =
  let h = h land 15 in
  let u = if h < 8 then x else y in
  let v = if h < 4 then y else if h = 12 || h = 14 then x else z in
  (if h land 1 = 0 then u else -.u) +. if h land 2 = 0 then v else -.v

(* Lattice cell index modulo 256, safe for any finite or non-finite input. *)
let[@inline] cell f =
  if Float.is_finite f && Float.abs f < 1e15 then int_of_float f land 255 else 0

let perlin x y z =
  let fx = Float.floor x and fy = Float.floor y and fz = Float.floor z in
  let xi = cell fx and yi = cell fy and zi = cell fz in
  let x = x -. fx and y = y -. fy and z = z -. fz in
  let u = fade x and v = fade y and w = fade z in
  let p = perm in
  let a = p.(xi) + yi in
  let aa = p.(a) + zi and ab = p.(a + 1) + zi in
  let b = p.(xi + 1) + yi in
  let ba = p.(b) + zi and bb = p.(b + 1) + zi in
  lerp w
    (lerp v
       (lerp u (grad p.(aa) x y z) (grad p.(ba) (x -. 1.) y z))
       (lerp u (grad p.(ab) x (y -. 1.) z) (grad p.(bb) (x -. 1.) (y -. 1.) z)))
    (lerp v
       (lerp u (grad p.(aa + 1) x y (z -. 1.)) (grad p.(ba + 1) (x -. 1.) y (z -. 1.)))
       (lerp u
          (grad p.(ab + 1) x (y -. 1.) (z -. 1.))
          (grad p.(bb + 1) (x -. 1.) (y -. 1.) (z -. 1.))))

let turbulence ?(octaves = 6) (p : Vec3.t) =
  let acc = ref 0. and f = ref 1. in
  for _ = 1 to octaves do
    acc := !acc +. (Float.abs (perlin (p.x *. !f) (p.y *. !f) (p.z *. !f)) /. !f);
    f := !f *. 2.
  done;
  !acc

let gradient x y z =
  let e = 1e-4 in
  let d fx = fx /. (2. *. e) in
  Vec3.v
    (d (perlin (x +. e) y z -. perlin (x -. e) y z))
    (d (perlin x (y +. e) z -. perlin x (y -. e) z))
    (d (perlin x y (z +. e) -. perlin x y (z -. e)))
