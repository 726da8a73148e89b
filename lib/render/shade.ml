(* [Vec3.max_abs] and [offset] of points held as scalars, the same results without the
   stdlib's C calls ({!Floats}). *)
let[@inline] max_abs3 x y z =
  Floats.max (Float.abs x) (Floats.max (Float.abs y) (Float.abs z))

let[@inline] offset_s px py pz ox oy oz =
  1e-9 *. Floats.max 1e-300 (Floats.max (max_abs3 px py pz) (max_abs3 ox oy oz))

let offset (p : Vec3.t) (o : Vec3.t) = offset_s p.x p.y p.z o.x o.y o.z

(* The light of one shading step, as scalars in a flat record of floats (nothing boxes):
   the diffuse and specular sum (ar, ag, ab); the transmittance of the last shadow ray
   or area light (tr, tg, tb); the point shaded (px, py, pz) and where its shadow rays
   start (lx, ly, lz), for the area lights; Schlick's F0 (f0) of the last index of
   refraction it was computed for (f0_ior), since a glass scene asks it again at every
   crossing. With soft shadows also the half-difference ({!area_transmittance}) of the
   last area light's transmittance (ur, ug, ub), the weight in the camera sample's
   colour of the light of the step being shaded (wl), and the half-difference of that
   colour summed so far (nr, ng, nb): the colour is a weighted sum of the steps' light,
   linear in the area lights' transmittances, so the same weights carry their
   half-differences. *)
type acc = {
  mutable ar : float;
  mutable ag : float;
  mutable ab : float;
  mutable tr : float;
  mutable tg : float;
  mutable tb : float;
  mutable px : float;
  mutable py : float;
  mutable pz : float;
  mutable lx : float;
  mutable ly : float;
  mutable lz : float;
  mutable f0_ior : float;
  mutable f0 : float;
  mutable ur : float;
  mutable ug : float;
  mutable ub : float;
  mutable nr : float;
  mutable ng : float;
  mutable nb : float;
  mutable wl : float;
}

(* A domain's scratch: the ray being traced ([q]) and what its query found ([hit]), the
   shadow ray ([sq]) and its crossings ([xb]), the fragment that shapes and textures
   answer into (and where a trace leaves its colour), the light sums, the factors of the
   crossings, and the queries' scratch of the domain it is made on ([ax]: no look-up per
   query). A shading step copies what it needs into locals before it traces again, so one
   scratch serves every depth. With soft shadows, [wts.(d)] is the weight in the camera
   sample's colour of the step at depth d (the product of the reflected or transmitted
   shares and fog that lead to it). *)
type scratch = {
  q : Probe.t;
  hit : Walk.hit;
  sq : Probe.t;
  xb : Walk.crossings;
  f : Frag.t;
  acc : acc;
  xs : crossings;
  ax : Accel.scratch;
  mutable wts : Float.Array.t;
  mutable disk : Float.Array.t;
      (** for an area light of [disk_n]×[disk_n] samples: the cosines and sines of the
          angles 2π(b+½)/n, then the square roots √((a+½)/n), n of each *)
  mutable disk_n : int;
}

(* The factors of a shadow ray's transparent crossings, 4 floats each (t, then
   transparency · albedo in r, g, b), in the order the structure visits them, and the
   channels (bits 1, 2, 4) in which some factor is zero. *)
and crossings = { mutable fs : Float.Array.t; mutable n : int; mutable zero : int }

(* Albedo C at world point p on object o with geometric normal n, into (f.r, f.g, f.b):
   the texture is evaluated in object space at p − δ·n (doc/reference/shading.md, section 6). *)
let[@inline] albedo_into (o : Primitive.t) (f : Frag.t) px py pz nx ny nz delta =
  match o.material.texture with
  | None -> Frag.set_color f o.color
  | Some tex ->
      (* N is the geometric normal: a smooth mesh's interpolated normal is not. *)
      (match o.shape with
      | Shape.Triangle { normals = Some _; tn; _ } ->
          Frag.set_normal f (Transform.normal o.transform tn)
      | _ ->
          f.nx <- nx;
          f.ny <- ny;
          f.nz <- nz);
      let k = -.delta in
      Frag.set_point f (px +. (k *. f.nx)) (py +. (k *. f.ny)) (pz +. (k *. f.nz));
      Primitive.texture_point_into o f;
      if Texture.needs_uv tex then (
        let tx = f.x and ty = f.y and tz = f.z in
        Frag.set_point f px py pz;
        Primitive.uv_into o f;
        Frag.set_point f tx ty tz)
      else (
        f.u <- 0.;
        f.v <- 0.);
      Texture.eval_into tex f

(* The shadow ray [q] crossing transparent object [o] at t = q.p_t, on its part ([leaf],
   [face]): its factor, transparency · albedo there, recorded in [xs]; whether the product
   is black whatever the other factors (a zero in every channel: stop). *)
let crossing (q : Probe.t) (f : Frag.t) xs (o : Primitive.t) ~leaf ~face =
  let t = q.p_t in
  let ox = q.ox and oy = q.oy and oz = q.oz in
  (* A CSG object's crossing shades with the leaf it lies on, a mesh's with its face. *)
  let o = Primitive.surface o ~leaf ~face in
  let px = ox +. (t *. q.dx) and py = oy +. (t *. q.dy) and pz = oz +. (t *. q.dz) in
  Frag.set_point f px py pz;
  Primitive.normal_into o f;
  albedo_into o f px py pz f.nx f.ny f.nz (offset_s px py pz ox oy oz);
  let tau = o.material.transparency in
  let fr = tau *. f.r and fg = tau *. f.g and fb = tau *. f.b in
  if 4 * (xs.n + 1) > Float.Array.length xs.fs then (
    let d = Float.Array.make (8 * (xs.n + 1)) 0. in
    Float.Array.blit xs.fs 0 d 0 (4 * xs.n);
    xs.fs <- d);
  let k = 4 * xs.n in
  Float.Array.unsafe_set xs.fs k t;
  Float.Array.unsafe_set xs.fs (k + 1) fr;
  Float.Array.unsafe_set xs.fs (k + 2) fg;
  Float.Array.unsafe_set xs.fs (k + 3) fb;
  xs.n <- xs.n + 1;
  if fr = 0. then xs.zero <- xs.zero lor 1;
  if fg = 0. then xs.zero <- xs.zero lor 2;
  if fb = 0. then xs.zero <- xs.zero lor 4;
  xs.zero = 7

(* Factor [i] of [xs] before factor [j] in the product: by t, then by the factors
   themselves, so that the order is that of the crossings' values alone (a NaN, which
   makes the product NaN in any order, counts as equal to anything). *)
let[@inline] before (fs : Float.Array.t) i j =
  let r = ref false and go = ref true and k = ref 0 in
  while !go && !k < 4 do
    let x = Float.Array.unsafe_get fs ((4 * i) + !k)
    and y = Float.Array.unsafe_get fs ((4 * j) + !k) in
    if x < y then (
      r := true;
      go := false)
    else if x > y then go := false
    else incr k
  done;
  !r

(* Sort the [n] factors of [fs] into that order by insertion (nothing allocated). *)
let insertion_sort fs n =
  for i = 1 to n - 1 do
    let j = ref i in
    while !j > 0 && before fs !j (!j - 1) do
      for k = 0 to 3 do
        let a = (4 * !j) + k and b = (4 * (!j - 1)) + k in
        let x = Float.Array.unsafe_get fs a in
        Float.Array.unsafe_set fs a (Float.Array.unsafe_get fs b);
        Float.Array.unsafe_set fs b x
      done;
      decr j
    done
  done

(* Sort the factors of [xs] into that order: by insertion where a shadow ray crosses a
   few, else by a merge sort of their indices. *)
let sort_crossings xs =
  let fs = xs.fs in
  (* Two factors multiply to the same bits in either order, one or none trivially. *)
  if xs.n <= 2 then ()
  else if xs.n <= 32 then insertion_sort fs xs.n
  else
    let order = Array.init xs.n Fun.id in
    Array.stable_sort
      (fun i j -> if before fs i j then -1 else if before fs j i then 1 else 0)
      order;
    let sorted = Float.Array.make (4 * xs.n) 0. in
    Array.iteri (fun r i -> Float.Array.blit fs (4 * i) sorted (4 * r) 4) order;
    Float.Array.blit sorted 0 fs 0 (4 * xs.n)

let scratch () =
  let sq = Probe.create () and f = Frag.create () in
  let acc =
    {
      ar = 0.;
      ag = 0.;
      ab = 0.;
      tr = 0.;
      tg = 0.;
      tb = 0.;
      px = 0.;
      py = 0.;
      pz = 0.;
      lx = 0.;
      ly = 0.;
      lz = 0.;
      f0_ior = Float.nan;
      f0 = 0.;
      ur = 0.;
      ug = 0.;
      ub = 0.;
      nr = 0.;
      ng = 0.;
      nb = 0.;
      wl = 0.;
    }
  in
  let xs = { fs = Float.Array.make 32 0.; n = 0; zero = 0 } in
  {
    q = Probe.create ();
    hit = Walk.hit ();
    sq;
    xb = Walk.crossings ();
    f;
    acc;
    xs;
    ax = Accel.domain_scratch ();
    wts = Float.Array.make 8 0.;
    disk = Float.Array.create 0;
    disk_n = 0;
  }

let probe scr = scr.q
let frag scr = scr.f

let[@inline] half_diff_into scr a k =
  Float.Array.unsafe_set a k scr.acc.nr;
  Float.Array.unsafe_set a (k + 1) scr.acc.ng;
  Float.Array.unsafe_set a (k + 2) scr.acc.nb

let accel_scratch scr = scr.ax

(* Where no opaque surface blocks the shadow ray that [scr.sq] holds (the occlusion
   query leaves its origin, direction and interval as they were): the product over the
   transparent surfaces crossed of transparency · albedo, from white, into
   acc.(tr, tg, tb). The factors are multiplied in the order of their values (t first),
   not in the order a structure visits them: floating-point products depend on their
   order in the last bit, and a frame of an animation walks its still and moving parts
   in two structures where a still walks one. *)
let transparent_into (sc : Scene.t) scr =
  let acc = scr.acc and xs = scr.xs and xb = scr.xb and q = scr.sq in
  xs.n <- 0;
  xs.zero <- 0;
  Accel.crossings scr.ax sc.accel q ~transparent:true xb;
  (if xb.n > 0 then
     let k = ref 0 and ts = xb.ts and ps = xb.parts in
     while !k < xb.n && xs.zero <> 7 do
       let c = 3 * !k in
       q.p_t <- Float.Array.get ts !k;
       ignore (crossing q scr.f xs sc.objects.(ps.(c)) ~leaf:ps.(c + 1) ~face:ps.(c + 2));
       incr k
     done);
  if xs.zero = 7 then (
    acc.tr <- 0.;
    acc.tg <- 0.;
    acc.tb <- 0.)
  else (
    sort_crossings xs;
    let fs = xs.fs in
    acc.tr <- 1.;
    acc.tg <- 1.;
    acc.tb <- 1.;
    for i = 0 to xs.n - 1 do
      let k = 4 * i in
      acc.tr <- acc.tr *. Float.Array.unsafe_get fs (k + 1);
      acc.tg <- acc.tg *. Float.Array.unsafe_get fs (k + 2);
      acc.tb <- acc.tb *. Float.Array.unsafe_get fs (k + 3)
    done)

(* Transmittance from (ox, oy, oz) along the unit direction (dx, dy, dz) up to [dist],
   into acc.(tr, tg, tb). Opaque surfaces first, by the occlusion query, which allocates
   nothing and answers most shadow rays; only where none blocks and some surface is
   transparent are the crossings of the transparent ones folded. [slot] is the light's
   index. *)
let[@inline] shadow_into (sc : Scene.t) (st : Task.t) slot scr ox oy oz dx dy dz dist
    ~mask =
  st.shadow <- st.shadow + 1;
  Task.tick st;
  let q = scr.sq and acc = scr.acc in
  q.ox <- ox;
  q.oy <- oy;
  q.oz <- oz;
  q.dx <- dx;
  q.dy <- dy;
  q.dz <- dz;
  q.p_tmin <- 0.;
  q.p_tmax <- dist;
  if Accel.any scr.ax sc.accel q ~opaque:true ~slot ~mask then (
    acc.tr <- 0.;
    acc.tg <- 0.;
    acc.tb <- 0.)
  else if not sc.features.refraction then (
    acc.tr <- 1.;
    acc.tg <- 1.;
    acc.tb <- 1.)
  else transparent_into sc scr

(* With S = S_A + S_B and Δ = S_A − S_B of m ≥ 2 samples: m_A = (S + Δ)/2n_A and
   m_B = (S − Δ)/2n_B, n_A = ⌈m/2⌉, n_B = ⌊m/2⌋. *)
let[@inline] half_diff m s d =
  let na = (m + 1) / 2 and nb = m / 2 in
  let w = Float.sqrt (Float.of_int (na * nb)) /. Float.of_int m in
  w *. (((s +. d) /. Float.of_int (2 * na)) -. ((s -. d) /. Float.of_int (2 * nb)))

(* Stratified points on the disk of radius [radius] facing the point p = acc.(px, py, pz),
   centred on the light: sample (a, b) of n×n sits at radius R·√((a+½)/n) and angle
   2π(b+½)/n. The pattern is the same for every pixel, so soft shadows are deterministic
   and noise-free in time. The frame is w = (position − p)/|position − p|, e1 =
   normalize(h × w) with h the x axis (the y axis when |w.x| ≥ 0.9), e2 = w × e1;
   everything is computed in scalars, with the operations of the vector form. The shadow
   rays start at acc.(lx, ly, lz); the mean transmittance goes into acc.(tr, tg, tb).
   The samples fall into two interleaved halves, A where a + b is even (⌈n²/2⌉ of them)
   and B where it is odd (⌊n²/2⌋), whose means are two estimates of the same
   transmittance; their half-difference (T_A − T_B)·√(n_A·n_B)/n² goes into
   acc.(ur, ug, ub): its square estimates the variance of the mean (a quarter of
   (T_A − T_B)² for equal halves), as if the samples were independent. The sum of the
   mean is taken as it would be without it, so the image does not change. *)
let area_transmittance sc st slot scr (position : Vec3.t) radius n =
  let acc = scr.acc in
  let lx = position.x -. acc.px
  and ly = position.y -. acc.py
  and lz = position.z -. acc.pz in
  let ox = acc.lx and oy = acc.ly and oz = acc.lz in
  let ll = Vec3.length3 lx ly lz in
  let k = 1. /. ll in
  let wx = if ll = 0. then 0. else k *. lx
  and wy = if ll = 0. then 0. else k *. ly
  and wz = if ll = 0. then 0. else k *. lz in
  let hx = if Float.abs wx < 0.9 then 1. else 0. in
  let hy = 1. -. hx and hz = 0. in
  let cx = (hy *. wz) -. (hz *. wy)
  and cy = (hz *. wx) -. (hx *. wz)
  and cz = (hx *. wy) -. (hy *. wx) in
  let cl = Vec3.length3 cx cy cz in
  let k = 1. /. cl in
  let e1x = if cl = 0. then 0. else k *. cx
  and e1y = if cl = 0. then 0. else k *. cy
  and e1z = if cl = 0. then 0. else k *. cz in
  let e2x = (wy *. e1z) -. (wz *. e1y)
  and e2y = (wz *. e1x) -. (wx *. e1z)
  and e2z = (wx *. e1y) -. (wy *. e1x) in
  let sr = ref 0. and sg = ref 0. and sb = ref 0. in
  let dr = ref 0. and dg = ref 0. and db = ref 0. in
  let nf = Float.of_int n in
  (* The pattern's n angles and n radii, computed as the samples use them, once for as
     long as the lights have n×n samples. *)
  if scr.disk_n <> n then (
    if Float.Array.length scr.disk < 3 * n then scr.disk <- Float.Array.create (3 * n);
    for b = 0 to n - 1 do
      let th = 2. *. Float.pi *. (Float.of_int b +. 0.5) /. nf in
      Float.Array.unsafe_set scr.disk b (Float.cos th);
      Float.Array.unsafe_set scr.disk (n + b) (Float.sin th)
    done;
    for a = 0 to n - 1 do
      Float.Array.unsafe_set scr.disk
        ((2 * n) + a)
        (Float.sqrt ((Float.of_int a +. 0.5) /. nf))
    done;
    scr.disk_n <- n);
  let disk = scr.disk in
  (* Every sample is at most [radius] from [position]: the objects the rays from the
     origin may cross, found once for all of them. *)
  let mask =
    let q = scr.sq in
    q.ox <- ox;
    q.oy <- oy;
    q.oz <- oz;
    Accel.shadow_mask sc.Scene.accel q position radius
  in
  for a = 0 to n - 1 do
    for b = 0 to n - 1 do
      let rr = radius *. Float.Array.unsafe_get disk ((2 * n) + a) in
      let u = rr *. Float.Array.unsafe_get disk b
      and v = rr *. Float.Array.unsafe_get disk (n + b) in
      let dx = position.x +. (u *. e1x) +. (v *. e2x) -. ox
      and dy = position.y +. (u *. e1y) +. (v *. e2y) -. oy
      and dz = position.z +. (u *. e1z) +. (v *. e2z) -. oz in
      let dist = Vec3.length3 dx dy dz in
      let k = 1. /. dist in
      shadow_into sc st slot scr ox oy oz (k *. dx) (k *. dy) (k *. dz) dist ~mask;
      sr := !sr +. acc.tr;
      sg := !sg +. acc.tg;
      sb := !sb +. acc.tb;
      if (a + b) land 1 = 0 then (
        dr := !dr +. acc.tr;
        dg := !dg +. acc.tg;
        db := !db +. acc.tb)
      else (
        dr := !dr -. acc.tr;
        dg := !dg -. acc.tg;
        db := !db -. acc.tb)
    done
  done;
  let s = 1. /. (nf *. nf) in
  acc.tr <- s *. !sr;
  acc.tg <- s *. !sg;
  acc.tb <- s *. !sb;
  acc.ur <- half_diff (n * n) !sr !dr;
  acc.ug <- half_diff (n * n) !sg !dg;
  acc.ub <- half_diff (n * n) !sb !db

let reflect d nf = Vec3.madd d (-2. *. Vec3.dot d nf) nf

(* Snell–Descartes: with c = −D·Nf and k = 1 − η²(1 − c²) ≥ 0, T = η·D + (η·c − √k)·Nf.
   [shade] computes c and k itself (Fresnel needs them) and the direction in scalars. *)
let refract d nf eta =
  let c = -.Vec3.dot d nf in
  let k = 1. -. (eta *. eta *. (1. -. (c *. c))) in
  if k < 0. then None
  else Some (Vec3.madd (Vec3.smul eta d) ((eta *. c) -. Float.sqrt k) nf)

(* A channel of tint(k) = (1 − k)·(1, 1, 1) + k·C for C's channel [c]: white at k = 0, the
   albedo at k = 1, exactly. *)
let[@inline] tint k c = 1. -. k +. (k *. c)

(* The half-difference of the light (kr, kg, kb) · ia · color · T of an area light of
   transmittance T, weighted as the step's light, into acc.(nr, ng, nb). *)
let[@inline] half_diff_light acc kr kg kb ia (color : Color.t) =
  let iw = ia *. acc.wl in
  acc.nr <- acc.nr +. (kr *. (iw *. color.r *. acc.ur));
  acc.ng <- acc.ng +. (kg *. (iw *. color.g *. acc.ug));
  acc.nb <- acc.nb +. (kb *. (iw *. color.b *. acc.ub))

(* The diffuse and specular light of one light with unit direction (ldx, ldy, ldz) towards
   it, added into acc.(ar, ag, ab) (doc/reference/shading.md, section 4), for albedo (cr, cg, cb),
   the normal facing the ray (nfx, nfy, nfz), the ray's direction (dx, dy, dz) and shadow
   rays from (lox, loy, loz). Inlined into [shade]: its floats stay unboxed and nothing is
   allocated. [area_n] > 0 makes it an area light sampled n×n over [radius] around
   [position]; [slot] is the light's index. *)
let[@inline] light_term (sc : Scene.t) st slot scr (m : Material.t) cr cg cb nfx nfy nfz
    dx dy dz lox loy loz ldx ldy ldz dist att (color : Color.t) intensity position radius
    area_n =
  let acc = scr.acc in
  let ndl = (nfx *. ldx) +. (nfy *. ldy) +. (nfz *. ldz) in
  if ndl > 0. then (
    if not sc.features.shadows then (
      acc.tr <- 1.;
      acc.tg <- 1.;
      acc.tb <- 1.)
    else if area_n > 0 then area_transmittance sc st slot scr position radius area_n
    else shadow_into sc st slot scr lox loy loz ldx ldy ldz dist ~mask:(-1);
    let trr = acc.tr and trg = acc.tg and trb = acc.tb in
    if trr > 0. || trg > 0. || trb > 0. then (
      let ia = intensity *. att in
      let er = ia *. color.r *. trr
      and eg = ia *. color.g *. trg
      and eb = ia *. color.b *. trb in
      let kd = m.diffuse *. ndl in
      acc.ar <- acc.ar +. (kd *. (cr *. er));
      acc.ag <- acc.ag +. (kd *. (cg *. eg));
      acc.ab <- acc.ab +. (kd *. (cb *. eb));
      (* The light is linear in the transmittance: its half-difference, the same way. *)
      let soft = area_n > 0 && sc.features.shadows in
      if soft then half_diff_light acc (kd *. cr) (kd *. cg) (kd *. cb) ia color;
      if m.specular > 0. then
        let k2 = 2. *. ndl in
        let rx = (k2 *. nfx) -. ldx
        and ry = (k2 *. nfy) -. ldy
        and rz = (k2 *. nfz) -. ldz in
        (* R·V with V = −D *)
        let rv = (rx *. -.dx) +. (ry *. -.dy) +. (rz *. -.dz) in
        (* max(0, R·V)^shininess: nothing when R·V ≤ 0, except that x⁰ = 1. *)
        if rv > 0. || m.shininess = 0. then
          let ks = m.specular *. Float.pow (if rv > 0. then rv else 0.) m.shininess in
          let mu = m.metallic in
          if mu = 0. then (
            acc.ar <- acc.ar +. (ks *. er);
            acc.ag <- acc.ag +. (ks *. eg);
            acc.ab <- acc.ab +. (ks *. eb);
            if soft then half_diff_light acc ks ks ks ia color)
          else (
            (* A metal's highlight: E ⊙ tint(μ). *)
            acc.ar <- acc.ar +. (ks *. er *. tint mu cr);
            acc.ag <- acc.ag +. (ks *. eg *. tint mu cg);
            acc.ab <- acc.ab +. (ks *. eb *. tint mu cb);
            if soft then
              half_diff_light acc
                (ks *. tint mu cr)
                (ks *. tint mu cg)
                (ks *. tint mu cb)
                ia color)))

(* [Settings.background_along] for a direction whose y component is [dy], into the
   fragment's colour. *)
let[@inline] background_into (s : Settings.t) (f : Frag.t) dy =
  match s.sky with
  | None -> Frag.set_color f s.background
  | Some { horizon = h; zenith = z } ->
      let t = if dy > 0. then dy else 0. in
      f.r <- h.r +. (t *. (z.r -. h.r));
      f.g <- h.g +. (t *. (z.g -. h.g));
      f.b <- h.b +. (t *. (z.b -. h.b))

(* [Settings.fog_segment] of length [t] applied to the fragment's colour, in place. *)
let[@inline] fog_into (fg : Settings.fog) t (f : Frag.t) =
  let e = Float.exp (-.t /. fg.distance) in
  let k = 1. -. e in
  let fc = fg.color in
  f.r <- (f.r *. e) +. (fc.r *. k);
  f.g <- (f.g *. e) +. (fc.g *. k);
  f.b <- (f.b *. e) +. (fc.b *. k)

let miss (sc : Scene.t) d =
  let s = sc.settings in
  match s.fog with
  | None -> Settings.background_along s d
  | Some f -> Settings.fog_segment f Float.infinity (Settings.background_along s d)

(* A bound on the secondary rays one camera sample may cast. A surface that both reflects
   and refracts doubles the rays at every bounce, so that three half-mirror, half-glass
   planes at depth 1000 would never finish; past the bound a secondary ray contributes
   black, as one past the depth does. A full binary tree of depth 16 (2^16 − 2 secondary
   rays) stays under it, so it changes nothing in a scene that does not branch that much.
   Pruning rays by their weight instead would move bytes of ordinary glass scenes. *)
let max_secondary = 65536

(* The weight in the camera sample's colour of the step at [depth + 1] that a step at
   [depth] traces with factor [k]. *)
let[@inline] weigh scr depth k =
  Float.Array.unsafe_set scr.wts (depth + 1) (k *. Float.Array.unsafe_get scr.wts depth)

(* The colour seen along the ray that [scr.q] holds, into (scr.f.r, scr.f.g, scr.f.b).
   Everything a shading step needs after tracing again is in locals: a float bound by
   [let] stays unboxed across the call. *)
let rec trace_b (sc : Scene.t) st scr depth =
  Task.tick st;
  let q = scr.q and f = scr.f in
  q.p_tmin <- 0.;
  q.p_tmax <- Float.infinity;
  Accel.nearest scr.ax sc.accel q scr.hit;
  let i = scr.hit.item in
  match sc.settings.fog with
  | None ->
      if i >= 0 then shade sc st scr depth sc.objects.(i)
      else background_into sc.settings f q.dy
  | Some fg ->
      (* The segment to the hit, or an infinite one for a miss. *)
      if i >= 0 then (
        let t = q.p_t in
        (* The surface's light fades in the fog, and its half-difference with it. *)
        if sc.features.soft_shadows then
          Float.Array.unsafe_set scr.wts depth
            (Float.Array.unsafe_get scr.wts depth *. Float.exp (-.t /. fg.distance));
        shade sc st scr depth sc.objects.(i);
        fog_into fg t f)
      else (
        background_into sc.settings f q.dy;
        fog_into fg Float.infinity f)

(* The surface hit at t = scr.q.p_t by the ray [scr.q] holds. *)
and shade (sc : Scene.t) (st : Task.t) scr depth (o : Primitive.t) =
  let q = scr.q and f = scr.f and acc = scr.acc in
  let t = q.p_t in
  let ox = q.ox and oy = q.oy and oz = q.oz and dx = q.dx and dy = q.dy and dz = q.dz in
  let o = Primitive.surface o ~leaf:scr.hit.leaf ~face:scr.hit.face in
  let s = sc.settings in
  let m = o.material in
  let px = ox +. (t *. dx) and py = oy +. (t *. dy) and pz = oz +. (t *. dz) in
  Frag.set_point f px py pz;
  Primitive.normal_into o f;
  let nx = f.nx and ny = f.ny and nz = f.nz in
  let delta = offset_s px py pz ox oy oz in
  albedo_into o f px py pz nx ny nz delta;
  let cr = f.r and cg = f.g and cb = f.b in
  let entering = (dx *. nx) +. (dy *. ny) +. (dz *. nz) < 0. in
  (match m.bump with
  | None ->
      if entering then (
        f.nx <- nx;
        f.ny <- ny;
        f.nz <- nz)
      else (
        f.nx <- -.nx;
        f.ny <- -.ny;
        f.nz <- -.nz)
  | Some b ->
      let p = Vec3.v px py pz in
      let nf = if entering then Vec3.v nx ny nz else Vec3.v (-.nx) (-.ny) (-.nz) in
      Frag.set_normal f
        (Bump.perturb b
           ~uv:(fun d -> Primitive.uv o (Vec3.add p d))
           (Primitive.texture_point o p) nf));
  let nfx = f.nx and nfy = f.ny and nfz = f.nz in
  let lox = px +. (delta *. nfx)
  and loy = py +. (delta *. nfy)
  and loz = pz +. (delta *. nfz) in
  acc.ar <- m.ambient *. (cr *. s.ambient.r);
  acc.ag <- m.ambient *. (cg *. s.ambient.g);
  acc.ab <- m.ambient *. (cb *. s.ambient.b);
  acc.tr <- 0.;
  acc.tg <- 0.;
  acc.tb <- 0.;
  acc.px <- px;
  acc.py <- py;
  acc.pz <- pz;
  acc.lx <- lox;
  acc.ly <- loy;
  acc.lz <- loz;
  (* The weight of this step's own light in the camera sample's colour. *)
  if sc.features.soft_shadows then
    acc.wl <-
      Float.Array.unsafe_get scr.wts depth *. (1. -. m.reflection -. m.transparency);
  let lights = sc.view_lights in
  for li = 0 to Array.length lights - 1 do
    match lights.(li) with
    | Light.Point { position; color; intensity; attenuation = a; radius; samples; spot }
      -> (
        let lx = position.x -. px and ly = position.y -. py and lz = position.z -. pz in
        let dist = Vec3.length3 lx ly lz in
        let att = 1. /. (a.x +. (a.y *. dist) +. (a.z *. dist *. dist)) in
        let k = 1. /. dist in
        let area_n = if radius > 0. && samples > 1 then samples else 0 in
        match spot with
        | None ->
            light_term sc st li scr m cr cg cb nfx nfy nfz dx dy dz lox loy loz (k *. lx)
              (k *. ly) (k *. lz) dist att color intensity position radius area_n
        | Some sp ->
            (* The cone scales E; outside it the light is not even tested for shadow. cos θ
                is axis · (P − position)/d = −axis · Ldir. *)
            let ax = sp.axis in
            let fs =
              Light.spot_factor sp
                (-.((ax.x *. k *. lx) +. (ax.y *. k *. ly) +. (ax.z *. k *. lz)))
            in
            if fs > 0. then
              light_term sc st li scr m cr cg cb nfx nfy nfz dx dy dz lox loy loz
                (k *. lx) (k *. ly) (k *. lz) dist (att *. fs) color intensity position
                radius area_n)
    | Light.Directional { direction; color; intensity } ->
        light_term sc st li scr m cr cg cb nfx nfy nfz dx dy dz lox loy loz
          (-.direction.x) (-.direction.y) (-.direction.z) Float.infinity 1. color
          intensity direction 0. 0
  done;
  let lr = acc.ar and lg = acc.ag and lb = acc.ab in
  let r = m.reflection and tau = m.transparency in
  if r = 0. && tau = 0. then (
    f.r <- lr;
    f.g <- lg;
    f.b <- lb)
  else
    (* Refraction geometry first: total internal reflection and Fresnel both move weight
       from τ to r. *)
    let c_in = -.((dx *. nfx) +. (dy *. nfy) +. (dz *. nfz)) in
    let eta = if entering then 1. /. m.ior else m.ior in
    let k = 1. -. (eta *. eta *. (1. -. (c_in *. c_in))) in
    (* Schlick's F, where it applies. *)
    let fr =
      if tau = 0. || k < 0. || not m.fresnel then 0.
      else
        let f0 =
          if m.ior = acc.f0_ior then acc.f0
          else
            let f0 = ((m.ior -. 1.) /. (m.ior +. 1.)) ** 2. in
            acc.f0_ior <- m.ior;
            acc.f0 <- f0;
            f0
        in
        let c' = if entering then c_in else Float.sqrt k in
        f0 +. ((1. -. f0) *. ((1. -. c') ** 5.))
    in
    let r' =
      if tau = 0. then r
      else if k < 0. then r +. tau
      else if m.fresnel then r +. (tau *. fr)
      else r
    and tau' =
      if tau = 0. then 0.
      else if k < 0. then 0.
      else if m.fresnel then tau *. (1. -. fr)
      else tau
    in
    let w = 1. -. r -. tau in
    let outr = ref (w *. lr) and outg = ref (w *. lg) and outb = ref (w *. lb) in

    if depth < s.depth then (
      if r' > 0. && st.budget > 0 then (
        st.reflected <- st.reflected + 1;
        st.budget <- st.budget - 1;
        (* D − 2(D·Nf)·Nf *)
        let kr = -2. *. ((dx *. nfx) +. (dy *. nfy) +. (dz *. nfz)) in
        Probe.set_origin q lox loy loz;
        Probe.set_unit_dir q (dx +. (kr *. nfx)) (dy +. (kr *. nfy)) (dz +. (kr *. nfz));
        if sc.features.soft_shadows then weigh scr depth r';
        trace_b sc st scr (depth + 1);
        (* r·tint(μ) ⊙ reflected: a metal tints what it mirrors (tint(0) is 1, exactly). *)
        let mu = m.metallic in
        outr := !outr +. (r' *. tint mu cr *. f.r);
        outg := !outg +. (r' *. tint mu cg *. f.g);
        outb := !outb +. (r' *. tint mu cb *. f.b));
      if tau' > 0. && st.budget > 0 then (
        st.refracted <- st.refracted + 1;
        st.budget <- st.budget - 1;
        let kt = (eta *. c_in) -. Float.sqrt k and kd = -.delta in
        Probe.set_origin q (px +. (kd *. nfx)) (py +. (kd *. nfy)) (pz +. (kd *. nfz));
        Probe.set_unit_dir q
          ((eta *. dx) +. (kt *. nfx))
          ((eta *. dy) +. (kt *. nfy))
          ((eta *. dz) +. (kt *. nfz));
        if sc.features.soft_shadows then weigh scr depth tau';
        trace_b sc st scr (depth + 1);
        (* τ·tint(φ) ⊙ refracted: coloured glass filters what is seen through it. *)
        let phi = m.filter in
        outr := !outr +. (tau' *. tint phi cr *. f.r);
        outg := !outg +. (tau' *. tint phi cg *. f.g);
        outb := !outb +. (tau' *. tint phi cb *. f.b)));
    f.r <- !outr;
    f.g <- !outg;
    f.b <- !outb

(* A camera sample's half-difference starts from nothing, its first step at weight 1. *)
let start_half_diff (sc : Scene.t) scr depth =
  let acc = scr.acc in
  acc.nr <- 0.;
  acc.ng <- 0.;
  acc.nb <- 0.;
  if Float.Array.length scr.wts < sc.settings.depth + 2 then
    scr.wts <- Float.Array.make (sc.settings.depth + 2) 0.;
  Float.Array.unsafe_set scr.wts depth 1.

let[@inline] trace_into (sc : Scene.t) (st : Task.t) scr depth =
  st.budget <- max_secondary;
  if sc.features.soft_shadows then start_half_diff sc scr depth;
  trace_b sc st scr depth

let trace sc st ray depth =
  let scr = scratch () in
  Probe.of_ray scr.q ray;
  trace_into sc st scr depth;
  Color.v scr.f.r scr.f.g scr.f.b

let transmittance sc st (origin : Vec3.t) (dir : Vec3.t) dist =
  let scr = scratch () in
  shadow_into sc st 0 scr origin.x origin.y origin.z dir.x dir.y dir.z dist ~mask:(-1);
  Color.v scr.acc.tr scr.acc.tg scr.acc.tb
