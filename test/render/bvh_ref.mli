(** The reference for {!Lancer_render.Bvh.build}: the binned-SAH build in its first form
    (each node binned in one pass and partitioned in another), which the test compares
    with the library's build node for node, in bits. *)

type t = {
  nodes : Float.Array.t;  (** as {!Lancer_render.Bvh.t}'s *)
  order : int array;  (** the items in leaf order *)
  depth : int;  (** the tree's depth *)
}

val build : ?cheap:Bytes.t * int -> ?large:int -> Float.Array.t -> t
(** [build pbox] over the padded item boxes of [pbox], as {!Lancer_render.Bvh.build} (with
    [cheap] and [large] as there): from [large] items, the Morton order written plainly
    (each code bit by bit, the order by a sort of (code, index) pairs). *)
