(* Growable flat arrays of what was read so far: [len] elements of [width] floats. *)
type floats = { mutable fl : Float.Array.t; mutable len : int; width : int }

let floats width = { fl = Float.Array.create 0; len = 0; width }

let grow_floats s =
  if s.width * (s.len + 1) > Float.Array.length s.fl then (
    let d = Float.Array.create (s.width * max 16 (2 * s.len)) in
    Float.Array.blit s.fl 0 d 0 (s.width * s.len);
    s.fl <- d)

let push3 s x y z =
  grow_floats s;
  let k = 3 * s.len in
  Float.Array.unsafe_set s.fl k x;
  Float.Array.unsafe_set s.fl (k + 1) y;
  Float.Array.unsafe_set s.fl (k + 2) z;
  s.len <- s.len + 1

let push2 s u v =
  grow_floats s;
  let k = 2 * s.len in
  Float.Array.unsafe_set s.fl k u;
  Float.Array.unsafe_set s.fl (k + 1) v;
  s.len <- s.len + 1

(* Triangles' corner indices, three 32-bit ints each. *)
type corners = { mutable ix : Trimesh.ints; mutable n : int }

let corners () = { ix = Trimesh.ints 0; n = 0 }

let push_corners s a b c =
  if 3 * (s.n + 1) > Bigarray.Array1.dim s.ix then (
    let d = Trimesh.ints (3 * max 16 (2 * s.n)) in
    Bigarray.Array1.blit s.ix (Bigarray.Array1.sub d 0 (3 * s.n));
    s.ix <- d);
  let k = 3 * s.n in
  Bigarray.Array1.unsafe_set s.ix k (Int32.of_int a);
  Bigarray.Array1.unsafe_set s.ix (k + 1) (Int32.of_int b);
  Bigarray.Array1.unsafe_set s.ix (k + 2) (Int32.of_int c);
  s.n <- s.n + 1

(* The normals' and texture coordinates' corners of a mesh that has none are only
   counted: the array is made, its first faces marked absent, at the first face that has
   them (a million faces without them would write 24 MB of −1 that are dropped). *)
let push_absent s =
  if Bigarray.Array1.dim s.ix = 0 then s.n <- s.n + 1 else push_corners s (-1) (-1) (-1)

let push_present s a b c =
  if Bigarray.Array1.dim s.ix = 0 && s.n > 0 then (
    let d = Trimesh.ints (3 * 2 * (s.n + 1)) in
    Bigarray.Array1.fill (Bigarray.Array1.sub d 0 (3 * s.n)) (-1l);
    s.ix <- d);
  push_corners s a b c

let trimmed s =
  if 3 * s.n = Bigarray.Array1.dim s.ix then s.ix
  else
    let d = Trimesh.ints (3 * s.n) in
    Bigarray.Array1.blit (Bigarray.Array1.sub s.ix 0 (3 * s.n)) d;
    d

let trimmed_floats s =
  if s.width * s.len = Float.Array.length s.fl then s.fl
  else Float.Array.sub s.fl 0 (s.width * s.len)

type mesh = {
  pos : Float.Array.t;
  nrm : Float.Array.t;
  tex : Float.Array.t;
  tv : Trimesh.ints;
  tn : Trimesh.ints;
  tt : Trimesh.ints;
}

let mesh vs vns vts tv tn tt =
  let some = function Some c -> trimmed c | None -> Trimesh.no_ints in
  {
    pos = trimmed_floats vs;
    nrm = trimmed_floats vns;
    tex = trimmed_floats vts;
    tv = trimmed tv;
    tn = some tn;
    tt = some tt;
  }

(* |(b − a) × (c − a)| for the vertices a, b, c of [p] (3 coordinates each), in floats (as
   Vec3.length of Vec3.cross would compute it). *)
let area (p : Float.Array.t) a b c =
  let a = 3 * a and b = 3 * b and c = 3 * c in
  let ax = Float.Array.get p a
  and ay = Float.Array.get p (a + 1)
  and az = Float.Array.get p (a + 2) in
  let ux = Float.Array.get p b -. ax
  and uy = Float.Array.get p (b + 1) -. ay
  and uz = Float.Array.get p (b + 2) -. az in
  let wx = Float.Array.get p c -. ax
  and wy = Float.Array.get p (c + 1) -. ay
  and wz = Float.Array.get p (c + 2) -. az in
  Vec3.length3
    ((uy *. wz) -. (uz *. wy))
    ((uz *. wx) -. (ux *. wz))
    ((ux *. wy) -. (uy *. wx))
