(* A major cycle marks every live block; while the heap grows by blocks that all live
   on, a cycle frees almost nothing, and the collector's default pace (a cycle's worth
   of work for every so many words allocated) marks the same primitives again and
   again. *)
let all_live = 1_000_000

(* The setting is the whole program's, and work runs at this pace on several domains at
   once (the frames of an animation each allocate their framebuffer): the calls in
   progress are counted, the first one keeps the overhead from before, and the last one
   to return sets it back. *)
let lock = Mutex.create ()
let running = ref 0
let before = ref 0

let within overhead f =
  (* Counted once the setting is made, and uncounted only if it was: an exception
     (Ctrl-C's among them) before the work starts leaves the count as it was. *)
  let counted = ref false in
  Fun.protect
    ~finally:(fun () ->
      if !counted then
        Mutex.protect lock (fun () ->
            decr running;
            if !running = 0 then Gc.set { (Gc.get ()) with space_overhead = !before }))
    (fun () ->
      Mutex.protect lock (fun () ->
          let g = Gc.get () in
          if !running = 0 then before := g.space_overhead;
          Gc.set { g with space_overhead = overhead };
          incr running;
          counted := true);
      f ())
