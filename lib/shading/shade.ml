let offset (p : Vec3.t) (o : Vec3.t) = 1e-9 *. Float.max 1e-300 (Float.max (Vec3.max_abs p) (Vec3.max_abs o))

(* Albedo C at world point p on object o with geometric normal n: the texture is evaluated
   in object space at p − δ·n (doc/shading.md, section 6). *)
let albedo (o : Primitive.t) p n delta =
  let m = o.material in
  match m.texture with
  | None -> m.color
  | Some tex ->
      (* N is the geometric normal: a smooth mesh's interpolated normal is not. *)
      let n = match o.shape with Shape.Triangle { normals = Some _; tn; _ } -> Transform.normal o.transform tn | _ -> n in
      let q = Primitive.to_object o (Vec3.madd p (-.delta) n) in
      if Texture.needs_uv tex then
        let u, v = Shape.uv o.shape (Primitive.to_object o p) in
        Texture.eval tex q u v
      else Texture.eval tex q 0. 0.

let transmittance (sc : Scene.t) (st : Stats.t) origin dir dist =
  st.shadow <- st.shadow + 1;
  Stats.tick st;
  let r = Ray.make_raw origin dir in
  if not sc.features.refraction then
    (* Every surface is opaque: the first one met makes the shadow. *)
    if Accel.any_hit sc.accel r 0. dist then Color.black else Color.white
  else
  Accel.fold_hits sc.accel r 0. dist
    (fun o t acc ->
      let m = o.material in
      if m.transparency = 0. then Color.black
      else
        let p = Ray.at r t in
        let po = Primitive.to_object o p in
        let n = Primitive.normal o po in
        let c = albedo o p n (offset p origin) in
        Color.mul acc (Color.scale m.transparency c))
    Color.white

(* Stratified points on the disk of radius [radius] facing [p], centred on the light:
   sample (a, b) of n×n sits at radius R·√((a+½)/n) and angle 2π(b+½)/n. The pattern is
   the same for every pixel, so soft shadows are deterministic and noise-free in time. *)
let area_transmittance sc st p origin (position : Vec3.t) radius n =
  let l = Vec3.sub position p in
  let w = Vec3.normalize l in
  let helper = if Float.abs w.x < 0.9 then Vec3.x_axis else Vec3.y_axis in
  let e1 = Vec3.normalize (Vec3.cross helper w) in
  let e2 = Vec3.cross w e1 in
  let acc = ref Color.black in
  let nf = Float.of_int n in
  for a = 0 to n - 1 do
    for b = 0 to n - 1 do
      let rr = radius *. Float.sqrt ((Float.of_int a +. 0.5) /. nf) in
      let th = 2. *. Float.pi *. (Float.of_int b +. 0.5) /. nf in
      let target = Vec3.madd (Vec3.madd position (rr *. Float.cos th) e1) (rr *. Float.sin th) e2 in
      let d = Vec3.sub target origin in
      let dist = Vec3.length d in
      acc := Color.add !acc (transmittance sc st origin (Vec3.smul (1. /. dist) d) dist)
    done
  done;
  Color.scale (1. /. (nf *. nf)) !acc

let reflect d nf = Vec3.madd d (-2. *. Vec3.dot d nf) nf

(* Snell–Descartes: with c = −D·Nf and k = 1 − η²(1 − c²) ≥ 0, T = η·D + (η·c − √k)·Nf.
   [shade] computes c and k itself (Fresnel needs them) and shares this. *)
let[@inline] refracted d nf eta c k = Vec3.madd (Vec3.smul eta d) ((eta *. c) -. Float.sqrt k) nf

let refract d nf eta =
  let c = -.Vec3.dot d nf in
  let k = 1. -. (eta *. eta *. (1. -. (c *. c))) in
  if k < 0. then None else Some (refracted d nf eta c k)

(* The diffuse and specular light of one light with unit direction (ldx, ldy, ldz) towards
   it, added into [acc] (doc/shading.md, section 4). Inlined into [shade]: its floats stay unboxed and
   nothing is allocated but the shadow ray. [area_n] > 0 makes it an area light sampled
   n×n over [radius] around [position]. *)
type acc = { mutable ar : float; mutable ag : float; mutable ab : float }

let[@inline] light_term (sc : Scene.t) st (m : Material.t) (c : Color.t) (nf : Vec3.t) (d : Vec3.t) p lit_origin acc ldx ldy
    ldz dist att (color : Color.t) intensity position radius area_n =
  let ndl = (nf.x *. ldx) +. (nf.y *. ldy) +. (nf.z *. ldz) in
  if ndl > 0. then begin
    let (tr : Color.t) =
      if not sc.features.shadows then Color.white
      else if area_n > 0 then area_transmittance sc st p lit_origin position radius area_n
      else transmittance sc st lit_origin (Vec3.v ldx ldy ldz) dist
    in
    if tr.r > 0. || tr.g > 0. || tr.b > 0. then begin
      let ia = intensity *. att in
      let er = ia *. color.r *. tr.r and eg = ia *. color.g *. tr.g and eb = ia *. color.b *. tr.b in
      let kd = m.diffuse *. ndl in
      acc.ar <- acc.ar +. (kd *. (c.r *. er));
      acc.ag <- acc.ag +. (kd *. (c.g *. eg));
      acc.ab <- acc.ab +. (kd *. (c.b *. eb));
      if m.specular > 0. then begin
        let k2 = 2. *. ndl in
        let rx = (k2 *. nf.x) -. ldx and ry = (k2 *. nf.y) -. ldy and rz = (k2 *. nf.z) -. ldz in
        (* R·V with V = −D *)
        let rv = (rx *. -.d.x) +. (ry *. -.d.y) +. (rz *. -.d.z) in
        (* max(0, R·V)^shininess: nothing when R·V ≤ 0, except that x⁰ = 1. *)
        if rv > 0. || m.shininess = 0. then begin
          let ks = m.specular *. Float.pow (if rv > 0. then rv else 0.) m.shininess in
          acc.ar <- acc.ar +. (ks *. er);
          acc.ag <- acc.ag +. (ks *. eg);
          acc.ab <- acc.ab +. (ks *. eb)
        end
      end
    end
  end

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
      else Settings.fog_segment f Float.infinity (Settings.background_along sc.settings (Ray.dir ray))

and shade (sc : Scene.t) (st : Stats.t) ray depth (o : Primitive.t) t =
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
  let nf = match m.bump with None -> nf | Some b -> Bump.perturb b ~uv:(fun d -> Shape.uv o.shape (Primitive.to_object o (Vec3.add p d))) po nf in
  let lit_origin = Vec3.madd p delta nf in
  let acc = { ar = m.ambient *. (c.r *. s.ambient.r); ag = m.ambient *. (c.g *. s.ambient.g); ab = m.ambient *. (c.b *. s.ambient.b) } in
  let lights = sc.lights in
  for li = 0 to Array.length lights - 1 do
    match lights.(li) with
    | Light.Point { position; color; intensity; attenuation = a; radius; samples; spot } ->
        let lx = position.x -. p.x and ly = position.y -. p.y and lz = position.z -. p.z in
        let l2 = (lx *. lx) +. (ly *. ly) +. (lz *. lz) in
        let dist = if l2 > 1e-280 && l2 < 1e280 then Float.sqrt l2 else Vec3.length (Vec3.v lx ly lz) in
        let att = 1. /. (a.x +. (a.y *. dist) +. (a.z *. dist *. dist)) in
        let k = 1. /. dist in
        let area_n = if radius > 0. && samples > 1 then samples else 0 in
        (match spot with
         | None -> light_term sc st m c nf d p lit_origin acc (k *. lx) (k *. ly) (k *. lz) dist att color intensity position radius area_n
         | Some sp ->
             (* The cone scales E; outside it the light is not even tested for shadow. cos θ
                is axis · (P − position)/d = −axis · Ldir. *)
             let ax = sp.axis in
             let f = Light.spot_factor sp (-.((ax.x *. k *. lx) +. (ax.y *. k *. ly) +. (ax.z *. k *. lz))) in
             if f > 0. then
               light_term sc st m c nf d p lit_origin acc (k *. lx) (k *. ly) (k *. lz) dist (att *. f) color intensity position
                 radius area_n)
    | Light.Directional { direction; color; intensity } ->
        light_term sc st m c nf d p lit_origin acc (-.direction.x) (-.direction.y) (-.direction.z) Float.infinity 1. color
          intensity direction 0. 0
  done;
  let local = Color.v acc.ar acc.ag acc.ab in
  let r = m.reflection and tau = m.transparency in
  if r = 0. && tau = 0. then local
  else begin
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
        if r' > 0. && st.budget > 0 then begin
          st.reflected <- st.reflected + 1;
          st.budget <- st.budget - 1;
          Color.madd out r' (trace_b sc st (Ray.make lit_origin (reflect d nf)) (depth + 1))
        end
        else out
      in
      if tau' > 0. && st.budget > 0 then begin
        st.refracted <- st.refracted + 1;
        st.budget <- st.budget - 1;
        let td = refracted d nf eta c_in k in
        Color.madd out tau' (trace_b sc st (Ray.make (Vec3.madd p (-.delta) nf) td) (depth + 1))
      end
      else out
  end

let trace sc (st : Stats.t) ray depth =
  st.budget <- max_secondary;
  trace_b sc st ray depth
