(** The process's limit on its address space: what the scene language refuses to build
    beyond, and what the renderer sizes its domains' minor heaps by. *)

val limit : unit -> int option
(** The soft limit on the process's address space (ulimit -v), in bytes, from
    [/proc/self/limits]; [None] when unlimited or unknown. *)
