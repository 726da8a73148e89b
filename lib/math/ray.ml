type t = { origin : Vec3.t; dir : Vec3.t; inv_dir : Vec3.t }

let make_raw origin (dir : Vec3.t) =
  { origin; dir; inv_dir = Vec3.v (1. /. dir.x) (1. /. dir.y) (1. /. dir.z) }

let make origin dir = make_raw origin (Vec3.normalize dir)
let origin r = r.origin
let dir r = r.dir
let inv_dir r = r.inv_dir
let at r t = Vec3.madd r.origin t r.dir
