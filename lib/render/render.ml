let tile_size = 32
let strided_tile_size = 8

(* The bits of a sample's image coordinate, to hash: a sample is named by its place. *)
let[@inline] bits x = Int64.to_int (Int64.bits_of_float x)

(* Whether a pixel's camera samples are random draws (jittered, at hashed instants of
   the shutter, through hashed lens points), so that two halves of them are two
   independent estimates of the pixel. *)
let[@inline] camera_noise (sc : Scene.t) =
  sc.settings.jitter || Array.length sc.moments > 0 || sc.features.depth_of_field

let noise_estimated (sc : Scene.t) =
  let s = sc.settings in
  sc.features.soft_shadows
  || camera_noise sc
     && (s.samples >= 2 || s.adaptive > 0.
        || (sc.features.depth_of_field && sc.view.lens_samples >= 2))

(* A tile's scratch: the shading scratch, where each sample leaves its colour (in its
   fragment); in [coarse] the four samples of an adaptive pixel's first pass (0–11), room
   to compare them (12–16) and the image point of a sample through a camera other than
   the pinhole (17, 18); in [pin] the pinhole ray of a depth-of-field sample; in [nz],
   for the noise estimate, a sample's half-difference of the area lights (0–2) and
   variance of the mean of its lens samples (3–5), a pixel's sum of the first (6–8),
   signed sum of its samples' colours, + for half A and − for half B (9–11), and its
   variance (12–14), kept only where [noisy] ({!noise_estimated}). Made for each tile, so
   that no two domains share one. *)
type scratch = {
  shade : Shade.scratch;
  coarse : Float.Array.t;
  pin : Probe.t;
  nz : Float.Array.t;
  noisy : bool;
}

let scratch sc =
  {
    shade = Shade.scratch ();
    coarse = Float.Array.make 19 0.;
    pin = Probe.create ();
    nz = Float.Array.make 15 0.;
    noisy = noise_estimated sc;
  }

let[@inline] nz_add a k (y : float) =
  Float.Array.unsafe_set a k (Float.Array.unsafe_get a k +. y)

let[@inline] nz_zero a k =
  Float.Array.unsafe_set a k 0.;
  Float.Array.unsafe_set a (k + 1) 0.;
  Float.Array.unsafe_set a (k + 2) 0.

let[@inline] sq x = x *. x

(* The noise estimate's sums over a pixel's samples (or a sample's lens rays), at
   nz.(into): the one just taken, its half-difference of the area lights at nz.(from)
   added to nz.(into + 0–2), its colour added to nz.(into + 3–5) in half A (p + q even),
   subtracted in half B. *)
let[@inline] noise_sample nz ~from ~into (f : Frag.t) p q =
  nz_add nz into (Float.Array.unsafe_get nz from);
  nz_add nz (into + 1) (Float.Array.unsafe_get nz (from + 1));
  nz_add nz (into + 2) (Float.Array.unsafe_get nz (from + 2));
  let sign = if (p + q) land 1 = 0 then 1. else -1. in
  nz_add nz (into + 3) (sign *. f.r);
  nz_add nz (into + 4) (sign *. f.g);
  nz_add nz (into + 5) (sign *. f.b)

(* A sample through any camera but the plain pinhole: an orthographic or fisheye ray
   (a fisheye point outside its circle sees what a ray along f that hits nothing sees),
   and with depth of field the average of its n×n lens rays. Lens point (a, b) lies in
   its stratum by a hash of frame, pixel, sample and (a, b), so the image does not depend
   on which domain renders which tile. Its colour goes into the fragment. *)
let camera_sample (sc : Scene.t) (st : Task.t) scr i j =
  let s = sc.settings and c = sc.view in
  let f = Shade.frag scr.shade in
  let x = Float.Array.unsafe_get scr.coarse 17
  and y = Float.Array.unsafe_get scr.coarse 18 in
  let nz = scr.nz in
  if not (Camera.in_view c ~width:s.width ~height:s.height x y) then (
    Frag.set_color f (Shade.miss sc c.f);
    nz_zero nz 0;
    nz_zero nz 3)
  else if not (Camera.depth_of_field c) then (
    Camera.ray_into c ~width:s.width ~height:s.height x y (Shade.probe scr.shade);
    st.primary <- st.primary + 1;
    Shade.trace_into sc st scr.shade 1;
    Shade.half_diff_into scr.shade nz 0;
    nz_zero nz 3)
  else
    let pin = scr.pin in
    Camera.ray_into c ~width:s.width ~height:s.height x y pin;
    let n = c.lens_samples in
    let h0 =
      Hash.combine
        (Hash.combine (Hash.combine (Hash.combine (Hash.mix sc.frame) i) j) (bits x))
        (bits y)
    in
    let ar = ref 0. and ag = ref 0. and ab = ref 0. in
    (* For the noise estimate: the lens rays' half-differences of the area lights
       summed, and their colours summed + in half A (a + b even) and − in half B. *)
    nz_zero nz 0;
    nz_zero nz 3;
    for a = 0 to n - 1 do
      for b = 0 to n - 1 do
        let hk = Hash.combine h0 ((a * 4096) + b) in
        st.primary <- st.primary + 1;
        Camera.lens_ray_into c pin a b
          (Hash.to_unit (Hash.combine hk 2))
          (Hash.to_unit (Hash.combine hk 3))
          (Shade.probe scr.shade);
        Shade.trace_into sc st scr.shade 1;
        ar := !ar +. f.r;
        ag := !ag +. f.g;
        ab := !ab +. f.b;
        Shade.half_diff_into scr.shade nz 12;
        noise_sample nz ~from:12 ~into:0 f a b
      done
    done;
    let k = 1. /. Float.of_int (n * n) in
    f.r <- k *. !ar;
    f.g <- k *. !ag;
    f.b <- k *. !ab;
    for ch = 0 to 2 do
      Float.Array.unsafe_set nz ch (k *. Float.Array.unsafe_get nz ch);
      Float.Array.unsafe_set nz (3 + ch)
        (if n < 2 then 0.
         else
           sq
             (Shade.half_diff (n * n)
                (if ch = 0 then !ar else if ch = 1 then !ag else !ab)
                (Float.Array.unsafe_get nz (3 + ch))))
    done

(* The scene that sample (p, q) of the n×n grid of pixel (i, j) sees: the scene itself,
   or with an open shutter one of its m moments (the scenes at the shutter's instants).
   The grid's samples take the n² slots of the shutter, in m equal strata, as a Latin
   square does: slot n·((p + q) mod n) + p, so that every row and every column of the
   grid spans the shutter; the slots are turned by a hash of (frame, pixel), and each
   sample lies inside its slot by a hash of (frame, pixel, sample), as the other samples
   are drawn, so that the image does not depend on which domain renders which tile. *)
let[@inline] moment (sc : Scene.t) i j p q n =
  let ms = sc.moments in
  let m = Array.length ms in
  if m = 0 then sc
  else
    let count = n * n in
    let h = Hash.combine (Hash.combine (Hash.mix sc.frame) i) j in
    let turn = Hash.combine h 4 land max_int mod count in
    let slot = ((n * ((p + q) mod n)) + p + turn) mod count in
    let u = Hash.to_unit (Hash.combine (Hash.combine h ((p * 4096) + q)) 5) in
    let k =
      Float.to_int ((Float.of_int slot +. u) *. Float.of_int m /. Float.of_int count)
    in
    Array.unsafe_get ms (if k < m then k else m - 1)

(* One sample at image point (x, y), sample (p, q) of the pixel's n×n grid, its colour
   into the fragment. Inlined, so that x and y are not boxed on the way to the camera. *)
let[@inline] sample (sc : Scene.t) (st : Task.t) scr i j p q n x y =
  let sc = moment sc i j p q n in
  let s = sc.settings in
  if Camera.pinhole_perspective sc.view then (
    st.primary <- st.primary + 1;
    Camera.ray_into sc.view ~width:s.width ~height:s.height x y (Shade.probe scr.shade);
    Shade.trace_into sc st scr.shade 1;
    if scr.noisy then Shade.half_diff_into scr.shade scr.nz 0)
  else (
    (* Through the scratch: arguments would be boxed. *)
    Float.Array.unsafe_set scr.coarse 17 x;
    Float.Array.unsafe_set scr.coarse 18 y;
    camera_sample sc st scr i j);
  let f = Shade.frag scr.shade in
  if not (Float.is_finite f.r && Float.is_finite f.g && Float.is_finite f.b) then (
    st.bad_samples <- st.bad_samples + 1;
    if Option.is_none st.first_bad then st.first_bad <- Some (i, j);
    Frag.set_color f s.background;
    nz_zero scr.nz 0;
    nz_zero scr.nz 3)

(* Offset of sample (p, q) of n inside pixel (i, j): the sub-cell centre, or a hashed
   point inside the sub-cell with jitter. *)
let[@inline] sub_offset (sc : Scene.t) n i j p q axis =
  let nf = Float.of_int n in
  if not sc.settings.jitter then (Float.of_int p +. 0.5) /. nf
  else
    let h =
      Hash.combine
        (Hash.combine
           (Hash.combine (Hash.combine (Hash.mix sc.frame) i) j)
           ((p * 4096) + q))
        axis
    in
    (Float.of_int p +. Hash.to_unit h) /. nf

(* The variance of channel [ch] of the mean of a pixel's [m] ≥ 2 samples whose colours in
   that channel sum to [s], into nz.(12 + ch): the square of the area lights' mean
   half-difference, and where the samples are random draws that of the two halves of
   the samples. *)
let[@inline] noise_channel (sc : Scene.t) nz m ch s =
  let l = Float.Array.unsafe_get nz (6 + ch) /. Float.of_int m in
  let c =
    if camera_noise sc then sq (Shade.half_diff m s (Float.Array.unsafe_get nz (9 + ch)))
    else 0.
  in
  Float.Array.unsafe_set nz (12 + ch) ((l *. l) +. c)

let grid sc st scr i j n =
  let f = Shade.frag scr.shade in
  let ar = ref 0. and ag = ref 0. and ab = ref 0. in
  let noisy = scr.noisy and nz = scr.nz in
  if noisy then (
    nz_zero nz 6;
    nz_zero nz 9);
  for q = 0 to n - 1 do
    for p = 0 to n - 1 do
      let x = Float.of_int i +. sub_offset sc n i j p q 0 in
      let y = Float.of_int j +. sub_offset sc n i j q p 1 in
      sample sc st scr i j p q n x y;
      ar := !ar +. f.r;
      ag := !ag +. f.g;
      ab := !ab +. f.b;
      if noisy then noise_sample nz ~from:0 ~into:6 f p q
    done
  done;
  let k = 1. /. Float.of_int (n * n) in
  f.r <- k *. !ar;
  f.g <- k *. !ag;
  f.b <- k *. !ab;
  if noisy then (
    noise_channel sc nz (n * n) 0 !ar;
    noise_channel sc nz (n * n) 1 !ag;
    noise_channel sc nz (n * n) 2 !ab)

(* c.(i) <- Float.max c.(i) y and c.(i) <- Float.min c.(i) y, the stdlib's definitions
   written as assignments: a float-valued [if] of boxed and unboxed branches would box. *)
let[@inline] max_into c i (y : float) =
  let x = Float.Array.unsafe_get c i in
  if y > x || ((not (Float.sign_bit y)) && Float.sign_bit x) then (
    if not (Float.is_nan x) then Float.Array.unsafe_set c i y)
  else if Float.is_nan y then Float.Array.unsafe_set c i y

let[@inline] min_into c i (y : float) =
  let x = Float.Array.unsafe_get c i in
  if y > x || ((not (Float.sign_bit y)) && Float.sign_bit x) then (
    if Float.is_nan y then Float.Array.unsafe_set c i y)
  else if not (Float.is_nan x) then Float.Array.unsafe_set c i y

(* The spread max − min of channel [k] of the four coarse samples (at 0, 3, 6, 9), folded
   as [Array.fold_left Float.max neg_infinity] and [Float.min infinity] would, into
   c.(12 + k); the work in c.(15) and c.(16). *)
let[@inline] spread c k =
  Float.Array.unsafe_set c 15 Float.neg_infinity;
  Float.Array.unsafe_set c 16 Float.infinity;
  for s = 0 to 3 do
    let v = Float.Array.unsafe_get c ((3 * s) + k) in
    max_into c 15 v;
    min_into c 16 v
  done;
  Float.Array.unsafe_set c (12 + k)
    (Float.Array.unsafe_get c 15 -. Float.Array.unsafe_get c 16)

(* Float.max r (Float.max g b) of the three spreads, into c.(15). *)
let[@inline] contrast c =
  spread c 0;
  spread c 1;
  spread c 2;
  Float.Array.unsafe_set c 16 (Float.Array.unsafe_get c 13);
  max_into c 16 (Float.Array.unsafe_get c 14);
  Float.Array.unsafe_set c 15 (Float.Array.unsafe_get c 12);
  max_into c 15 (Float.Array.unsafe_get c 16)

(* Channel [k] of the four coarse samples summed from black, as
   [Array.fold_left Color.add Color.black] would. *)
let[@inline] sum4 c k =
  0. +. Float.Array.unsafe_get c k
  +. Float.Array.unsafe_get c (3 + k)
  +. Float.Array.unsafe_get c (6 + k)
  +. Float.Array.unsafe_get c (9 + k)

(* The colour of pixel (i, j), into the fragment. *)
let pixel_into (sc : Scene.t) st scr i j =
  let s = sc.settings in
  let f = Shade.frag scr.shade in
  let noisy = scr.noisy and nz = scr.nz in
  if s.adaptive > 0. then (
    let c = scr.coarse in
    if noisy then (
      nz_zero nz 6;
      nz_zero nz 9);
    for q = 0 to 1 do
      for p = 0 to 1 do
        let x = Float.of_int i +. sub_offset sc 2 i j p q 0 in
        let y = Float.of_int j +. sub_offset sc 2 i j q p 1 in
        sample sc st scr i j p q 2 x y;
        let k = 3 * ((2 * q) + p) in
        Float.Array.unsafe_set c k f.r;
        Float.Array.unsafe_set c (k + 1) f.g;
        Float.Array.unsafe_set c (k + 2) f.b;
        if noisy then noise_sample nz ~from:0 ~into:6 f p q
      done
    done;
    contrast c;
    if Float.Array.unsafe_get c 15 > s.adaptive then grid sc st scr i j (max s.samples 4)
    else (
      f.r <- 0.25 *. sum4 c 0;
      f.g <- 0.25 *. sum4 c 1;
      f.b <- 0.25 *. sum4 c 2;
      if noisy then (
        noise_channel sc nz 4 0 (sum4 c 0);
        noise_channel sc nz 4 1 (sum4 c 1);
        noise_channel sc nz 4 2 (sum4 c 2))))
  else if s.samples = 1 then (
    sample sc st scr i j 0 0 1
      (Float.of_int i +. sub_offset sc 1 i j 0 0 0)
      (Float.of_int j +. sub_offset sc 1 i j 0 0 1);
    (* One camera sample: its lens samples' halves, if it has any. *)
    if noisy then
      for ch = 0 to 2 do
        Float.Array.unsafe_set nz (12 + ch)
          (sq (Float.Array.unsafe_get nz ch)
          +. if sc.features.depth_of_field then Float.Array.unsafe_get nz (3 + ch) else 0.
          )
      done)
  else grid sc st scr i j s.samples

let pixel sc st i j =
  let scr = scratch sc in
  pixel_into sc st scr i j;
  let f = Shade.frag scr.shade in
  Color.v f.r f.g f.b

(* The share of pixel (i, j)'s sample points whose primary ray hits a surface: its
   alpha. The points are those of the n×n grid (jittered as the colour's are); with
   adaptive sampling, those of the refined max(n, 4)² grid in every pixel. *)
let coverage (sc : Scene.t) i j =
  let s = sc.settings in
  let n = if s.adaptive > 0. then max s.samples 4 else s.samples in
  let hits = ref 0 and r = Probe.create () and ax = Accel.domain_scratch () in
  for q = 0 to n - 1 do
    for p = 0 to n - 1 do
      let x = Float.of_int i +. sub_offset sc n i j p q 0 in
      let y = Float.of_int j +. sub_offset sc n i j q p 1 in
      let at = moment sc i j p q n in
      Probe.of_ray r (Camera.ray at.view ~width:s.width ~height:s.height x y);
      r.p_tmin <- 0.;
      r.p_tmax <- Float.infinity;
      if Accel.any ax at.accel r ~opaque:false ~slot:(-1) ~mask:(-1) then incr hits
    done
  done;
  Float.of_int !hits /. Float.of_int (n * n)

type reuse =
  | Watch of { box : Float.Array.t; mask : Bytes.t }
  | Only of { mask : Bytes.t; base : Framebuffer.t }

let check_reuse (fb : Framebuffer.t) = function
  | None -> ()
  | Some (Watch { box; mask }) ->
      if Float.Array.length box <> 6 || Bytes.length mask <> fb.width * fb.height then
        invalid_arg "Render: a watch's box or mask has the wrong size"
  | Some (Only { mask; base }) ->
      if
        Bytes.length mask <> fb.width * fb.height
        || base.width <> fb.width || base.height <> fb.height
      then invalid_arg "Render: a reuse's mask or image has the wrong size"

(* Column or row [i] of an image of one sample per [k]×[k] block: the block's middle
   pixel of the full image, or its last one where the block is cut by the edge. *)
let[@inline] strided k n i = if k = 1 then i else min (n - 1) ((i * k) + (k / 2))

(* A channel of value [v] and estimated variance [var] into the task's noise sums: the
   standard error σ = √var in 8-bit encoded steps, 255·(curve(v + σ) − curve(v − σ))/2
   (the slope of the encoding times σ, where it is smooth), squared, in
   {!Counters.noise_unit}s rounded to the nearest. *)
let[@inline] noise_count (st : Task.t) gamma v var =
  let sd = Float.sqrt var in
  let e = 127.5 *. (Image.curve gamma (v +. sd) -. Image.curve gamma (v -. sd)) in
  st.noise_sq <- st.noise_sq + Float.to_int ((e *. e *. Counters.noise_unit) +. 0.5);
  st.noise_n <- st.noise_n + 1

let render_tile ?alpha ?reuse ?(stride = 1) sc st fb x0 y0 x1 y1 =
  check_reuse fb reuse;
  if Option.is_some alpha && Option.is_some reuse then
    invalid_arg "Render: alpha with a reuse (coverage is not watched)";
  if stride < 1 || (stride > 1 && (Option.is_some alpha || Option.is_some reuse)) then
    invalid_arg "Render: a stride below 1, or with alpha or a reuse";
  let sw = sc.Scene.settings.width and sh = sc.settings.height in
  let scr = scratch sc in
  let f = Shade.frag scr.shade in
  let ax = Shade.accel_scratch scr.shade in
  let w = fb.Framebuffer.width in
  let noisy = scr.noisy and gamma = sc.settings.gamma in
  (match reuse with Some (Watch { box; _ }) -> Accel.watch ax (Some box) | _ -> ());
  (* The work deep in queries that is not handed [st] (a CSG object's crossings) counts
     into it, and so polls its token too; a poll there may leave a query half done, which
     leaves nothing for the next query to undo. *)
  Fun.protect
    ~finally:(fun () -> Accel.watch ax None)
    (fun () ->
      Task.with_current st @@ fun () ->
      for j = y0 to y1 - 1 do
        for i = x0 to x1 - 1 do
          let p = (j * w) + i in
          match reuse with
          | Some (Only { mask; base }) when Bytes.get mask p = '\000' ->
              (* Untouched by what changes: the base's pixel, as it would be again. *)
              for c = 0 to 2 do
                Float.Array.set fb.data
                  ((3 * p) + c)
                  (Float.Array.get base.data ((3 * p) + c))
              done
          | _ -> (
              Accel.untouch ax;
              pixel_into sc st scr (strided stride sw i) (strided stride sh j);
              Framebuffer.set_rgb fb i j f.r f.g f.b;
              if noisy then (
                noise_count st gamma f.r (Float.Array.unsafe_get scr.nz 12);
                noise_count st gamma f.g (Float.Array.unsafe_get scr.nz 13);
                noise_count st gamma f.b (Float.Array.unsafe_get scr.nz 14));
              (match reuse with
              | Some (Watch { mask; _ }) ->
                  Bytes.set mask p (if Accel.touched ax then '\001' else '\000')
              | _ -> ());
              match alpha with
              | Some a -> Float.Array.set a p (coverage sc i j)
              | None -> ())
        done
      done)

let size ?(stride = 1) (sc : Scene.t) =
  let k = max 1 stride in
  ((sc.settings.width + k - 1) / k, (sc.settings.height + k - 1) / k)

(* A strided image has few pixels: smaller tiles spread them over the domains. *)
let side = function Some k when k > 1 -> strided_tile_size | _ -> tile_size

(* Tile [k] of the scene's image (of its image of one sample per [stride]×[stride] block),
   row-major; with [region], of the tiles that meet it, clipped to it: the same grid
   either way, so a pixel is computed the same. Found by arithmetic, so that a caller
   that renders an image unit by unit (a lancer-mpi rank: thousands of small calls) never
   builds the whole list. *)

let tile_count ?region ?stride (sc : Scene.t) =
  let w, h = size ?stride sc in
  let tile_size = side stride in
  let span a b = if b <= a then 0 else ((b - 1) / tile_size) - (a / tile_size) + 1 in
  match (region : Image.region option) with
  | None -> span 0 w * span 0 h
  | Some r -> span (max 0 r.x0) (min w r.x1) * span (max 0 r.y0) (min h r.y1)

let tile ?region ?stride (sc : Scene.t) k =
  let w, h = size ?stride sc in
  let tile_size = side stride in
  let x0, y0, x1, y1 =
    match (region : Image.region option) with
    | None -> (0, 0, w, h)
    | Some r -> (max 0 r.x0, max 0 r.y0, min w r.x1, min h r.y1)
  in
  let tx0 = x0 / tile_size and ty0 = y0 / tile_size in
  let nx = ((x1 - 1) / tile_size) - tx0 + 1 in
  let tx = tx0 + (k mod nx) and ty = ty0 + (k / nx) in
  ( max x0 (tx * tile_size),
    max y0 (ty * tile_size),
    min x1 ((tx + 1) * tile_size),
    min y1 ((ty + 1) * tile_size) )

let tiles ?region ?stride sc =
  Array.init (tile_count ?region ?stride sc) (tile ?region ?stride sc)

(* The one tile loop: tiles [idxs] of the scene (of the region's tiles with [region]),
   each written only by the task that renders it, with its own counters; the token is
   polled before each tile and inside it. *)
let render_tiles ?(cancel = Cancel.create ()) ?pool ?(on_tile = fun _ _ _ -> ()) ?region
    ?alpha ?reuse ?stride (sc : Scene.t) fb idxs =
  if Option.is_some region && Option.is_some stride then
    invalid_arg "Render: a region with a stride";
  let n = Array.length idxs in
  let tasks = Array.init n (fun _ -> Task.create ~cancel ()) in
  let done_ = Atomic.make 0 in
  let work k =
    Cancel.check cancel;
    let x0, y0, x1, y1 = tile ?region ?stride sc idxs.(k) in
    render_tile ?alpha ?reuse ?stride sc tasks.(k) fb x0 y0 x1 y1;
    on_tile (Atomic.fetch_and_add done_ 1 + 1) idxs.(k) (Task.counters tasks.(k))
  in
  (match pool with
  | None ->
      for k = 0 to n - 1 do
        work k
      done
  | Some pool -> Pool.parallel_for pool n work);
  (* A cancellation after the last tile started: the result is not to be used. *)
  Cancel.check cancel;
  Counters.sum (Array.map Task.counters tasks)

let render ?cancel ?pool ?(on_tile = fun _ _ _ -> ()) ?region ?alpha ?reuse ?stride
    (sc : Scene.t) =
  let w, h = size ?stride sc in
  (* The framebuffer lives as long as the render: allocated at the default pace, its
     floats (6.2 M words at 1920×1080) counted as work for the collector, which marked
     the scene's primitives in two more major cycles for them (field_100000: 67 M
     instructions of 6.4 G). *)
  let fb = Pace.within Pace.all_live (fun () -> Framebuffer.create w h) in
  (* Outside a region: the background, and alpha 0. *)
  if region <> None then
    for j = 0 to fb.height - 1 do
      for i = 0 to fb.width - 1 do
        Framebuffer.set fb i j sc.settings.background
      done
    done;
  Option.iter (fun a -> Float.Array.fill a 0 (Float.Array.length a) 0.) alpha;
  let n = tile_count ?region ?stride sc in
  let st =
    render_tiles ?cancel ?pool ?region ?alpha ?reuse ?stride
      ~on_tile:(fun d _ st -> on_tile d n (Counters.total_rays st))
      sc fb (Array.init n Fun.id)
  in
  (fb, st)

(* Every minor collection stops all domains together, so one domain that the system
   pauses (another program wants the core) holds up the others at each one. A larger
   minor heap makes those rendezvous rarer. On this project's 2-core machine, with other
   busy processes beside it, a two-domain render of scenes/bench/mirrors_10.rts took
   8.0 s with the default 256k words and 1.6 s with 2M words (16 MB) per domain (one
   domain: 1.2 s); unloaded, the two are equal. *)
let parallel_minor_heap_words = 2 * 1024 * 1024
let address_space_limit = Address_space.limit

(* The runtime reserves address space for the minor heaps of every domain it could run
   (128) as soon as their size is set: 2M words would reserve 2 GiB, and under a smaller
   ulimit -v the runtime aborts ("Not enough heap memory to reserve minor heaps"). Under
   a limit, the reservation is kept to an eighth of it. *)
let minor_heap_words_for limit =
  match limit with
  | None -> parallel_minor_heap_words
  | Some bytes -> min parallel_minor_heap_words (bytes / 8 / (Sys.word_size / 8) / 128)

let with_pool ?(cancel = Cancel.create ()) n f =
  if n <= 1 then f None
  else
    let g = Gc.get () in
    let words = minor_heap_words_for (address_space_limit ()) in
    if g.minor_heap_size < words then Gc.set { g with minor_heap_size = words };
    (* An exception raised by a signal handler inside the pool's synchronisation could
       leave a lock held: while the pool lives, an interrupt only cancels the token, and
       the work stops at its next poll. *)
    let r =
      Cancel.deferring cancel (fun () ->
          let pool = Pool.create n in
          Fun.protect ~finally:(fun () -> Pool.teardown pool) (fun () -> f (Some pool)))
    in
    (* An interrupt that came when no poll was left to see it. *)
    Cancel.check cancel;
    r
