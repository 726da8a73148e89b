(** The queries of {!Lancer.Accel} and {!Lancer.Walk} asked with a ray and answered as
    values: the forms the tests compare with brute force and with each other. The renderer
    asks the same queries with a probe (allocating nothing); these allocate. *)

open Lancer

val probe : Ray.t -> float -> float -> Probe.t
(** A probe holding the ray over (tmin, tmax), its reciprocal direction set. *)

val nearest : Accel.t -> Ray.t -> float -> float -> float * int
(** [nearest a r tmin tmax]: (t, index) of the nearest hit in (tmin, tmax), or (infinity,
    −1). *)

val hit : Accel.t -> Ray.t -> float -> float -> float * int * int * int
(** {!nearest} with the part: (t, index, leaf, face). *)

val any : ?slot:int -> Accel.t -> Ray.t -> float -> float -> opaque:bool -> bool
(** [any a r tmin tmax ~opaque]: whether a surface (an opaque one with [opaque]) crosses
    (tmin, tmax); [slot] as {!Accel.any}'s (default −1: no occluder remembered). *)

val crossings :
  Accel.t -> Ray.t -> float -> float -> transparent:bool -> (float * int * int * int) list
(** Every crossing in (tmin, tmax) as (t, index, leaf, face), in {!Accel.crossings}'
    order. *)

val object_ray : Primitive.t -> Ray.t -> Ray.t
(** [object_ray o r] is world ray [r] in [o]'s object space, not renormalised (t is the
    same in both spaces). *)

val intersect : Primitive.t -> Ray.t -> float -> float -> float
(** [intersect o r tmin tmax] is the nearest root of world ray [r] on [o] in (tmin, tmax),
    or infinity: {!Walk.intersect} of its shape for the ray in its object space (not
    renormalised, so t is the same in both spaces). *)

val surface : Primitive.t -> Ray.t -> float -> float -> Primitive.t * float
(** [surface o r tmin tmax]: what [r] hits first on [o] alone, as {!Primitive.surface} of
    the part the nearest query found, with its t; [o] itself where nothing is hit. *)
