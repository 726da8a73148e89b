type t = {
  mutable primary : int;
  mutable shadow : int;
  mutable reflected : int;
  mutable refracted : int;
  mutable bad_samples : int;
  mutable first_bad : (int * int) option;
  cancel : Cancel.t;
  mutable until_poll : int;
  mutable budget : int;
  mutable noise_sq : int;
  mutable noise_n : int;
  _p0 : int;
  _p1 : int;
  _p2 : int;
  _p3 : int;
  _p4 : int;
  _p5 : int;
  _p6 : int;
  _p7 : int;
  _p8 : int;
  _p9 : int;
  _p10 : int;
  _p11 : int;
  _p12 : int;
  _p13 : int;
  _p14 : int;
  _p15 : int;
}

let create ?(cancel = Cancel.create ()) () =
  {
    primary = 0;
    shadow = 0;
    reflected = 0;
    refracted = 0;
    bad_samples = 0;
    first_bad = None;
    cancel;
    until_poll = Cancel.check_every;
    budget = 0;
    noise_sq = 0;
    noise_n = 0;
    _p0 = 0;
    _p1 = 0;
    _p2 = 0;
    _p3 = 0;
    _p4 = 0;
    _p5 = 0;
    _p6 = 0;
    _p7 = 0;
    _p8 = 0;
    _p9 = 0;
    _p10 = 0;
    _p11 = 0;
    _p12 = 0;
    _p13 = 0;
    _p14 = 0;
    _p15 = 0;
  }

let[@inline] spend s n =
  s.until_poll <- s.until_poll - n;
  if s.until_poll <= 0 then (
    s.until_poll <- Cancel.check_every;
    Cancel.check s.cancel)

let[@inline] tick s = spend s 1

(* The counters of the task a domain runs, found by one look-up by work that is not
   handed them (a CSG object's crossings); outside a task, counters nobody cancels. *)
type slot = { mutable task : t }

let slot_key = Domain.DLS.new_key (fun () -> { task = create () })
let current () = (Domain.DLS.get slot_key).task

let with_current s f =
  let slot = Domain.DLS.get slot_key in
  let before = slot.task in
  slot.task <- s;
  match f () with
  | v ->
      slot.task <- before;
      v
  | exception e ->
      slot.task <- before;
      raise e

let counters (s : t) : Counters.t =
  {
    primary = s.primary;
    shadow = s.shadow;
    reflected = s.reflected;
    refracted = s.refracted;
    bad_samples = s.bad_samples;
    first_bad = s.first_bad;
    noise_sq = s.noise_sq;
    noise_n = s.noise_n;
  }
