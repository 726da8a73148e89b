(** The garbage collector's pace around work whose allocations mostly live on. *)

val all_live : int
(** A space overhead for work whose allocations all outlive it (the primitives of held
    spheres made again, a hierarchy built over primitives that all live, a render's
    framebuffer): 1 000 000, at which the collector's work for those allocations is about
    the least OCaml 5 allows (it still completes a major cycle each time the heap grows by
    about two thirds of itself, where the default overhead, 120, completes one for about a
    third). *)

val within : int -> (unit -> 'a) -> 'a
(** [within overhead f] is [f ()] with the collector's [space_overhead] at [overhead]. The
    setting is the whole program's: while calls overlap, on one domain or several, the
    latest one's overhead holds, and when the last of them returns or raises, the overhead
    from before the first is set back. *)
