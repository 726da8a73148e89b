(** The one walk of a bounding volume hierarchy, and the tests of what its leaves hold.

    A scene's hierarchy and every mesh's are walked by the same three queries, written
    once: the nearest root, any root, and every crossing. A hierarchy is a {!Bvh} tree
    (possibly none) over {e slots}, some tested in order before the tree; its leaves are
    the triangles of a mesh, or a scene's placed objects ({!type-items}): spheres and
    planes read from a float array, simple shapes through their primitive, meshes and CSG
    objects asked in turn, with the walk of their own hierarchy or the crossings of their
    members. Besides its t, a query answers the {e part} a root lies on: the face of a
    mesh, the leaf of a CSG object (and that leaf's face where it is a mesh), so that
    shading builds the surface of the winner without intersecting anything again
    ({!Primitive.surface}).

    The queries allocate nothing (with the shapes that {!Lancer_render.Shape.root} tests
    in scalars), CSG objects included. Each runs on a level of the calling domain's
    {!type-scratch}, the queries it makes in turn on the next. *)

(** {1 Answers} *)

type hit = {
  mutable item : int;  (** the item hit: a scene index; −1 for none *)
  mutable leaf : int;
      (** the CSG leaf it lies on ({!Lancer_render.Shape.csg_leaves}), or −1 *)
  mutable face : int;  (** the mesh face, of the item or of its leaf, or −1 *)
}
(** What a nearest query found besides its t, which is in the probe's [p_t]. *)

val hit : unit -> hit
(** A fresh record (item −1). *)

type sorter

type crossings = private {
  mutable ts : Float.Array.t;  (** crossing k's t at k *)
  mutable parts : int array;
      (** crossing k's item, leaf and face (as {!type-hit}'s) at 3k, 3k + 1 and 3k + 2 *)
  mutable n : int;  (** how many crossings: the arrays may be longer *)
  sorter : sorter;
}
(** A growing buffer of crossings, read in place. *)

val crossings : unit -> crossings
(** An empty buffer. *)

val clear : crossings -> unit

val remap : crossings -> int -> int array -> unit
(** [remap c from idx] replaces the item [i] of each crossing from the [from]-th on by
    [idx.(i)]. *)

val sort : crossings -> unit
(** Into increasing t, then item, leaf and face. Allocates nothing after the buffer's
    first sort of its size. *)

(** {1 A scene's index} *)

type items
(** A scene's objects by slot, with what their tests read without their primitive. *)

val items : ?flat:Float.Array.t -> Primitive.t array -> items
(** [items prims] are [prims] as slots: an untransformed sphere or plane is tested from 4
    floats kept beside the others (in [flat] when it is long enough, 4 floats a slot), a
    mesh or a CSG object by its own walk or members, any other through its primitive. *)

val sphere_candidates : Float.Array.t -> int -> int -> Probe.t -> int
(** [sphere_candidates flat lo n q], for [n ≤ Sys.int_size − 1], has bit [k] set unless
    the sphere of slot [lo + k] of [flat] (centre x, y, z and radius, 4 floats a slot) is
    missed for certain by [q]'s ray: where {!Shape.sphere_sc}'s early miss is taken (the
    line farther from the centre than the radius, by the same operations), the sphere
    having no root whatever the interval. A slot holding NaN is always set. How a walk
    passes over most of a leaf's spheres; written in C, two spheres at a time. *)

type index = {
  nodes : Float.Array.t;
      (** a {!Bvh.t}'s nodes over the slots from [first] on; empty: no tree *)
  depth : int;  (** the tree's depth *)
  ids : int array;  (** each slot's scene index *)
  first : int;  (** the slots below [first] are tested in order before the tree *)
  items : items;
}
(** A hierarchy over a scene's objects: a tree's leaf [(l, count)] holds [count] slots
    from [first + l] on, and every slot below [first] is tested before it (the unbounded
    objects, or all of them where there is no tree). *)

type scratch
(** What one domain's queries reuse: a level (stack, probes, buffers) for each query
    running inside another, made when first needed. *)

val scratch : unit -> scratch

val domain_scratch : unit -> scratch
(** The calling domain's scratch, to be used by that domain only. A query that an
    exception interrupts (a cancellation polled inside a CSG object, {!Task.spend}) leaves
    it fit for the next. *)

(** {1 The three queries}

    Each reads the ray and its interval ([p_tmin], [p_tmax]) from the probe, whose
    reciprocal direction must be set, and leaves the interval as it found it, but where
    said. *)

val nearest_in : scratch -> index -> Probe.t -> hit -> unit
(** [nearest_in sc x q h]: the object hit nearest in ([q.p_tmin], [q.p_tmax]) into [h]
    ([h.item] −1 for none), its t into [q.p_t] (infinity for none). The lexicographic
    minimum of (t, scene index) over the objects' nearest roots, whatever the order of the
    walk: ties go to the lower index. Moves [q.p_tmax]. *)

val any_in : scratch -> index -> Probe.t -> opaque:bool -> mask:int -> int
(** [any_in sc x q ~opaque ~mask]: an object crossing ([q.p_tmin], [q.p_tmax]), the first
    the walk meets, or −1; with [opaque], objects of a transparent material (transparency
    ≠ 0) do not count, and in an index without a tree, only the slots whose bit is set in
    [mask] ({!shadow_mask}; −1: all). Whether it is −1 does not depend on the walk. *)

val shadow_mask : index -> Probe.t -> Vec3.t -> float -> int
(** [shadow_mask x o c r]: for an index without a tree (a few objects), a bit for each
    slot whose bounds a segment from [o]'s origin to a point at most [r] from [c] may meet
    (slot j: bit j), the others clear; −1 for a tree, or more slots than an int has bits.
    A plane is left out where [o] and all such points are on one side of it, and a CSG
    difference or intersection whose first member is a sphere, a box or a capped cylinder
    with no transform of its own where a plane touching that member has [o] and them on
    the other side, each by a margin (a point of the object's own surface under a light
    above it). Every ray from that origin toward such a point (an area light's samples)
    crosses only objects whose bit is set, so {!any_in} with the mask answers as without
    it, testing fewer objects. *)

val crossings_in : scratch -> index -> Probe.t -> transparent:bool -> crossings -> unit
(** [crossings_in sc x q ~transparent out] appends every crossing in ([q.p_tmin],
    [q.p_tmax]) to [out], in no order ({!sort} orders them): each object's every root, a
    mesh's each t once with the lowest face crossed there, a CSG object's each crossing of
    its boundary with its leaf. With [transparent], only the objects of a transparent
    material. *)

val blocks : scratch -> Primitive.t -> Probe.t -> opaque:bool -> bool
(** [blocks sc p q ~opaque] is true only where [p] alone crosses ([q.p_tmin], [q.p_tmax]),
    as {!any_in} would count it: a cheap first try for the slot that blocked last. It
    answers for a simple shape and a mesh (first culled by its box); for a CSG object it
    is false, and the caller walks. *)

(** {1 One shape, for a ray}

    The same tests for one shape in its own space, a mesh and a CSG object included. They
    allocate their probe and answer. *)

val intersect : Shape.t -> Ray.t -> float -> float -> float
(** [intersect s r tmin tmax] is the nearest root of [r] on [s] in (tmin, tmax), or
    infinity. *)

val inside : Shape.t -> Vec3.t -> bool
(** [inside s p] is whether [p] is inside [s], the boundary included
    ({!Lancer_render.Shape.inside}); a solid mesh's inside is the parity of its crossings
    along a fixed direction, a CSG object's its members' combined. *)

val parity_direction : Vec3.t
(** The direction of the ray along which a solid mesh's crossings are counted for its
    inside ({!inside}): none of a mesh's axis-aligned features lies along it. *)

val shape_crossings : Shape.t -> Ray.t -> float -> (float * int * int) list
(** [shape_crossings s r tmin] is every t > tmin where [r] crosses the boundary of [s],
    nearest first, with the leaf (0 for a shape that is not a CSG object) and the face (−1
    for a shape that is not a mesh) it lies on: each root of a simple shape, each t of a
    mesh once (its lowest face there), each crossing of a CSG object's boundary. Each root
    of a CSG object's surface sought and each inside tested count as a unit of work into
    the calling domain's {!Task.current}, whose poll may raise [Sys.Break]. *)
