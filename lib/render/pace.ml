(* A major cycle marks every live block; while the heap grows by blocks that all live
   on, a cycle frees almost nothing, and the collector's default pace (a cycle's worth
   of work for every so many words allocated) marks the same primitives again and
   again. *)
let all_live = 1_000_000

let within overhead f =
  let g = Gc.get () in
  Gc.set { g with space_overhead = overhead };
  Fun.protect
    ~finally:(fun () -> Gc.set { (Gc.get ()) with space_overhead = g.space_overhead })
    f
