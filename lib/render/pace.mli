(** The garbage collector's pace around work whose allocations mostly live on. *)

val all_live : int
(** A space overhead for work whose allocations all outlive it (the primitives of held
    spheres made again, a hierarchy built over primitives that all live): 1 000 000, at
    which the collector runs no cycle of its own for that work's allocations. *)

val within : int -> (unit -> 'a) -> 'a
(** [within overhead f] is [f ()] with the collector's [space_overhead] at [overhead], and
    set back to what it was when [f] returns or raises. *)
