(** A stream's primitives, gathered in order as objects compile, and handed over in one
    array at the end.

    A sphere placed without a transform ({!holds}), whose material is the previous
    primitive's, is held as floats rather than as its primitive, which the collector would
    otherwise mark at every cycle of a long load, and made again at the end: a primitive
    equal to it field for field, its material the same record. Spheres in a row of equal
    radii share one float, and a colour record shared by consecutive spheres stays shared;
    one shared by spheres apart (A, B, A) is made again for each, as the language, which
    makes a colour record for each object, never shares it.

    The held floats are outside the OCaml heap, so that the collector neither marks nor
    counts them: {!take} frees each block of them as soon as it has read it, {!discard}
    frees them all, and a stream dropped without either has them freed when the collector
    finds it dead. *)

type t

val create : ?move:(Primitive.t -> Primitive.t) -> unit -> t
(** An empty stream whose primitives [move] (default none) is applied to, as they are
    added or, for those held, as they are made again. *)

val moves : t -> bool
(** Whether it was created with a [move]. *)

val holds : Primitive.t -> bool
(** Whether a primitive can be held as floats: a sphere, untransformed, bounded, neither
    flipped nor moved, as {!Primitive.make} makes it. {!add} holds it when its material is
    also the previous primitive's. *)

val add : t -> Primitive.t -> unit
(** [add t p]: [p] (moved), after those added before it. *)

val add_sphere : t -> center:Vec3.t -> radius:float -> color:Color.t -> Material.t -> unit
(** [add_sphere t ~center ~radius ~color m] is
    [add t (Primitive.make ~color m (Shape.sphere ~center ~radius))], the same primitive
    taken, without making it where it is held: a loop's spheres go straight to their
    floats. *)

val total : t -> int
(** How many have been added since the last {!take}. *)

val held : t -> int
(** How many of them are held as floats. *)

val take : t -> Primitive.t array
(** [take t]: every primitive added, in order and moved, each one held made again; [t] is
    emptied. *)

val discard : t -> unit
(** [discard t] empties [t] without making anything, and frees its held floats at once:
    for a load that failed. *)
