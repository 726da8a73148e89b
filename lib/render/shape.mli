(** Geometric primitives in object space: the closed set of surfaces lancer can intersect.

    Every function takes rays and points in the primitive's own object space (world space
    for an untransformed object). Intersections return the ray parameter t of the nearest
    root strictly inside (tmin, tmax), or [Float.infinity] when there is none; a NaN is
    never returned. Rays may have non-unit directions (object-space rays), and t then
    means the same point as in world space. The roots an intersection computes do not
    depend on tmin and tmax (only which root is kept does), so a smaller tmax never moves
    a hit: the bounding volume hierarchy relies on it.

    This module tests the simple surfaces ({!root}, {!inside}). A mesh's roots come from
    the walk of its hierarchy and a CSG object's from its members: {!Walk} asks those,
    with the same walk as the scene's.

    Build shapes with the smart constructors: the variants hold precomputed values (unit
    normals, reciprocals, frames) that the constructors keep consistent. *)

type csg_op =
  | Union  (** every member's surface; inside where any member is *)
  | Merge  (** the boundary of the union: surfaces inside another member vanish *)
  | Intersection  (** points inside every member *)
  | Difference  (** points inside the first member and inside none of the others *)

type t = private
  | Sphere of { center : Vec3.t; radius : float }
  | Plane of { normal : Vec3.t; offset : float }  (** unit normal; n̂·P = offset *)
  | Parallelogram of {
      origin : Vec3.t;
      edge1 : Vec3.t;
      edge2 : Vec3.t;
      pn : Vec3.t;  (** unit normal, E1 × E2 normalised *)
      w : Vec3.t;  (** (E1 × E2) / |E1 × E2|², for the (a, b) coordinates *)
      pd : float;  (** pn·origin *)
    }  (** A + a·E1 + b·E2, a, b ∈ [0, 1] *)
  | Triangle of {
      a : Vec3.t;
      b : Vec3.t;
      c : Vec3.t;
      tn : Vec3.t;  (** unit geometric normal, (b − a) × (c − a) normalised *)
      normals : (Vec3.t * Vec3.t * Vec3.t) option;
          (** unit vertex normals (smooth meshes) *)
      uvs : ((float * float) * (float * float) * (float * float)) option;
          (** vertex (u, v) *)
    }
  | Paraboloid of {
      vertex : Vec3.t;
      axis : Vec3.t;  (** unit *)
      radius : float;
      height : float;
      k : float;  (** r²/h: the surface is |x⊥|² = k·y' *)
      e1 : Vec3.t;
      e2 : Vec3.t;  (** unit frame perpendicular to the axis, for u *)
    }  (** open cup, 0 ≤ y' ≤ h, two-sided *)
  | Box of { min : Vec3.t; max : Vec3.t }  (** axis-aligned, min < max *)
  | Cylinder of {
      base : Vec3.t;
      axis : Vec3.t;  (** unit, base → top *)
      height : float;  (** |top − base| *)
      radius : float;
      caps : bool;
      e1 : Vec3.t;
      e2 : Vec3.t;
    }
  | Disk of { center : Vec3.t; normal : Vec3.t; radius : float; e1 : Vec3.t; e2 : Vec3.t }
      (** unit normal; (e1, e2) a frame in the disk's plane *)
  | Cone of {
      base : Vec3.t;
      axis : Vec3.t;  (** unit, base → top *)
      height : float;  (** |top − base| *)
      r0 : float;  (** radius at the base, ≥ 0 *)
      r1 : float;  (** radius at the top, ≥ 0; not both 0 *)
      caps : bool;
      e1 : Vec3.t;
      e2 : Vec3.t;
    }  (** the truncated cone between two disks, closed by them when [caps] *)
  | Torus of {
      center : Vec3.t;
      axis : Vec3.t;  (** unit *)
      major : float;  (** R: from the centre to the middle of the tube *)
      minor : float;  (** r: the tube's radius *)
      e1 : Vec3.t;
      e2 : Vec3.t;
    }  (** points at distance r from the ring of radius R around [axis] *)
  | Mesh of {
      mesh : Trimesh.t;
      solid : bool;
          (** every edge is shared by exactly two faces, as the caller checked: a solid,
              whose inside is decided by the parity of a ray's crossings *)
    }
      (** an indexed triangle mesh (an OBJ file's): one shape for all its faces, hit
          through its own bounding volume hierarchy, whose walk gives the face hit
          ({!face}) *)
  | Csg of {
      op : csg_op;
      members : csg_member array;  (** at least one *)
      leaf_count : int;  (** how many simple surfaces the tree has ({!csg_leaves}) *)
      cbounds : Bbox.t option;
          (** the intersection's overlap, the difference's first member's *)
    }  (** constructive solid geometry over solids placed by their own transforms *)

and csg_member = {
  shape : t;
  transform : Transform.t;  (** member space → the CSG's space *)
  first_leaf : int;
      (** index in {!csg_leaves} of this member's first simple surface (its leaves follow
          it, depth first) *)
}

and csg_leaf = {
  leaf_shape : t;
      (** never a [Csg]; a mesh is one leaf, its triangles the leaf's faces *)
  leaf_transform : Transform.t;  (** leaf space → the outermost CSG's space *)
  flipped : bool;
      (** subtracted an odd number of times: its normal points the other way *)
}

val sphere : center:Vec3.t -> radius:float -> t
(** The sphere |P − center| = radius; the radius must be positive. *)

val plane : normal:Vec3.t -> offset:float -> t
(** [plane ~normal ~offset]: [normal] need not be unit; the plane is n̂·P = offset with n̂ =
    normalize normal. *)

val parallelogram : origin:Vec3.t -> edge1:Vec3.t -> edge2:Vec3.t -> t
(** A + a·E1 + b·E2 for a, b ∈ [0, 1]; the edges must not be parallel. Hits use a
    parametric tolerance of 1e-9, so parallelograms tiled edge to edge leave no crack. *)

val triangle : a:Vec3.t -> b:Vec3.t -> c:Vec3.t -> t
(** A flat triangle (watertight intersection test); (u, v) are the barycentric weights of
    [b] and [c]. The corners must not be in a line. *)

val mesh_triangle :
  ?normals:Vec3.t * Vec3.t * Vec3.t ->
  ?uvs:(float * float) * (float * float) * (float * float) ->
  a:Vec3.t ->
  b:Vec3.t ->
  c:Vec3.t ->
  unit ->
  t
(** A mesh face: [normals] (normalised here) are interpolated for smooth shading, [uvs]
    for texture coordinates. *)

val paraboloid : vertex:Vec3.t -> axis:Vec3.t -> radius:float -> height:float -> t
(** The open cup |x⊥|² = (r²/h)·y' for y' ∈ [0, h] along [axis] (need not be unit) from
    [vertex]; radius and height positive. *)

val box : min:Vec3.t -> max:Vec3.t -> t
(** The axis-aligned box between the two corners (taken component-wise). *)

val cylinder : base:Vec3.t -> top:Vec3.t -> radius:float -> caps:bool -> t
(** The cylinder of [radius] around the segment base–top (distinct points), closed by two
    disks when [caps]. *)

val cone :
  base:Vec3.t -> top:Vec3.t -> base_radius:float -> top_radius:float -> caps:bool -> t
(** The cone around the segment base–top (distinct points) whose radius goes linearly from
    [base_radius] to [top_radius] (either may be 0, not both), closed by disks when
    [caps]. *)

val torus : center:Vec3.t -> axis:Vec3.t -> major:float -> minor:float -> t
(** The torus of tube radius [minor] around the ring of radius [major] about [axis] (need
    not be unit) through [center]. Its quartic is solved on a ray restarted at its point
    nearest the centre, each root isolated between critical points and refined by Newton
    steps on the original equation; tangent (double) roots are kept. *)

val disk : center:Vec3.t -> normal:Vec3.t -> radius:float -> t
(** The flat disk of [radius] around [center] in the plane of [normal] (need not be unit).
*)

val csg : csg_op -> (t * Transform.t) list -> t
(** [csg op members] combines solids, each placed by its transform; members of
    [Intersection], [Merge] and [Difference] (and of a [Union] inside one of them) must be
    solids (as {!Lancer_description.Description.is_solid} says, a mesh made by
    {!solid_mesh}); at least one member. *)

val csg_leaves : t -> csg_leaf array
(** [csg_leaves s] is every simple surface of CSG tree [s], depth first (a mesh one leaf),
    placed in the outermost object's space: the leaves that [first_leaf] and the CSG
    crossings of {!Walk} number. Made anew at each call (the tree holds only their count);
    [[||]] for a shape that is not a [Csg]. *)

val inside : t -> Vec3.t -> bool
(** [inside s p] is whether [p] is inside [s], the boundary included; [false] for shapes
    that have no inside. Raises [Invalid_argument] on a solid mesh and a CSG object, whose
    inside follows from their crossings ({!Lancer_render.Walk.inside}). *)

val inside_at : t -> float -> float -> float -> bool
(** [inside_at s x y z] is [inside s (Vec3.v x y z)], bit for bit, without the vector. *)

val inside_probe : t -> Probe.t -> bool
(** [inside_probe s p] is [inside_at s p.ox p.oy p.oz], bit for bit, allocating nothing:
    the point is [p]'s origin. *)

val root : t -> Probe.t -> unit
(** [root s q] is the nearest root of the ray that [q] holds on the simple shape [s] in
    ([q.p_tmin], [q.p_tmax]), into [q.p_t] (infinity for none). Allocates nothing, but for
    cylinders, cones and tori, whose test builds the ray. Raises [Invalid_argument] on a
    mesh or a CSG object (see {!Walk}). *)

val roots : t -> Probe.t -> Float.Array.t -> int
(** [roots s q out] writes into [out] every root of the simple shape [s] along [q]'s ray
    after [q.p_tmin], in increasing order, each value once, at most as many as [out]
    holds: how many. They are the roots {!root} finds asked again past each one (up to
    infinity), bit for bit; a sphere's, a box's, a cylinder's and a cone's come from one
    test (there [out] must hold 2 or 4 floats at least, else they are asked one by one).
    Raises [Invalid_argument] on a mesh or a CSG object. *)

val intersect : t -> Ray.t -> float -> float -> float
(** [intersect s r tmin tmax] is {!root} for the ray [r] over (tmin, tmax): the same root,
    bit for bit. *)

val normal : t -> Vec3.t -> Vec3.t
(** [normal s p] is the unit normal at the surface point [p]: outward for closed surfaces
    (sphere, box, capped cylinder), away from the inside of a paraboloid's cup, the
    plane's own normal for flat shapes, and the interpolated vertex normal for smooth mesh
    triangles. Raises [Invalid_argument] on a [Csg] (ask the leaf a crossing lies on) and
    a mesh (ask the face, {!face}). *)

val normal_into : t -> Frag.t -> unit
(** [normal_into s f] is {!normal} at the point [(f.x, f.y, f.z)], written into
    [(f.nx, f.ny, f.nz)], bit for bit. Spheres, planes, disks, parallelograms, flat
    triangles and boxes allocate nothing. *)

val uv : t -> Vec3.t -> float * float
(** [uv s p] is the texture coordinate of surface point [p]: spheres longitude and
    latitude; planes the in-plane coordinates modulo 1; parallelograms (a, b); triangles
    the barycentric weights of b and c, or the interpolated vertex (u, v) of a mesh;
    paraboloids and cylinder sides the turn around the axis and y'/h; disks and cylinder
    caps (x, y)/(2r) + ½ in the disk's frame; boxes each face's own rectangle. In [0, 1]
    except for mesh (u, v), which are as the file gives them. *)

val uv_into : t -> Frag.t -> unit
(** [uv_into s f] is {!uv} at the point [(f.x, f.y, f.z)], written into [(f.u, f.v)]. *)

val bbox : t -> Bbox.t option
(** Object-space bounds; [None] for unbounded surfaces (planes). *)

val translate : Vec3.t -> t -> t
(** [translate d s] is [s] moved by [d]: the same surface, its points plus [d]. *)

val name : t -> string
(** The kind, as written in a scene ("sphere", "plane", …; "mesh" for mesh faces). *)

val mesh : Trimesh.t -> t
(** The mesh whose faces are the triangles of an indexed mesh. *)

val solid_mesh : Trimesh.t -> t
(** {!mesh}, a solid: the caller has checked that it is closed
    ({!Obj_file.open_edges_mesh} is 0), so that it may be a member of a CSG object. *)

val face : Trimesh.t -> int -> t
(** [face m k] is triangle [k] of [m] as {!mesh_triangle} makes it of its corners, normals
    and (u, v): the same bits as a triangle read on its own. *)

val faces : Trimesh.t -> t list
(** Every face, in order. *)

val sphere_sc :
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float
(** [sphere_sc cx cy cz r ox oy oz dx dy dz tmin tmax] is the sphere's root in (tmin,
    tmax) along the ray, or infinity: {!root} of a {!Sphere}, bit for bit, on scalars (for
    structures that keep spheres in flat arrays). *)

val plane_sc :
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float ->
  float
(** [plane_sc nx ny nz offset ox oy oz dx dy dz tmin tmax]: {!root} of a {!Plane}, bit for
    bit, on scalars. *)
