type t = {
  shape : Shape.t;
  transform : Transform.t;
  material : Material.t;
  color : Color.t;
  bounds : Bbox.t option;
  shift : Vec3.t;
  extra : extra;
}

and extra = { flip : bool; leaves : t array }

(* The bounds of a bounded untransformed shape are its own: rather than a box per
   primitive (13 words of 30 for a sphere), [bounds] holds this one shared marker, and
   {!bounds} asks the shape. *)
let own = Some { Bbox.min = Vec3.zero; max = Vec3.zero }

let world_bounds transform shape =
  if Transform.is_identity transform then
    (* A sphere is bounded: no box is made to learn it (a million spheres make two each,
       their own and the moved one's). *)
    match shape with
    | Shape.Sphere _ -> own
    | _ -> ( match Shape.bbox shape with Some _ -> own | None -> None)
  else Option.map (Bbox.transform transform) (Shape.bbox shape)

(* The [extra] of every primitive but a CSG object: one record for each orientation,
   shared by all. A million spheres hold a word fewer each than with the two fields in
   their own records. *)
let plain = { flip = false; leaves = [||] }
let flipped = { flip = true; leaves = [||] }

let extra flip leaves =
  if Array.length leaves > 0 then { flip; leaves } else if flip then flipped else plain

let bounds o = if o.bounds == own then Shape.bbox o.shape else o.bounds

let bounds_into o b off =
  let set = Float.Array.unsafe_set in
  match o.shape with
  | Shape.Sphere { center; radius } when o.bounds == own ->
      (* Shape.bbox's own arithmetic (centre ∓ radius), without its box. *)
      set b off (center.x -. radius);
      set b (off + 1) (center.y -. radius);
      set b (off + 2) (center.z -. radius);
      set b (off + 3) (center.x +. radius);
      set b (off + 4) (center.y +. radius);
      set b (off + 5) (center.z +. radius)
  | _ -> (
      match bounds o with
      | Some { Bbox.min; max } ->
          set b off min.x;
          set b (off + 1) min.y;
          set b (off + 2) min.z;
          set b (off + 3) max.x;
          set b (off + 4) max.y;
          set b (off + 5) max.z
      | None -> Float.Array.fill b off 6 Float.nan)

let rec make ?(transform = Transform.identity) ?(flip = false) ?leaf_materials ?color
    (material : Material.t) shape =
  let bounds = world_bounds transform shape in
  let leaves =
    match shape with
    | Shape.Csg _ ->
        Array.mapi
          (fun i (l : Shape.csg_leaf) ->
            let m =
              match leaf_materials with
              | Some ms when i < Array.length ms -> Option.value ms.(i) ~default:material
              | _ -> material
            in
            make
              ~transform:(Transform.then_ l.leaf_transform transform)
              ~flip:l.flipped m l.leaf_shape)
          (Shape.csg_leaves shape)
    | _ -> [||]
  in
  (* A CSG object never shades with its own material (its leaves do); shadow queries read
     it to tell opaque objects from transparent ones, so it is a transparent leaf's when
     any leaf is transparent. *)
  let material =
    if Array.length leaves = 0 then material
    else
      match Array.find_opt (fun l -> l.material.transparency <> 0.) leaves with
      | Some l -> l.material
      | None -> leaves.(0).material
  in
  let color =
    match color with Some c when Array.length leaves = 0 -> c | _ -> material.color
  in
  {
    shape;
    transform;
    material;
    color;
    bounds;
    shift = Vec3.zero;
    extra = extra flip leaves;
  }

(* A simple shape whose transform only moves it (a group's or a body's translation) is
   that shape moved, untransformed, its texture space (object space before) [shift]
   away: the inverse's translation. One without a texture or a bump map whose transform
   scales every length alike is the shape [similar_shape] makes of it. Either takes the
   fast path of untransformed shapes (flat sphere leaves, scalar plane tests, no ray
   moved into object space) for the same surface, up to the last bits of the arithmetic
   done in world space instead. Meshes stay as they are (a move would copy their
   vertices, shared by every placement of the mesh), and so do CSG objects, whose leaves
   carry the transform. *)
let bakeable = function
  | Shape.Mesh _ | Shape.Csg _ -> false
  | Shape.Sphere _ | Plane _ | Parallelogram _ | Triangle _ | Paraboloid _ | Box _
  | Cylinder _ | Disk _ | Cone _ | Torus _ ->
      true

(* The shape that a transform scaling every length by [k] (turns, mirrors, one scale)
   makes of [shape], in world space: points placed, axes and normals turned, lengths
   scaled. A box stays one only where the transform keeps the axes (no turn). Triangles
   and parallelograms are left to their transform: a mirror would reverse the normal
   their edges give. Only for shapes without a texture or a bump map, whose object space
   nothing reads. *)
let similar_shape tr k shape =
  let p = Transform.point tr and dir v = Vec3.normalize (Transform.vector tr v) in
  match shape with
  | Shape.Sphere { center; radius } ->
      Some (Shape.sphere ~center:(p center) ~radius:(k *. radius))
  | Shape.Plane { normal; offset } ->
      let n = Transform.normal tr normal in
      Some (Shape.plane ~normal:n ~offset:(Vec3.dot n (p (Vec3.smul offset normal))))
  | Shape.Disk { center; normal; radius; _ } ->
      Some
        (Shape.disk ~center:(p center) ~normal:(Transform.normal tr normal)
           ~radius:(k *. radius))
  | Shape.Cylinder { base; axis; height; radius; caps; _ } ->
      Some
        (Shape.cylinder ~base:(p base)
           ~top:(p (Vec3.madd base height axis))
           ~radius:(k *. radius) ~caps)
  | Shape.Cone { base; axis; height; r0; r1; caps; _ } ->
      Some
        (Shape.cone ~base:(p base)
           ~top:(p (Vec3.madd base height axis))
           ~base_radius:(k *. r0) ~top_radius:(k *. r1) ~caps)
  | Shape.Torus { center; axis; major; minor; _ } ->
      Some
        (Shape.torus ~center:(p center) ~axis:(dir axis) ~major:(k *. major)
           ~minor:(k *. minor))
  | Shape.Paraboloid { vertex; axis; radius; height; _ } ->
      Some
        (Shape.paraboloid ~vertex:(p vertex) ~axis:(dir axis) ~radius:(k *. radius)
           ~height:(k *. height))
  | Shape.Box { min; max } ->
      let off a b = Float.abs a <= 1e-12 *. k && Float.abs b <= 1e-12 *. k in
      let x = Transform.vector tr Vec3.x_axis
      and y = Transform.vector tr Vec3.y_axis
      and z = Transform.vector tr Vec3.z_axis in
      if off x.y x.z && off y.x y.z && off z.x z.y then
        Some (Shape.box ~min:(p min) ~max:(p max))
      else None
  | Shape.Parallelogram _ | Shape.Triangle _ | Shape.Mesh _ | Shape.Csg _ -> None

let baked o =
  (* [o] as [shape], untransformed, its texture space [shift] away. *)
  let placed shape shift =
    {
      o with
      shape;
      transform = Transform.identity;
      bounds =
        (if Option.is_none o.bounds then None else world_bounds Transform.identity shape);
      shift;
    }
  in
  (* Untransformed, it is itself: the identity is neither a translation nor a
     similarity. Asked first, as of each of a million spheres. *)
  if Transform.is_identity o.transform then o
  else if Array.length o.extra.leaves > 0 || not (bakeable o.shape) then o
  else
    match Transform.translation o.transform with
    | Some (d, e) -> placed (Shape.translate d o.shape) e
    | None -> (
        match Transform.similarity o.transform with
        | Some k when Option.is_none o.material.texture && Option.is_none o.material.bump
          -> (
            match similar_shape o.transform k o.shape with
            | Some shape -> placed shape o.shift
            | None -> o)
        | _ -> o)

(* A shape placed without a transform is moved itself, so that it stays on the fast path;
   its texture space is the world before the move, [shift] away. A transformed one gets the
   move appended to its transform, and its object space is its texture space as before. A
   CSG object takes the move in its transform and moves each of its leaves. *)
let rec moved_by ~shift (d : Vec3.t) o =
  let moved =
    if Array.length o.extra.leaves > 0 then
      let transform = Transform.then_ o.transform (Transform.translate d) in
      {
        o with
        transform;
        bounds = world_bounds transform o.shape;
        extra = extra o.extra.flip (Array.map (moved_by ~shift d) o.extra.leaves);
      }
    else if Transform.is_identity o.transform then
      let shape = Shape.translate d o.shape in
      {
        o with
        shape;
        bounds = world_bounds Transform.identity shape;
        shift = shift o.shift;
      }
    else
      baked
        {
          (make
             ~transform:(Transform.then_ o.transform (Transform.translate d))
             ~flip:o.extra.flip ~color:o.color o.material o.shape)
          with
          shift = o.shift;
        }
  in
  (* One kept out of the hierarchy (see [without_bounds]) stays out. *)
  if Option.is_none o.bounds then { moved with bounds = None } else moved

let translate d o = moved_by ~shift:(fun s -> Vec3.sub s d) d o

(* Primitives made without a shift (by {!make}, whose [shift] is [Vec3.zero] itself) share
   the one that the move gives them all. *)
let mover d =
  let common = Vec3.sub Vec3.zero d in
  moved_by ~shift:(fun s -> if s == Vec3.zero then common else Vec3.sub s d) d

(* The world probe [q] in object space, written into [obj], with [q]'s interval. *)
let[@inline] object_probe o (q : Probe.t) (obj : Probe.t) =
  Probe.inverse_into o.transform q obj;
  obj.p_tmin <- q.p_tmin;
  obj.p_tmax <- q.p_tmax

let root o (q : Probe.t) (obj : Probe.t) =
  if Transform.is_identity o.transform then Shape.root o.shape q
  else (
    object_probe o q obj;
    Shape.root o.shape obj;
    q.p_t <- obj.p_t)

let surface o ~leaf ~face =
  let o = if leaf >= 0 then o.extra.leaves.(leaf) else o in
  if face < 0 then o
  else
    match o.shape with
    | Shape.Mesh { mesh; _ } -> { o with shape = Shape.face mesh face }
    | _ -> o

let is_csg o = Array.length o.extra.leaves > 0

let is_composite o =
  Array.length o.extra.leaves > 0
  || match o.shape with Shape.Mesh _ -> true | _ -> false

let faces o = match o.shape with Shape.Mesh { mesh; _ } -> Trimesh.count mesh | _ -> 1
let to_object o p = Transform.inv_point o.transform p
let shifted o = not (o.shift.x = 0. && o.shift.y = 0. && o.shift.z = 0.)
let texture_point o p = if shifted o then Vec3.add p o.shift else to_object o p

(* A plane's (u, v) is measured from the world origin: a moved plane measures it in its
   texture space. The other shapes measure it from their own points. *)
let uv o p =
  match o.shape with
  | Shape.Plane _ when shifted o -> Shape.uv o.shape (Vec3.add p o.shift)
  | _ -> Shape.uv o.shape (to_object o p)

let normal o p =
  let n = Transform.normal o.transform (Shape.normal o.shape p) in
  if o.extra.flip then Vec3.neg n else n

(* The scalar forms of [to_object], [normal], [texture_point] and [uv], on a fragment. *)
let[@inline] to_object_into o (f : Frag.t) =
  let tr = o.transform in
  if not (Transform.is_identity tr) then (
    let x = f.x and y = f.y and z = f.z in
    f.x <- Transform.inv_px tr x y z;
    f.y <- Transform.inv_py tr x y z;
    f.z <- Transform.inv_pz tr x y z)

let normal_into o (f : Frag.t) =
  to_object_into o f;
  Shape.normal_into o.shape f;
  let tr = o.transform in
  if not (Transform.is_identity tr) then (
    let x = f.nx and y = f.ny and z = f.nz in
    let x' = Transform.normal_x tr x y z
    and y' = Transform.normal_y tr x y z
    and z' = Transform.normal_z tr x y z in
    let l = Vec3.length3 x' y' z' in
    if l = 0. then (
      f.nx <- 0.;
      f.ny <- 0.;
      f.nz <- 0.)
    else
      let k = 1. /. l in
      f.nx <- k *. x';
      f.ny <- k *. y';
      f.nz <- k *. z');
  if o.extra.flip then (
    f.nx <- -.f.nx;
    f.ny <- -.f.ny;
    f.nz <- -.f.nz)

let texture_point_into o (f : Frag.t) =
  if shifted o then (
    let s = o.shift in
    f.x <- f.x +. s.x;
    f.y <- f.y +. s.y;
    f.z <- f.z +. s.z)
  else to_object_into o f

let uv_into o (f : Frag.t) =
  (match o.shape with
  | Shape.Plane _ when shifted o ->
      let s = o.shift in
      f.x <- f.x +. s.x;
      f.y <- f.y +. s.y;
      f.z <- f.z +. s.z
  | _ -> to_object_into o f);
  Shape.uv_into o.shape f

let painted o =
  if o.material.color == o.color then o.material else { o.material with color = o.color }

let materials o =
  if Array.length o.extra.leaves = 0 then [ painted o ]
  else Array.to_list (Array.map painted o.extra.leaves)

let without_bounds o = { o with bounds = None }
