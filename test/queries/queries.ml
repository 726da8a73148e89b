open Lancer

let probe r tmin tmax =
  let q = Probe.create () in
  Probe.of_ray q r;
  q.p_tmin <- tmin;
  q.p_tmax <- tmax;
  q

let hit a r tmin tmax =
  let q = probe r tmin tmax and h = Walk.hit () in
  Accel.nearest (Accel.domain_scratch ()) a q h;
  (q.p_t, h.item, h.leaf, h.face)

let nearest a r tmin tmax =
  let t, i, _, _ = hit a r tmin tmax in
  (t, i)

let any ?(slot = -1) a r tmin tmax ~opaque =
  Accel.any (Accel.domain_scratch ()) a (probe r tmin tmax) ~opaque ~slot ~mask:(-1)

let crossings a r tmin tmax ~transparent =
  let out = Walk.crossings () in
  Accel.crossings (Accel.domain_scratch ()) a (probe r tmin tmax) ~transparent out;
  List.init out.n (fun k ->
      ( Float.Array.get out.ts k,
        out.parts.(3 * k),
        out.parts.((3 * k) + 1),
        out.parts.((3 * k) + 2) ))

let object_ray (o : Primitive.t) r =
  if Transform.is_identity o.transform then r
  else
    Ray.make_raw
      (Transform.inv_point o.transform (Ray.origin r))
      (Transform.inv_vector o.transform (Ray.dir r))

let intersect (o : Primitive.t) r tmin tmax =
  Walk.intersect o.shape (object_ray o r) tmin tmax

let surface o r tmin tmax =
  let t, i, leaf, face = hit (Accel.build [| o |]) r tmin tmax in
  ((if i < 0 then o else Primitive.surface o ~leaf ~face), t)
