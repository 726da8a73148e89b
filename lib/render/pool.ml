(* One job at a time: a loop body, its bounds and an atomic "next index". Workers sleep on
   [wake] until [generation] changes, take the job if it is still posted, run indices
   until none is left, then report on [finished]. *)

type job = {
  body : int -> unit;
  n : int;
  next : int Atomic.t;
  failed : (exn * Printexc.raw_backtrace) option Atomic.t;
}

type t = {
  mutable size : int;
  lock : Mutex.t;
  wake : Condition.t;
  finished : Condition.t;
  mutable generation : int;
  mutable job : job option;
  mutable busy : int;  (** workers inside the current job *)
  mutable started : int;  (** workers that have begun running *)
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

(* A worker counts itself in a job as it takes it, so that the caller waits for exactly
   the workers inside it: one that wakes after the job is over finds none posted. *)
let worker t () =
  Mutex.lock t.lock;
  t.started <- t.started + 1;
  Condition.broadcast t.finished;
  Mutex.unlock t.lock;
  let seen = ref 0 in
  let rec loop () =
    Mutex.lock t.lock;
    while (not t.stop) && t.generation = !seen do
      Condition.wait t.wake t.lock
    done;
    if t.stop then Mutex.unlock t.lock
    else (
      seen := t.generation;
      match t.job with
      | None ->
          Mutex.unlock t.lock;
          loop ()
      | Some j ->
          t.busy <- t.busy + 1;
          Mutex.unlock t.lock;
          work j;
          Mutex.lock t.lock;
          t.busy <- t.busy - 1;
          if t.busy = 0 then Condition.broadcast t.finished;
          Mutex.unlock t.lock;
          loop ())
  in
  loop ()

(* ---- Room for a domain ----

   Under a limit on the address space (ulimit -v), a domain that cannot be started is
   not always reported: its thread starts, and when the runtime's backup thread of that
   domain then finds no room for its stack, the runtime raises Failure in the new thread,
   where nothing can catch it; reporting it runs code of a domain not yet set up, and the
   process dies of a segmentation fault. So under a limit a domain is started only while
   the room left holds what starting it takes: the stacks of its thread, of its backup
   thread and of this domain's own backup thread (started with the first domain it
   spawns), a malloc arena for the new thread (64 MiB), and a margin for the rest (signal
   stack, first fiber stack, heap pools). Each domain is waited for until it runs, so
   that the next one's room is measured with the previous one's threads in place. *)

let mib = 1024 * 1024

(* A field of a /proc file whose lines are "Name: value…", as its words. *)
let proc_field file name =
  match In_channel.with_open_text file In_channel.input_all with
  | exception Sys_error _ -> None
  | text ->
      List.find_map
        (fun line ->
          if String.starts_with ~prefix:name line then
            let rest =
              String.sub line (String.length name)
                (String.length line - String.length name)
            in
            Some (List.filter (( <> ) "") (String.split_on_char ' ' (String.trim rest)))
          else None)
        (String.split_on_char '\n' text)

(* The address space in use, in bytes. *)
let used () =
  match proc_field "/proc/self/status" "VmSize:" with
  | Some [ kb; "kB" ] -> Option.map (fun k -> k * 1024) (int_of_string_opt kb)
  | _ -> None

(* A new thread's stack: the soft stack limit, or 8 MiB when unlimited (more than glibc
   takes then). *)
let thread_stack () =
  match proc_field "/proc/self/limits" "Max stack size" with
  | Some (soft :: _) -> Option.value (int_of_string_opt soft) ~default:(8 * mib)
  | _ -> 8 * mib

let room_for_domain () =
  match Address_space.limit () with
  | None -> true
  | Some limit -> (
      match used () with
      | None -> true
      | Some used -> limit - used >= (3 * thread_stack ()) + (64 * mib) + (16 * mib))

let create n =
  let t =
    {
      size = 1;
      lock = Mutex.create ();
      wake = Condition.create ();
      finished = Condition.create ();
      generation = 0;
      job = None;
      busy = 0;
      started = 0;
      stop = false;
      domains = [];
    }
  in
  (* A domain the system has no room for (Domain.spawn's Failure "failed to create domain
     thread", "failed to allocate domain", or Out_of_memory) ends the spawning: the pool
     works with the domains it has. A worker whose domain started although its spawn
     failed (the spawning domain's backup thread could not be created) takes jobs like the
     others and stops with them. *)
  let rec spawn k =
    if k > 0 && room_for_domain () then
      match Domain.spawn (worker t) with
      | d ->
          Mutex.lock t.lock;
          while t.started < t.size do
            Condition.wait t.finished t.lock
          done;
          t.size <- t.size + 1;
          t.domains <- d :: t.domains;
          Mutex.unlock t.lock;
          spawn (k - 1)
      | exception (Failure _ | Out_of_memory) -> ()
  in
  spawn (n - 1);
  t

let parallel_for t n body =
  if n > 0 then (
    let j = { body; n; next = Atomic.make 0; failed = Atomic.make None } in
    Mutex.lock t.lock;
    t.job <- Some j;
    t.generation <- t.generation + 1;
    Condition.broadcast t.wake;
    Mutex.unlock t.lock;
    (* The caller works too; whatever it raises is recorded like a worker's. *)
    work j;
    Mutex.lock t.lock;
    while t.busy > 0 do
      Condition.wait t.finished t.lock
    done;
    t.job <- None;
    Mutex.unlock t.lock;
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
