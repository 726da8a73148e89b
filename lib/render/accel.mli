(** Ray queries over all the primitives of a scene.

    This is the one place that decides which primitives a ray is tested against. It offers
    three queries, {!Walk}'s over the scene's hierarchy: the nearest hit (camera,
    reflected and refracted rays), any hit (shadow rays stop at the first opaque surface)
    and every crossing in order (the transmittance of a shadow ray through transparent
    surfaces). Each takes the calling domain's {!scratch} and a ray held in a
    {!Lancer_math.Probe.t} over its interval ([p_tmin], [p_tmax]); each sets the probe's
    reciprocal direction. *)

type t

val build : Primitive.t array -> t
(** [build prims] indexes [prims] for ray queries: a binned-SAH bounding volume hierarchy
    over the bounded ones when there are enough of them, a linear scan otherwise. *)

val unindexed : Primitive.t array -> t
(** [unindexed prims] answers every query by a linear scan, the answers {!build}'s would
    give, without building anything: for a caller that only asks {!uses_bvh}, which says
    whether [build prims] would build a tree. *)

val layered :
  Primitive.t array ->
  key:int array ->
  fixed:t ->
  fixed_idx:int array ->
  moving:t ->
  moving_idx:int array ->
  t
(** [layered prims ~key ~fixed ~fixed_idx ~moving ~moving_idx] indexes [prims] by two
    structures built over parts of it: [fixed] over the primitives [fixed_idx] lists (in
    increasing order), [moving] over the others ([moving_idx], increasing), so that the
    part that does not change between the frames of an animation is built once. Its
    queries answer as [build prims]'s would, with indices into [prims]: the nearest hit
    the same, whether there is any hit the same, every crossing the same in the same
    order. {!uses_bvh} says whether [build prims] would build a tree. [key] names what
    [fixed] holds, for {!fixed_key}. *)

val uses_bvh : t -> bool
(** Whether a bounding volume hierarchy was built (small scenes skip it), or for
    {!unindexed} would have been. *)

val fixed_key : t -> int array option
(** The [key] a {!layered} structure was given, or [None] for one made by {!build}. *)

(** {1 The three queries} *)

type scratch
(** What the queries of one domain reuse: the walks' levels ({!Walk.type-scratch}), the
    shadow queries' last occluders, and a watch. *)

val domain_scratch : unit -> scratch
(** The calling domain's scratch. It must be used by that domain only. *)

val nearest : scratch -> t -> Probe.t -> Walk.hit -> unit
(** [nearest sc a q h]: the primitive hit nearest in ([q.p_tmin], [q.p_tmax]) into [h],
    its index in the array given to {!build} ([h.item], −1 for none) with the part it lies
    on ([h.leaf], [h.face]: {!Primitive.surface}'s), its t into [q.p_t] (infinity for
    none). Ties go to the lower index, so the answer never depends on the traversal order.
    Moves [q.p_tmax]. Allocates nothing (with the shapes that {!Lancer_render.Shape.root}
    tests in scalars): the query of camera and secondary rays. *)

val any : scratch -> t -> Probe.t -> opaque:bool -> slot:int -> mask:int -> bool
(** [any sc a q ~opaque ~slot ~mask] is whether a surface crosses the ray with [q.p_tmin]
    < t < [q.p_tmax]; with [opaque], only one of an opaque material (transparency 0)
    counts. It stops at the first one found, trying first, for [slot] ≥ 0 (a light's
    index), the one that answered the last query of the same slot in this domain: the
    answer does not depend on it. [mask] is −1, or {!shadow_mask} of a segment the ray
    stays near: only the objects it allows are tested, and the answer is the same.
    Allocates nothing (as {!nearest}). *)

val shadow_mask : t -> Probe.t -> Vec3.t -> float -> int
(** [shadow_mask a o c r]: for a structure of a few objects and no tree, which objects a
    ray from [o]'s origin toward a point at most [r] from [c] may cross, as {!any} takes
    it ({!Walk.shadow_mask}); −1 (all) otherwise. An area light's shadow rays from one
    point share it. *)

val crossings : scratch -> t -> Probe.t -> transparent:bool -> Walk.crossings -> unit
(** [crossings sc a q ~transparent out] puts into [out] (emptied first) every crossing in
    ([q.p_tmin], [q.p_tmax]), in increasing t (then index, leaf and face): each
    primitive's every root, a mesh's each t once with the lowest face crossed there, a CSG
    object's each crossing of its boundary with its leaf; with [transparent], those of the
    primitives of a transparent material only. Allocates nothing once [out] has grown to
    the count (as {!nearest}). *)

(** {1 Watching a box}

    Animations share an index between frames: a pixel none of whose queries may meet the
    box around what moves keeps its bytes. *)

val watch : scratch -> Float.Array.t option -> unit
(** [watch sc (Some box)] makes the queries above, with [sc], mark [sc] {!touched} when
    the segment they search may meet [box] (min x y z, max x y z): a nearest query its
    segment up to its answer, the others all of it. It errs only towards touched.
    [watch sc None] stops it. *)

val untouch : scratch -> unit
(** Clear {!touched}. *)

val touched : scratch -> bool
(** Whether a query watched since {!untouch} may have met the box. *)

val moving_bounds : t list -> Float.Array.t option
(** The box (6 floats: min x y z, max x y z) around the primitives of the moving parts of
    these {!layered} structures, padded by a millionth of its magnitude (empty, min +∞ and
    max −∞, when there are none), or [None] where one of them is unbounded or one
    structure is not layered. *)
