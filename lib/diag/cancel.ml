type t = { flag : bool Atomic.t; deferred : int Atomic.t }

let create () = { flag = Atomic.make false; deferred = Atomic.make 0 }
let cancel t = Atomic.set t.flag true
let cancelled t = Atomic.get t.flag
let check t = if Atomic.get t.flag then raise Sys.Break

let signal t =
  cancel t;
  if Atomic.get t.deferred = 0 then raise Sys.Break

let deferring t f =
  Atomic.incr t.deferred;
  match f () with
  | v ->
      Atomic.decr t.deferred;
      v
  | exception e ->
      Atomic.decr t.deferred;
      raise e

(* At about 10 M rays a second per domain, a poll every 0.4 ms: a stop is felt at once,
   and the cost is one decrement and one comparison a ray. A test of one surface inside
   a CSG object, which counts as a ray does, is quicker still. *)
let check_every = 4096
