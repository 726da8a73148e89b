type t = {
  width : int;
  height : int;
  item : int array;
  depth : Float.Array.t;
  normal : Float.Array.t;
}

(* The shading normal at the hit the probe holds, of primitive [o] (its surface for [hit]),
   into [f]'s normal: the geometric normal facing the ray, then bumped. *)
let normal_into (o : Primitive.t) (hit : Walk.hit) (q : Probe.t) (f : Frag.t) =
  let o = Primitive.surface o ~leaf:hit.leaf ~face:hit.face in
  let t = q.p_t in
  let px = q.ox +. (t *. q.dx)
  and py = q.oy +. (t *. q.dy)
  and pz = q.oz +. (t *. q.dz) in
  Frag.set_point f px py pz;
  Primitive.normal_into o f;
  if (q.dx *. f.nx) +. (q.dy *. f.ny) +. (q.dz *. f.nz) >= 0. then (
    f.nx <- -.f.nx;
    f.ny <- -.f.ny;
    f.nz <- -.f.nz);
  match o.material.bump with
  | None -> ()
  | Some b ->
      let p = Vec3.v px py pz in
      Frag.set_normal f
        (Bump.perturb b
           ~uv:(fun d -> Primitive.uv o (Vec3.add p d))
           (Primitive.texture_point o p) (Vec3.v f.nx f.ny f.nz))

let primary (sc : Scene.t) =
  let w = sc.settings.width and h = sc.settings.height in
  let item = Array.make (w * h) (-1)
  and depth = Float.Array.make (w * h) Float.infinity
  and normal = Float.Array.make (3 * w * h) 0. in
  let q = Probe.create ()
  and hit = Walk.hit ()
  and ax = Accel.domain_scratch ()
  and f = Frag.create () in
  let c = sc.view in
  for j = 0 to h - 1 do
    for i = 0 to w - 1 do
      let x = Float.of_int i +. 0.5 and y = Float.of_int j +. 0.5 in
      if Camera.in_view c ~width:w ~height:h x y then (
        Camera.ray_into c ~width:w ~height:h x y q;
        q.p_tmin <- 0.;
        q.p_tmax <- Float.infinity;
        Accel.nearest ax sc.accel q hit;
        let k = hit.item and p = (j * w) + i in
        if k >= 0 then (
          Array.unsafe_set item p k;
          Float.Array.unsafe_set depth p q.p_t;
          normal_into (Array.unsafe_get sc.objects k) hit q f;
          Float.Array.unsafe_set normal (3 * p) f.nx;
          Float.Array.unsafe_set normal ((3 * p) + 1) f.ny;
          Float.Array.unsafe_set normal ((3 * p) + 2) f.nz))
    done
  done;
  { width = w; height = h; item; depth; normal }
