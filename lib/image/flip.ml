(* LDR FLIP in five passes over flat planes: decode to YCxCz, filter rows, filter columns
   and take the colour difference, filter rows of the achromatic channel by the feature
   kernels, filter its columns and combine. Every plane is a Float.Array of width·height
   values, row by row; loops read and write them without allocating. *)

let pixels_per_degree ~distance ~pixels ~width =
  distance *. (pixels /. width) *. Float.pi /. 180.

let default_ppd = pixels_per_degree ~distance:0.7 ~pixels:3840. ~width:0.7

(* The exponents and the redistribution of the colour error, and the width of the feature
   detectors in degrees. *)
let qc = 0.7
let pc = 0.4
let pt = 0.95
let gw = 0.082
let qf = 0.5

(* The contrast sensitivity functions, a·sqrt(π/b)·exp(-π²x²/b) with x in degrees: one
   Gaussian for the achromatic (Y) and red-green (Cx) channels, two for blue-yellow (Cz). *)
let a_y = 1.
let b_y = 0.0047
let a_cx = 1.
let b_cx = 0.0053
let a_cz1 = 34.1
let b_cz1 = 0.04
let a_cz2 = 13.5
let b_cz2 = 0.025

(* D65 white, and linear sRGB to CIE XYZ and back. *)
let white_x = 0.950428545
let white_z = 1.088900371
let m11 = 10135552. /. 24577794.
let m12 = 8788810. /. 24577794.
let m13 = 4435075. /. 24577794.
let m21 = 2613072. /. 12288897.
let m22 = 8788810. /. 12288897.
let m23 = 887015. /. 12288897.
let m31 = 1425312. /. 73733382.
let m32 = 8788810. /. 73733382.
let m33 = 70074185. /. 73733382.
let n11 = 3.241003275
let n12 = -1.537398934
let n13 = -0.498615861
let n21 = -0.969224334
let n22 = 1.875930071
let n23 = 0.041554224
let n31 = 0.055639423
let n32 = -0.204011202
let n33 = 1.057148933

let srgb_to_linear c =
  if c <= 0.04045 then c /. 12.92 else Float.pow ((c +. 0.055) /. 1.055) 2.4

let linear_of_byte =
  Float.Array.init 256 (fun i -> srgb_to_linear (Float.of_int i /. 255.))

(* The planes l, a, b hold filtered YCxCz colours; each becomes, in place, the colour
   clamped to the RGB cube in linear RGB, as Hunt-adjusted CIE L*a*b*. *)
let to_hunt_lab (l : Float.Array.t) (a : Float.Array.t) (b : Float.Array.t) =
  let d = 6. /. 29. in
  let d3 = d *. d *. d and slope = 1. /. (3. *. d *. d) and offset = 4. /. 29. in
  for k = 0 to Float.Array.length l - 1 do
    let yy = (Float.Array.unsafe_get l k +. 16.) /. 116. in
    let xx = (yy +. (Float.Array.unsafe_get a k /. 500.)) *. white_x
    and zz = (yy -. (Float.Array.unsafe_get b k /. 200.)) *. white_z in
    let r = (n11 *. xx) +. (n12 *. yy) +. (n13 *. zz)
    and g = (n21 *. xx) +. (n22 *. yy) +. (n23 *. zz)
    and bl = (n31 *. xx) +. (n32 *. yy) +. (n33 *. zz) in
    let r = if r < 0. then 0. else if r > 1. then 1. else r
    and g = if g < 0. then 0. else if g > 1. then 1. else g
    and bl = if bl < 0. then 0. else if bl > 1. then 1. else bl in
    let x = ((m11 *. r) +. (m12 *. g) +. (m13 *. bl)) /. white_x
    and y = (m21 *. r) +. (m22 *. g) +. (m23 *. bl)
    and z = ((m31 *. r) +. (m32 *. g) +. (m33 *. bl)) /. white_z in
    let fx = if x > d3 then Float.cbrt x else (x *. slope) +. offset
    and fy = if y > d3 then Float.cbrt y else (y *. slope) +. offset
    and fz = if z > d3 then Float.cbrt z else (z *. slope) +. offset in
    let ll = (116. *. fy) -. 16. in
    Float.Array.unsafe_set l k ll;
    Float.Array.unsafe_set a k (0.01 *. ll *. (500. *. (fx -. fy)));
    Float.Array.unsafe_set b k (0.01 *. ll *. (200. *. (fy -. fz)))
  done

(* Linear RGB to YCxCz, into the planes at k. *)
let set_ycxcz (py : Float.Array.t) (pcx : Float.Array.t) (pcz : Float.Array.t) k r g b =
  let x = ((m11 *. r) +. (m12 *. g) +. (m13 *. b)) /. white_x in
  let y = (m21 *. r) +. (m22 *. g) +. (m23 *. b) in
  let z = ((m31 *. r) +. (m32 *. g) +. (m33 *. b)) /. white_z in
  Float.Array.unsafe_set py k ((116. *. y) -. 16.);
  Float.Array.unsafe_set pcx k (500. *. (x -. y));
  Float.Array.unsafe_set pcz k (200. *. (y -. z))
[@@inline]

(* An image's YCxCz planes, from its encoded bytes. *)
let to_ycxcz bytes py pcx pcz =
  let lin = linear_of_byte in
  for k = 0 to Float.Array.length py - 1 do
    let j = 3 * k in
    set_ycxcz py pcx pcz k
      (Float.Array.unsafe_get lin (Char.code (Bytes.unsafe_get bytes j)))
      (Float.Array.unsafe_get lin (Char.code (Bytes.unsafe_get bytes (j + 1))))
      (Float.Array.unsafe_get lin (Char.code (Bytes.unsafe_get bytes (j + 2))))
  done

(* The HyAB distance of the Hunt-adjusted L*a*b* colours at k in two sets of planes,
   raised to qc. *)
let distance (l : Float.Array.t) (a : Float.Array.t) (b : Float.Array.t)
    (l' : Float.Array.t) (a' : Float.Array.t) (b' : Float.Array.t) k =
  let da = Float.Array.unsafe_get a k -. Float.Array.unsafe_get a' k
  and db = Float.Array.unsafe_get b k -. Float.Array.unsafe_get b' k in
  Float.pow
    (Float.abs (Float.Array.unsafe_get l k -. Float.Array.unsafe_get l' k)
    +. Float.sqrt ((da *. da) +. (db *. db)))
    qc
[@@inline]

(* The largest colour distance: green against blue. *)
let cmax =
  let plane () = Float.Array.make 1 0. in
  let l = plane () and a = plane () and b = plane () in
  let l' = plane () and a' = plane () and b' = plane () in
  set_ycxcz l a b 0 0. 1. 0.;
  set_ycxcz l' a' b' 0 0. 0. 1.;
  to_hunt_lab l a b;
  to_hunt_lab l' a' b';
  distance l a b l' a' b' 0

(* Kernels of 2·radius + 1 taps. *)

let spatial_radius ppd =
  let b = Float.max (Float.max b_y b_cx) (Float.max b_cz1 b_cz2) in
  Float.to_int (Float.ceil (3. *. Float.sqrt (b /. (2. *. Float.pi *. Float.pi)) *. ppd))

(* The 2-D contrast sensitivity filter a·(π/b)·exp(-π²(x²+y²)/b) is the product of two
   taps of sqrt(a·sqrt(π/b))·exp(-π²x²/b). The achromatic and red-green kernels are scaled
   to sum to 1; the blue-yellow filter is a sum of two such products, both scaled so that
   their 2-D sum is 1. *)
let spatial_kernels ppd =
  let r = spatial_radius ppd in
  let kernel a b =
    Float.Array.init
      ((2 * r) + 1)
      (fun i ->
        let x = Float.of_int (i - r) /. ppd in
        Float.sqrt (a *. Float.sqrt (Float.pi /. b))
        *. Float.exp (-.Float.pi *. Float.pi *. x *. x /. b))
  in
  let ky = kernel a_y b_y and kcx = kernel a_cx b_cx in
  let kcz1 = kernel a_cz1 b_cz1 and kcz2 = kernel a_cz2 b_cz2 in
  let sum k = Float.Array.fold_left ( +. ) 0. k in
  let scale s k = Float.Array.map_inplace (fun v -> v /. s) k in
  scale (sum ky) ky;
  scale (sum kcx) kcx;
  let s1 = sum kcz1 and s2 = sum kcz2 in
  let s = Float.sqrt ((s1 *. s1) +. (s2 *. s2)) in
  scale s kcz1;
  scale s kcz2;
  (r, ky, kcx, kcz1, kcz2)

(* A Gaussian of standard deviation gw/2 degrees and its first and second derivatives;
   the Gaussian sums to 1, each derivative's positive taps to 1 and negative ones to -1. *)
let feature_kernels ppd =
  let sd = 0.5 *. gw *. ppd in
  let r = Float.to_int (Float.ceil (3. *. sd)) in
  let tap f = Float.Array.init ((2 * r) + 1) (fun i -> f (Float.of_int (i - r))) in
  let gauss x = Float.exp (-.(x *. x) /. (2. *. sd *. sd)) in
  let g = tap gauss in
  let dg = tap (fun x -> -.x *. gauss x) in
  let ddg = tap (fun x -> ((x *. x /. (sd *. sd)) -. 1.) *. gauss x) in
  let sum p k =
    Float.Array.fold_left (fun s v -> if p v then s +. Float.abs v else s) 0. k
  in
  let sg = sum (fun _ -> true) g in
  Float.Array.map_inplace (fun v -> v /. sg) g;
  let split k =
    let pos = sum (fun v -> v > 0.) k and neg = sum (fun v -> v < 0.) k in
    Float.Array.map_inplace (fun v -> if v > 0. then v /. pos else v /. neg) k
  in
  split dg;
  split ddg;
  (r, g, dg, ddg)

(* out := the rows of src filtered by k (radius r), the borders repeated. *)
let filter_rows w h r (k : Float.Array.t) (src : Float.Array.t) (out : Float.Array.t) =
  for y = 0 to h - 1 do
    let row = y * w in
    for x = 0 to w - 1 do
      let s = ref 0. in
      if x >= r && x + r < w then
        (* Inside, the taps need no clamping. *)
        for i = -r to r do
          s :=
            !s
            +. Float.Array.unsafe_get k (i + r)
               *. Float.Array.unsafe_get src (row + x + i)
        done
      else
        for i = -r to r do
          let xi = x + i in
          let xi = if xi < 0 then 0 else if xi >= w then w - 1 else xi in
          s :=
            !s
            +. (Float.Array.unsafe_get k (i + r) *. Float.Array.unsafe_get src (row + xi))
        done;
      Float.Array.unsafe_set out (row + x) !s
    done
  done

(* out := the columns of src filtered by k (radius r), plus out itself with [add]. Row by
   row of taps, so that memory is read in order; each pixel's sum is still taken tap by
   tap from the top. *)
let filter_columns ?(add = false) w h r (k : Float.Array.t) (src : Float.Array.t)
    (out : Float.Array.t) =
  for y = 0 to h - 1 do
    let row = y * w in
    if not add then Float.Array.fill out row w 0.;
    for i = -r to r do
      let yi = y + i in
      let src_row = (if yi < 0 then 0 else if yi >= h then h - 1 else yi) * w in
      let ki = Float.Array.unsafe_get k (i + r) in
      for x = 0 to w - 1 do
        Float.Array.unsafe_set out (row + x)
          (Float.Array.unsafe_get out (row + x)
          +. (ki *. Float.Array.unsafe_get src (src_row + x)))
      done
    done
  done

(* The colour error of every pixel, redistributed to 0–1, into err. The YCxCz planes are
   kept; t holds 8 scratch planes. *)
let colour_error ppd w h (yr, cxr, czr) (yt, cxt, czt) (t : Float.Array.t array) err =
  let r, ky, kcx, kcz1, kcz2 = spatial_kernels ppd in
  (* Rows into t.(0..3), then columns into (l, a, b) = t.(4..6), per image. *)
  let filter (y, cx, cz) (l, a, b) =
    filter_rows w h r ky y t.(0);
    filter_rows w h r kcx cx t.(1);
    filter_rows w h r kcz1 cz t.(2);
    filter_rows w h r kcz2 cz t.(3);
    filter_columns w h r ky t.(0) l;
    filter_columns w h r kcx t.(1) a;
    filter_columns w h r kcz1 t.(2) b;
    filter_columns ~add:true w h r kcz2 t.(3) b;
    to_hunt_lab l a b
  in
  let lr = t.(4) and ar = t.(5) and br = t.(6) in
  filter (yr, cxr, czr) (lr, ar, br);
  (* The test's L*a*b* in err and in the two planes whose rows are no longer needed. *)
  let lt = err and at = t.(7) and bt = t.(0) in
  filter (yt, cxt, czt) (lt, at, bt);
  let pccmax = pc *. cmax in
  for k = 0 to (w * h) - 1 do
    let d = distance lr ar br lt at bt k in
    Float.Array.unsafe_set err k
      (if d < pccmax then d *. pt /. pccmax
       else pt +. ((d -. pccmax) /. (cmax -. pccmax) *. (1. -. pt)))
  done

let error_map ?(ppd = default_ppd) (w, h, ref_bytes) (w', h', test_bytes) =
  if w <> w' || h <> h' then invalid_arg "Flip.error_map: the images differ in size";
  if not (ppd > 0. && Float.is_finite ppd) then
    invalid_arg "Flip.error_map: pixels per degree must be positive";
  let n = w * h in
  let plane () = Float.Array.make n 0. in
  let ycxcz bytes =
    let p = (plane (), plane (), plane ()) in
    let y, cx, cz = p in
    to_ycxcz bytes y cx cz;
    p
  in
  let ((y_r, _, _) as ref_planes) = ycxcz ref_bytes in
  let ((y_t, _, _) as test_planes) = ycxcz test_bytes in
  let t = Array.init 8 (fun _ -> plane ()) in
  let err = plane () in
  colour_error ppd w h ref_planes test_planes t err;
  (* The features, on the achromatic channel scaled to 0–1: rows of the reference into
     t.(0..2), of the test into t.(3..5); columns into t.(6..7) and back over the rows'
     planes once they are read. *)
  let fr, g, dg, ddg = feature_kernels ppd in
  let unit p =
    for k = 0 to n - 1 do
      Float.Array.unsafe_set p k ((Float.Array.unsafe_get p k +. 16.) /. 116.)
    done
  in
  unit y_r;
  unit y_t;
  let rows y (pd, pdd, pg) =
    filter_rows w h fr dg y pd;
    filter_rows w h fr ddg y pdd;
    filter_rows w h fr g y pg
  in
  rows y_r (t.(0), t.(1), t.(2));
  rows y_t (t.(3), t.(4), t.(5));
  (* Per image: the edge strength into one plane, the point strength into another. *)
  let strengths (pd, pdd, pg) (edge, point) =
    (* dx, dy into edge and y's plane; ddx, ddy into point and a spare plane. *)
    filter_columns w h fr g pd edge;
    filter_columns w h fr dg pg pd;
    filter_columns w h fr g pdd point;
    filter_columns w h fr ddg pg pdd;
    for k = 0 to n - 1 do
      let dx = Float.Array.unsafe_get edge k and dy = Float.Array.unsafe_get pd k in
      let ddx = Float.Array.unsafe_get point k and ddy = Float.Array.unsafe_get pdd k in
      Float.Array.unsafe_set edge k (Float.sqrt ((dx *. dx) +. (dy *. dy)));
      Float.Array.unsafe_set point k (Float.sqrt ((ddx *. ddx) +. (ddy *. ddy)))
    done
  in
  strengths (t.(0), t.(1), t.(2)) (t.(6), t.(7));
  strengths (t.(3), t.(4), t.(5)) (y_r, y_t);
  let edge_r = t.(6) and point_r = t.(7) and edge_t = y_r and point_t = y_t in
  let norm = 1. /. Float.sqrt 2. in
  for k = 0 to n - 1 do
    let edge =
      Float.abs (Float.Array.unsafe_get edge_r k -. Float.Array.unsafe_get edge_t k)
    and point =
      Float.abs (Float.Array.unsafe_get point_r k -. Float.Array.unsafe_get point_t k)
    in
    let f = Float.pow (norm *. Float.max edge point) qf in
    Float.Array.unsafe_set err k (Float.pow (Float.Array.unsafe_get err k) (1. -. f))
  done;
  err

let mean m =
  let s = ref 0. in
  for i = 0 to Float.Array.length m - 1 do
    s := !s +. Float.Array.unsafe_get m i
  done;
  if Float.Array.length m = 0 then 0. else !s /. Float.of_int (Float.Array.length m)

let grey m =
  let n = Float.Array.length m in
  let out = Bytes.create (3 * n) in
  for i = 0 to n - 1 do
    let e = Float.Array.unsafe_get m i in
    let e = if e < 0. then 0. else if e > 1. then 1. else e in
    let v = Char.unsafe_chr (Float.to_int (Float.round (255. *. e))) in
    Bytes.unsafe_set out (3 * i) v;
    Bytes.unsafe_set out ((3 * i) + 1) v;
    Bytes.unsafe_set out ((3 * i) + 2) v
  done;
  out
