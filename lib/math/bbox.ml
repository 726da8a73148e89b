type t = { min : Vec3.t; max : Vec3.t }

let empty =
  {
    min = Vec3.v Float.infinity Float.infinity Float.infinity;
    max = Vec3.v Float.neg_infinity Float.neg_infinity Float.neg_infinity;
  }

let union a b = { min = Vec3.min a.min b.min; max = Vec3.max a.max b.max }
let of_points ps = List.fold_left (fun b p -> union b { min = p; max = p }) empty ps
let centroid b = Vec3.smul 0.5 (Vec3.add b.min b.max)

let transform m b =
  if Transform.is_identity m then b
  else
    let c x y z = Transform.point m (Vec3.v x y z) in
    let l = b.min and h = b.max in
    of_points
      [
        c l.x l.y l.z;
        c l.x l.y h.z;
        c l.x h.y l.z;
        c l.x h.y h.z;
        c h.x l.y l.z;
        c h.x l.y h.z;
        c h.x h.y l.z;
        c h.x h.y h.z;
      ]
