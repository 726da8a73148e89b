type t = { shape : Shape.t; transform : Transform.t; material : Material.t; bounds : Bbox.t option }

let make ?(transform = Transform.identity) material shape =
  let bounds = Option.map (Bbox.transform transform) (Shape.bbox shape) in
  { shape; transform; material; bounds }

let intersect_into o r h =
  if Transform.is_identity o.transform then Shape.intersect_into o.shape r h
  else
    let r' =
      Ray.make_raw (Transform.inv_point o.transform (Ray.origin r)) (Transform.inv_vector o.transform (Ray.dir r))
    in
    Shape.intersect_into o.shape r' h

let intersect o r tmin tmax =
  if Transform.is_identity o.transform then Shape.intersect o.shape r tmin tmax
  else
    let r' =
      Ray.make_raw (Transform.inv_point o.transform (Ray.origin r)) (Transform.inv_vector o.transform (Ray.dir r))
    in
    Shape.intersect o.shape r' tmin tmax

let to_object o p = Transform.inv_point o.transform p
let normal o p = Transform.normal o.transform (Shape.normal o.shape p)

let without_bounds o = { o with bounds = None }
