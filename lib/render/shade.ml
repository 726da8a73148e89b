let offset (p : Vec3.t) (o : Vec3.t) =
  1e-9 *. Float.max 1e-300 (Float.max (Vec3.max_abs p) (Vec3.max_abs o))

(* Albedo C at world point p on object o with geometric normal n: the texture is evaluated
   in object space at p − δ·n (doc/shading.md, section 6). *)
let albedo (o : Primitive.t) p n delta =
  let m = o.material in
  match m.texture with
  | None -> m.color
  | Some tex ->
      (* N is the geometric normal: a smooth mesh's interpolated normal is not. *)
      let n =
        match o.shape with
        | Shape.Triangle { normals = Some _; tn; _ } -> Transform.normal o.transform tn
        | _ -> n
      in
      let q = Primitive.texture_point o (Vec3.madd p (-.delta) n) in
      if Texture.needs_uv tex then
        let u, v = Primitive.uv o p in
        Texture.eval tex q u v
      else Texture.eval tex q 0. 0.

(* The diffuse and specular light of one light is summed into [acc] (ar, ag, ab); the
   transmittance of its shadow rays is written into (tr, tg, tb) first. A record of floats
   is flat, so neither boxes anything. *)
type acc = {
  mutable ar : float;
  mutable ag : float;
  mutable ab : float;
  mutable tr : float;
  mutable tg : float;
  mutable tb : float;
}

(* Where no opaque surface blocks the segment: the product over the transparent surfaces
   crossed of transparency · albedo, into acc.(tr, tg, tb). Apart from [shadow_into], which
   inlines (a function holding a closure would not). *)
let transparent_into (sc : Scene.t) acc origin dir dist =
  let r = Ray.make_raw origin dir in
  let (c : Color.t) =
    Accel.fold_transparent_hits sc.accel r 0. dist
      (fun o t acc ->
        (* A CSG object's crossing shades with the leaf it lies on. *)
        let o = Primitive.surface o r t in
        let m = o.material in
        let p = Ray.at r t in
        let po = Primitive.to_object o p in
        let n = Primitive.normal o po in
        let c = albedo o p n (offset p origin) in
        Color.mul acc (Color.scale m.transparency c))
      Color.white
  in
  acc.tr <- c.r;
  acc.tg <- c.g;
  acc.tb <- c.b

(* Transmittance from [origin] along the unit direction (dx, dy, dz) up to [dist], into
   acc.(tr, tg, tb). Opaque surfaces first, by the occlusion query, which allocates nothing
   and answers most shadow rays; only where none blocks and some surface is transparent
   are the crossings of the transparent ones folded. [slot] is the light's index. *)
let[@inline] shadow_into (sc : Scene.t) (st : Stats.t) slot acc (origin : Vec3.t) dx dy dz
    dist =
  st.shadow <- st.shadow + 1;
  Stats.tick st;
  let q = Accel.shadow_probe () in
  q.ox <- origin.x;
  q.oy <- origin.y;
  q.oz <- origin.z;
  q.dx <- dx;
  q.dy <- dy;
  q.dz <- dz;
  q.p_tmin <- 0.;
  q.p_tmax <- dist;
  if Accel.occluded sc.accel q ~slot then (
    acc.tr <- 0.;
    acc.tg <- 0.;
    acc.tb <- 0.)
  else if not sc.features.refraction then (
    acc.tr <- 1.;
    acc.tg <- 1.;
    acc.tb <- 1.)
  else transparent_into sc acc origin (Vec3.v dx dy dz) dist

(* Length of (x, y, z) as [Vec3.length] computes it. *)
let[@inline] len3 x y z =
  let l2 = (x *. x) +. (y *. y) +. (z *. z) in
  if l2 > 1e-280 && l2 < 1e280 then Float.sqrt l2 else Vec3.length (Vec3.v x y z)

(* Stratified points on the disk of radius [radius] facing [p], centred on the light:
   sample (a, b) of n×n sits at radius R·√((a+½)/n) and angle 2π(b+½)/n. The pattern is
   the same for every pixel, so soft shadows are deterministic and noise-free in time.
   The frame is w = (position − p)/|position − p|, e1 = normalize(h × w) with h the x axis
   (the y axis when |w.x| ≥ 0.9), e2 = w × e1; everything is computed in scalars, with the
   operations of the vector form. The mean transmittance goes into acc.(tr, tg, tb). *)
let area_transmittance sc st slot acc (p : Vec3.t) (origin : Vec3.t) (position : Vec3.t)
    radius n =
  let lx = position.x -. p.x and ly = position.y -. p.y and lz = position.z -. p.z in
  let ll = len3 lx ly lz in
  let k = 1. /. ll in
  let wx = if ll = 0. then 0. else k *. lx
  and wy = if ll = 0. then 0. else k *. ly
  and wz = if ll = 0. then 0. else k *. lz in
  let hx = if Float.abs wx < 0.9 then 1. else 0. in
  let hy = 1. -. hx and hz = 0. in
  let cx = (hy *. wz) -. (hz *. wy)
  and cy = (hz *. wx) -. (hx *. wz)
  and cz = (hx *. wy) -. (hy *. wx) in
  let cl = len3 cx cy cz in
  let k = 1. /. cl in
  let e1x = if cl = 0. then 0. else k *. cx
  and e1y = if cl = 0. then 0. else k *. cy
  and e1z = if cl = 0. then 0. else k *. cz in
  let e2x = (wy *. e1z) -. (wz *. e1y)
  and e2y = (wz *. e1x) -. (wx *. e1z)
  and e2z = (wx *. e1y) -. (wy *. e1x) in
  let sr = ref 0. and sg = ref 0. and sb = ref 0. in
  let nf = Float.of_int n in
  for a = 0 to n - 1 do
    for b = 0 to n - 1 do
      let rr = radius *. Float.sqrt ((Float.of_int a +. 0.5) /. nf) in
      let th = 2. *. Float.pi *. (Float.of_int b +. 0.5) /. nf in
      let u = rr *. Float.cos th and v = rr *. Float.sin th in
      let dx = position.x +. (u *. e1x) +. (v *. e2x) -. origin.x
      and dy = position.y +. (u *. e1y) +. (v *. e2y) -. origin.y
      and dz = position.z +. (u *. e1z) +. (v *. e2z) -. origin.z in
      let dist = len3 dx dy dz in
      let k = 1. /. dist in
      shadow_into sc st slot acc origin (k *. dx) (k *. dy) (k *. dz) dist;
      sr := !sr +. acc.tr;
      sg := !sg +. acc.tg;
      sb := !sb +. acc.tb
    done
  done;
  let s = 1. /. (nf *. nf) in
  acc.tr <- s *. !sr;
  acc.tg <- s *. !sg;
  acc.tb <- s *. !sb

let reflect d nf = Vec3.madd d (-2. *. Vec3.dot d nf) nf

(* Snell–Descartes: with c = −D·Nf and k = 1 − η²(1 − c²) ≥ 0, T = η·D + (η·c − √k)·Nf.
   [shade] computes c and k itself (Fresnel needs them) and shares this. *)
let[@inline] refracted d nf eta c k =
  Vec3.madd (Vec3.smul eta d) ((eta *. c) -. Float.sqrt k) nf

let refract d nf eta =
  let c = -.Vec3.dot d nf in
  let k = 1. -. (eta *. eta *. (1. -. (c *. c))) in
  if k < 0. then None else Some (refracted d nf eta c k)

(* The diffuse and specular light of one light with unit direction (ldx, ldy, ldz) towards
   it, added into [acc] (doc/shading.md, section 4). Inlined into [shade]: its floats stay
   unboxed and nothing is allocated. [area_n] > 0 makes it an area light sampled n×n over
   [radius] around [position]; [slot] is the light's index. *)
let[@inline] light_term (sc : Scene.t) st slot (m : Material.t) (c : Color.t)
    (nf : Vec3.t) (d : Vec3.t) p (lit_origin : Vec3.t) acc ldx ldy ldz dist att
    (color : Color.t) intensity position radius area_n =
  let ndl = (nf.x *. ldx) +. (nf.y *. ldy) +. (nf.z *. ldz) in
  if ndl > 0. then (
    if not sc.features.shadows then (
      acc.tr <- 1.;
      acc.tg <- 1.;
      acc.tb <- 1.)
    else if area_n > 0 then
      area_transmittance sc st slot acc p lit_origin position radius area_n
    else shadow_into sc st slot acc lit_origin ldx ldy ldz dist;
    let trr = acc.tr and trg = acc.tg and trb = acc.tb in
    if trr > 0. || trg > 0. || trb > 0. then (
      let ia = intensity *. att in
      let er = ia *. color.r *. trr
      and eg = ia *. color.g *. trg
      and eb = ia *. color.b *. trb in
      let kd = m.diffuse *. ndl in
      acc.ar <- acc.ar +. (kd *. (c.r *. er));
      acc.ag <- acc.ag +. (kd *. (c.g *. eg));
      acc.ab <- acc.ab +. (kd *. (c.b *. eb));
      if m.specular > 0. then
        let k2 = 2. *. ndl in
        let rx = (k2 *. nf.x) -. ldx
        and ry = (k2 *. nf.y) -. ldy
        and rz = (k2 *. nf.z) -. ldz in
        (* R·V with V = −D *)
        let rv = (rx *. -.d.x) +. (ry *. -.d.y) +. (rz *. -.d.z) in
        (* max(0, R·V)^shininess: nothing when R·V ≤ 0, except that x⁰ = 1. *)
        if rv > 0. || m.shininess = 0. then (
          let ks = m.specular *. Float.pow (if rv > 0. then rv else 0.) m.shininess in
          acc.ar <- acc.ar +. (ks *. er);
          acc.ag <- acc.ag +. (ks *. eg);
          acc.ab <- acc.ab +. (ks *. eb))))

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

let rec trace_b (sc : Scene.t) st ray depth =
  Stats.tick st;
  let h = { Shape.tmin = 0.; tmax = Float.infinity; t = Float.infinity } in
  let i = Accel.nearest_into sc.accel ray 0. Float.infinity h in
  match sc.settings.fog with
  | None ->
      if i >= 0 then shade sc st ray depth sc.objects.(i) h.t
      else if Option.is_none sc.settings.sky then sc.settings.background
      else Settings.background_along sc.settings (Ray.dir ray)
  | Some f ->
      (* The segment to the hit, or an infinite one for a miss. *)
      if i >= 0 then Settings.fog_segment f h.t (shade sc st ray depth sc.objects.(i) h.t)
      else
        Settings.fog_segment f Float.infinity
          (Settings.background_along sc.settings (Ray.dir ray))

and shade (sc : Scene.t) (st : Stats.t) ray depth (o : Primitive.t) t =
  let o = Primitive.surface o ray t in
  let s = sc.settings in
  let m = o.material in
  let d = Ray.dir ray in
  let p = Ray.at ray t in
  let po = Primitive.to_object o p in
  let n = Primitive.normal o po in
  let delta = offset p (Ray.origin ray) in
  let c = albedo o p n delta in
  let entering = Vec3.dot d n < 0. in
  let nf = if entering then n else Vec3.neg n in
  let nf =
    match m.bump with
    | None -> nf
    | Some b ->
        Bump.perturb b
          ~uv:(fun d -> Primitive.uv o (Vec3.add p d))
          (Primitive.texture_point o p) nf
  in
  let lit_origin = Vec3.madd p delta nf in
  let acc =
    {
      ar = m.ambient *. (c.r *. s.ambient.r);
      ag = m.ambient *. (c.g *. s.ambient.g);
      ab = m.ambient *. (c.b *. s.ambient.b);
      tr = 0.;
      tg = 0.;
      tb = 0.;
    }
  in
  let lights = sc.view_lights in
  for li = 0 to Array.length lights - 1 do
    match lights.(li) with
    | Light.Point { position; color; intensity; attenuation = a; radius; samples; spot }
      -> (
        let lx = position.x -. p.x
        and ly = position.y -. p.y
        and lz = position.z -. p.z in
        let l2 = (lx *. lx) +. (ly *. ly) +. (lz *. lz) in
        let dist =
          if l2 > 1e-280 && l2 < 1e280 then Float.sqrt l2
          else Vec3.length (Vec3.v lx ly lz)
        in
        let att = 1. /. (a.x +. (a.y *. dist) +. (a.z *. dist *. dist)) in
        let k = 1. /. dist in
        let area_n = if radius > 0. && samples > 1 then samples else 0 in
        match spot with
        | None ->
            light_term sc st li m c nf d p lit_origin acc (k *. lx) (k *. ly) (k *. lz)
              dist att color intensity position radius area_n
        | Some sp ->
            (* The cone scales E; outside it the light is not even tested for shadow. cos θ
                is axis · (P − position)/d = −axis · Ldir. *)
            let ax = sp.axis in
            let f =
              Light.spot_factor sp
                (-.((ax.x *. k *. lx) +. (ax.y *. k *. ly) +. (ax.z *. k *. lz)))
            in
            if f > 0. then
              light_term sc st li m c nf d p lit_origin acc (k *. lx) (k *. ly) (k *. lz)
                dist (att *. f) color intensity position radius area_n)
    | Light.Directional { direction; color; intensity } ->
        light_term sc st li m c nf d p lit_origin acc (-.direction.x) (-.direction.y)
          (-.direction.z) Float.infinity 1. color intensity direction 0. 0
  done;
  let local = Color.v acc.ar acc.ag acc.ab in
  let r = m.reflection and tau = m.transparency in
  if r = 0. && tau = 0. then local
  else
    (* Refraction geometry first: total internal reflection and Fresnel both move weight
       from τ to r. *)
    let c_in = -.Vec3.dot d nf in
    let eta = if entering then 1. /. m.ior else m.ior in
    let k = 1. -. (eta *. eta *. (1. -. (c_in *. c_in))) in
    let r', tau' =
      if tau = 0. then (r, 0.)
      else if k < 0. then (r +. tau, 0.)
      else if m.fresnel then
        let f0 = ((m.ior -. 1.) /. (m.ior +. 1.)) ** 2. in
        let c' = if entering then c_in else Float.sqrt k in
        let f = f0 +. ((1. -. f0) *. ((1. -. c') ** 5.)) in
        (r +. (tau *. f), tau *. (1. -. f))
      else (r, tau)
    in
    let out = Color.scale (1. -. r -. tau) local in
    if depth >= s.depth then out
    else
      let out =
        if r' > 0. && st.budget > 0 then (
          st.reflected <- st.reflected + 1;
          st.budget <- st.budget - 1;
          Color.madd out r'
            (trace_b sc st (Ray.make lit_origin (reflect d nf)) (depth + 1)))
        else out
      in
      if tau' > 0. && st.budget > 0 then (
        st.refracted <- st.refracted + 1;
        st.budget <- st.budget - 1;
        let td = refracted d nf eta c_in k in
        Color.madd out tau'
          (trace_b sc st (Ray.make (Vec3.madd p (-.delta) nf) td) (depth + 1)))
      else out

let trace sc (st : Stats.t) ray depth =
  st.budget <- max_secondary;
  trace_b sc st ray depth

let transmittance sc st origin (dir : Vec3.t) dist =
  let acc = { ar = 0.; ag = 0.; ab = 0.; tr = 0.; tg = 0.; tb = 0. } in
  shadow_into sc st 0 acc origin dir.x dir.y dir.z dist;
  Color.v acc.tr acc.tg acc.tb
