(* One job at a time: a loop body, its bounds and an atomic "next index". Workers sleep on
   [wake] until [generation] changes, run indices until none is left, then report on
   [finished]. *)

type job = {
  body : int -> unit;
  n : int;
  next : int Atomic.t;
  failed : (exn * Printexc.raw_backtrace) option Atomic.t;
}

type t = {
  size : int;
  lock : Mutex.t;
  wake : Condition.t;
  finished : Condition.t;
  mutable generation : int;
  mutable job : job option;
  mutable busy : int;  (** workers still inside the current job *)
  mutable stop : bool;
  mutable domains : unit Domain.t list;
}

let size t = t.size

(* Run indices of [j] until none is left or one has failed. *)
let work j =
  let rec go () =
    if Option.is_none (Atomic.get j.failed) then
      let i = Atomic.fetch_and_add j.next 1 in
      if i < j.n then (
        (try j.body i
         with e ->
           let bt = Printexc.get_raw_backtrace () in
           ignore (Atomic.compare_and_set j.failed None (Some (e, bt))));
        go ())
  in
  go ()

let worker t () =
  let seen = ref 0 in
  let rec loop () =
    Mutex.lock t.lock;
    while (not t.stop) && t.generation = !seen do
      Condition.wait t.wake t.lock
    done;
    if t.stop then Mutex.unlock t.lock
    else (
      seen := t.generation;
      let j = t.job in
      Mutex.unlock t.lock;
      Option.iter work j;
      Mutex.lock t.lock;
      t.busy <- t.busy - 1;
      if t.busy = 0 then Condition.broadcast t.finished;
      Mutex.unlock t.lock;
      loop ())
  in
  loop ()

let create n =
  let t =
    {
      size = max 1 n;
      lock = Mutex.create ();
      wake = Condition.create ();
      finished = Condition.create ();
      generation = 0;
      job = None;
      busy = 0;
      stop = false;
      domains = [];
    }
  in
  t.domains <- List.init (t.size - 1) (fun _ -> Domain.spawn (worker t));
  t

let parallel_for t n body =
  if n > 0 then (
    let j = { body; n; next = Atomic.make 0; failed = Atomic.make None } in
    let workers = t.size - 1 in
    if workers > 0 then (
      Mutex.lock t.lock;
      t.job <- Some j;
      t.busy <- workers;
      t.generation <- t.generation + 1;
      Condition.broadcast t.wake;
      Mutex.unlock t.lock);
    (* The caller works too; whatever it raises is recorded like a worker's. *)
    work j;
    if workers > 0 then (
      Mutex.lock t.lock;
      while t.busy > 0 do
        Condition.wait t.finished t.lock
      done;
      t.job <- None;
      Mutex.unlock t.lock);
    match Atomic.get j.failed with
    | Some (e, bt) -> Printexc.raise_with_backtrace e bt
    | None -> ())

let teardown t =
  Mutex.lock t.lock;
  t.stop <- true;
  Condition.broadcast t.wake;
  Mutex.unlock t.lock;
  List.iter Domain.join t.domains;
  t.domains <- []
