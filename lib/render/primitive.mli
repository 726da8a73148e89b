(** A scene object: a shape placed in the world by a transform, with its material.

    World bounds are precomputed; unbounded shapes (planes) have none and are kept out of
    the bounding volume hierarchy. *)

type t = private {
  shape : Shape.t;
  transform : Transform.t;  (** object space → world space *)
  material : Material.t;
      (** for a CSG object, which shades with its leaves' materials, a transparent leaf's
          when there is one (else its first leaf's): what shadow queries look at. Its
          [color] is not read: [color] is, so that objects whose materials differ in their
          colour alone share one *)
  color : Color.t;  (** the colour of its material, which shading reads *)
  bounds : Bbox.t option;
      (** [None] when unbounded; otherwise read the bounds with {!val-bounds}: an
          untransformed shape's are its own, and this field holds a marker shared by all
          of them instead of a box each *)
  shift : Vec3.t;
      (** what a world point adds to become a texture-space point, for an untransformed
          object that {!translate} moved; zero otherwise *)
  extra : extra;
      (** its orientation and leaves: one record for each orientation, shared by every
          primitive but a CSG object *)
}

and extra = private {
  flip : bool;  (** the normal is reversed (a surface subtracted by a CSG difference) *)
  leaves : t array;
      (** for a CSG shape, each of its simple surfaces placed in the world with its own
          material and orientation (the shape's {!Lancer_render.Shape.csg_leaves}, in
          order); empty otherwise *)
}

val make :
  ?transform:Transform.t ->
  ?flip:bool ->
  ?leaf_materials:Material.t option array ->
  ?color:Color.t ->
  Material.t ->
  Shape.t ->
  t
(** [make ~transform material shape] places [shape] in the world by [transform] (default
    the identity) and computes its world bounds. [flip] reverses its normal. For a CSG
    shape, [leaf_materials.(i)] is the material of leaf i, [material] where it is [None],
    and each leaf's colour its material's. [color] (default [material]'s) is the colour of
    any other shape. *)

val bounds : t -> Bbox.t option
(** The world-space bounds; [None] when unbounded. *)

val bounds_into : t -> Float.Array.t -> int -> unit
(** [bounds_into p b off] writes {!val-bounds} into [b] at [off] (min x y z, max x y z,
    the same floats), NaN when unbounded; an untransformed sphere's without allocating. *)

val surface : t -> leaf:int -> face:int -> t
(** [surface o ~leaf ~face] is the part of [o] that a crossing lies on, as a query of
    {!Walk} found it ([−1]: none): [o] itself, for a CSG object its leaf [leaf] with its
    material and orientation, and where that (or [o]) is a mesh, its face [face]
    ({!Lancer_render.Shape.face}). Shading and shadows ask it before anything else;
    nothing is intersected again. *)

val is_csg : t -> bool
(** Whether [o] is a CSG object (its normal and material are those of its {!surface}). *)

val is_composite : t -> bool
(** Whether [o] is a CSG object or a mesh: its normal and material are those of its
    {!surface} (a CSG leaf, a mesh's face). *)

val faces : t -> int
(** How many surfaces [o] stands for: a mesh's triangles, 1 for any other object. *)

val materials : t -> Material.t list
(** The materials the object can shade with: its own, or its leaves' for a CSG object,
    each with its {!field-color} (a copy where its record holds another). *)

val object_probe : t -> Probe.t -> Probe.t -> unit
(** [object_probe o q obj] writes the probe [q] (a world ray and its interval) into [obj]
    in [o]'s object space: origin and direction transformed as {!to_object} and
    {!Lancer_math.Transform.inv_vector} do, bit for bit, the reciprocal direction
    recomputed. The direction is not renormalised, so t means the same point in both
    spaces. *)

val root : t -> Probe.t -> Probe.t -> unit
(** [root o q obj] is {!Lancer_render.Shape.root} of [o]'s simple shape for the world ray
    [q] holds, in object space through the scratch probe [obj] when [o] is transformed:
    the root into [q.p_t]. A mesh's and a CSG object's roots are {!Walk}'s. *)

val to_object : t -> Vec3.t -> Vec3.t
(** World point to object space. *)

val normal : t -> Vec3.t -> Vec3.t
(** [normal o p_obj] is the unit world-space geometric normal at object-space point
    [p_obj]. *)

val normal_into : t -> Frag.t -> unit
(** [normal_into o f] is {!normal} at the world point [(f.x, f.y, f.z)], bit for bit: the
    unit world normal goes into [(f.nx, f.ny, f.nz)] and the point is left in object
    space. Allocates nothing where {!Lancer_render.Shape.normal_into} does not. *)

val texture_point_into : t -> Frag.t -> unit
(** [texture_point_into o f] replaces the world point [(f.x, f.y, f.z)] by
    {!texture_point} of it, bit for bit. *)

val uv_into : t -> Frag.t -> unit
(** [uv_into o f] is {!uv} at the world point [(f.x, f.y, f.z)], into [(f.u, f.v)]; the
    point is left as the shape's own point. *)

val translate : Vec3.t -> t -> t
(** [translate d o] is [o] moved by [d], its textures moving with it: an untransformed
    object has its shape moved (and keeps the fast path), a transformed one gets the move
    after its transform ({!baked} when that is then only a move). *)

val baked : t -> t
(** [baked o] is [o] untransformed where that is the same surface: a shape (not a mesh or
    a CSG object) whose transform only moves it becomes the shape moved, its texture space
    kept by its shift; a sphere without a texture or a bump map whose transform turns,
    mirrors or scales it alike on every axis becomes the sphere placed and scaled. Either
    is then on the fast path of untransformed shapes, the same up to the last bits of the
    arithmetic. Any other [o] is itself. {!translate} gives a transformed object its move
    and then this. *)

val mover : Vec3.t -> t -> t
(** [mover d] is {!translate} [d], the same bits, for many primitives: those {!make} made
    share the one shift vector the move gives them instead of a copy each. *)

val texture_point : t -> Vec3.t -> Vec3.t
(** The point of texture space at a world point: object space, or for a moved
    untransformed object the world point before the move. *)

val uv : t -> Vec3.t -> float * float
(** [uv o p] is the (u, v) of the surface at world point [p] ({!Lancer_render.Shape.uv} at
    the object's own point). *)

val without_bounds : t -> t
(** The same primitive with no bounds, so that {!Accel} scans it linearly: tests compare
    the bounding volume hierarchy with a brute-force scene this way. *)
