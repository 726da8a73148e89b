(** The reference for {!Lancer_render.Bvh.start} and {!Lancer_render.Bvh.next_leaf}: the
    descent written plainly in OCaml, one box and one slab at a time, over the same stack,
    which the test compares with the library's step by step. *)

val start :
  Float.Array.t -> Lancer_math.Probe.t -> Lancer_render.Bvh.walk -> float -> float -> int
(** As {!Lancer_render.Bvh.start}. *)

val next_leaf : Float.Array.t -> Lancer_math.Probe.t -> Lancer_render.Bvh.walk -> int
(** As {!Lancer_render.Bvh.next_leaf}. *)
