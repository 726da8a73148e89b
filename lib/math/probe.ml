(* The field order is the one [probe.mli] states, which the hierarchy's descent in C reads. *)
type t = {
  mutable ox : float;
  mutable oy : float;
  mutable oz : float;
  mutable dx : float;
  mutable dy : float;
  mutable dz : float;
  mutable ix : float;
  mutable iy : float;
  mutable iz : float;
  mutable p_tmin : float;
  mutable p_tmax : float;
  mutable p_t : float;
}

let create () =
  {
    ox = 0.;
    oy = 0.;
    oz = 0.;
    dx = 0.;
    dy = 0.;
    dz = 0.;
    ix = 0.;
    iy = 0.;
    iz = 0.;
    p_tmin = 0.;
    p_tmax = 0.;
    p_t = Float.infinity;
  }

let[@inline] set_origin q x y z =
  q.ox <- x;
  q.oy <- y;
  q.oz <- z

(* [Vec3.normalize] of (x, y, z), the same operations. *)
let[@inline] set_unit_dir q x y z =
  let l = Vec3.length3 x y z in
  if l = 0. then (
    q.dx <- 0.;
    q.dy <- 0.;
    q.dz <- 0.)
  else
    let k = 1. /. l in
    q.dx <- k *. x;
    q.dy <- k *. y;
    q.dz <- k *. z

let[@inline] set_inv_dir q =
  q.ix <- 1. /. q.dx;
  q.iy <- 1. /. q.dy;
  q.iz <- 1. /. q.dz

let of_ray q r =
  let o = Ray.origin r and d = Ray.dir r and i = Ray.inv_dir r in
  q.ox <- o.x;
  q.oy <- o.y;
  q.oz <- o.z;
  q.dx <- d.x;
  q.dy <- d.y;
  q.dz <- d.z;
  q.ix <- i.x;
  q.iy <- i.y;
  q.iz <- i.z

let to_ray q = Ray.make_raw (Vec3.v q.ox q.oy q.oz) (Vec3.v q.dx q.dy q.dz)

let[@inline] inverse_into tr q out =
  let x = q.ox and y = q.oy and z = q.oz in
  out.ox <- Transform.inv_px tr x y z;
  out.oy <- Transform.inv_py tr x y z;
  out.oz <- Transform.inv_pz tr x y z;
  let x = q.dx and y = q.dy and z = q.dz in
  let dx = Transform.inv_vx tr x y z
  and dy = Transform.inv_vy tr x y z
  and dz = Transform.inv_vz tr x y z in
  out.dx <- dx;
  out.dy <- dy;
  out.dz <- dz;
  out.ix <- 1. /. dx;
  out.iy <- 1. /. dy;
  out.iz <- 1. /. dz
