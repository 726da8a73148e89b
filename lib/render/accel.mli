(** Ray queries over all the primitives of a scene.

    This is the one place that decides which primitives a ray is tested against: the
    nearest hit for camera, reflected and refracted rays, and every hit before a distance
    for shadow rays (transmittance through transparent surfaces). *)

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
  fixed:t ->
  fixed_idx:int array ->
  moving:t ->
  moving_idx:int array ->
  t
(** [layered prims ~fixed ~fixed_idx ~moving ~moving_idx] indexes [prims] by two
    structures built over parts of it: [fixed] over the primitives [fixed_idx] lists (in
    increasing order), [moving] over the others ([moving_idx], increasing), so that the
    part that does not change between the frames of an animation is built once. Its
    {!nearest}, {!nearest_probe}, {!any_hit} and {!occluded} answer as [build prims]
    would, indices into [prims]; {!fold_hits} and {!transparent_crossings} visit the fixed
    part's crossings first, an order that [build]'s need not have (the shading multiplies
    a shadow ray's crossings in the order of their values, whatever order they come in).
    {!uses_bvh} says whether [build prims] would build a tree. *)

val uses_bvh : t -> bool
(** Whether a bounding volume hierarchy was built (small scenes skip it), or for
    {!unindexed} would have been. *)

val fixed_part : t -> t option
(** The structure over the fixed part of a {!layered} one (physically the one given), or
    [None] for one made by {!build}. *)

val nearest : t -> Ray.t -> float -> float -> float * int
(** [nearest a r tmin tmax] is (t, index) of the primitive hit nearest in (tmin, tmax), or
    (infinity, −1); the index is into the array given to {!build}. Ties go to the lower
    index, so the answer never depends on the traversal order. *)

val nearest_into : t -> Ray.t -> float -> float -> Shape.hit -> int
(** {!nearest} with t stored in the record: {!nearest_probe} on a probe made for the ray
    (two small records per query). *)

val nearest_probe : t -> Shape.probe -> int
(** [nearest_probe a q] is {!nearest_into} for the ray that [q] holds over ([q.p_tmin],
    [q.p_tmax]), bit for bit: the index of the primitive hit (−1 for none), its t stored
    in [q.p_t]. It sets the probe's reciprocal direction itself and moves [q.p_tmax].
    Allocates nothing (with the shapes that {!Shape.probe_into} tests in scalars): the
    query of camera and secondary rays. *)

val fold_hits :
  t ->
  Ray.t ->
  float ->
  float ->
  (Primitive.t -> float -> Color.t -> Color.t) ->
  Color.t ->
  Color.t
(** [fold_hits a r tmin tmax f acc] folds [f prim t acc] over every surface crossing of
    [r] with tmin < t < tmax, stopping early once [acc] is black. Used for shadow
    transmittance, whose product does not depend on the order. *)

val fold_transparent_hits :
  t ->
  Ray.t ->
  float ->
  float ->
  (Primitive.t -> float -> Color.t -> Color.t) ->
  Color.t ->
  Color.t
(** {!fold_hits} over the transparent primitives only (transparency ≠ 0): the same answer
    where {!occluded} has said that no opaque surface crosses the segment. *)

val transparent_crossings : t -> Shape.probe -> (Primitive.t -> bool) -> unit
(** [transparent_crossings a q visit] is {!fold_transparent_hits} for the ray that [q]
    holds over ([q.p_tmin], [q.p_tmax]), with the accumulator kept by the caller:
    [visit o] is called at each crossing of a transparent primitive [o], in the fold's
    order, with the crossing's t in [q.p_t], and answers whether to stop (the fold stops
    where its accumulator is black). It sets the probe's reciprocal direction and moves
    its interval; [visit] must leave the probe's ray alone. Allocates nothing itself: a
    [visit] made once and reused makes the transmittance of a shadow ray free. *)

val any_hit : t -> Ray.t -> float -> float -> bool
(** [any_hit a r tmin tmax] is whether [r] crosses any surface with tmin < t < tmax. It
    stops at the first one found: the walk of {!occluded} with every primitive counting,
    on a probe made for the ray (two small records per query). *)

val shadow_probe : unit -> Shape.probe
(** This domain's shadow probe: fill its origin, direction and interval, then ask
    {!occluded}. *)

val occluded : t -> Shape.probe -> slot:int -> bool
(** [occluded a q ~slot] is whether an opaque surface (transparency 0) crosses the ray
    that [q] holds with [q.p_tmin] < t < [q.p_tmax]; it sets the probe's reciprocal
    direction itself. It stops at the first one found, trying first the one that answered
    the last query of the same [slot] (a light's index) in this domain: the answer does
    not depend on it. Allocates nothing (with the shapes that {!Shape.probe_into} tests in
    scalars). *)

(** {2 With the domain's scratch in hand}

    Each query above finds what it reuses (traversal stacks, a scratch probe, the shadow
    query's last occluders) in a domain-local slot, a look-up per query; a glass scene
    asks some twenty queries a pixel. A renderer that keeps the scratch of its domain
    passes it instead: the same answers, found with the same scratch. *)

type scratch
(** What the queries of one domain reuse. *)

val domain_scratch : unit -> scratch
(** The calling domain's scratch. It must be used by that domain only. *)

val watch : scratch -> Float.Array.t option -> unit
(** [watch sc (Some box)] makes the queries below, with [sc], mark [sc] {!touched} when
    the segment they search may meet [box] (min x y z, max x y z): a nearest query its
    segment up to its answer, an occlusion or a fold of crossings all of it. It errs only
    towards touched. [watch sc None] stops it. *)

val untouch : scratch -> unit
(** Clear {!touched}. *)

val touched : scratch -> bool
(** Whether a query watched since {!untouch} may have met the box. *)

val release : scratch -> unit
(** Marks [sc]'s traversal stack free, as a query that an exception left half done (a
    cancellation polled inside a CSG object's test, {!Stats.spend}) did not. Only where
    none of [sc]'s queries is running. *)

val moving_bounds : t list -> Float.Array.t option
(** The box (6 floats: min x y z, max x y z) around the primitives of the moving parts of
    these {!layered} structures, padded by a millionth of its magnitude (empty, min +∞ and
    max −∞, when there are none), or [None] where one of them is unbounded or one
    structure is not layered. *)

val nearest_probe_with : scratch -> t -> Shape.probe -> int
(** [nearest_probe_with (domain_scratch ()) a q] is [nearest_probe a q]. *)

val occluded_with : scratch -> t -> Shape.probe -> slot:int -> bool
(** [occluded_with (domain_scratch ()) a q ~slot] is [occluded a q ~slot]. *)

val transparent_crossings_with :
  scratch -> t -> Shape.probe -> (Primitive.t -> bool) -> unit
(** [transparent_crossings_with (domain_scratch ()) a q visit] is
    [transparent_crossings a q visit]. *)
