(* See farm.mli. The protocol, one worker at a time:

     worker                         rank 0
     Ready domains          ───▶
                            ◀───    Work { key; tiles } | Stop
     Done (unit, stats, wait, inputs) ───▶  (wait: seconds between its last request and
                                    the answer; inputs: the files its scene was made of)
     pixels (doubles)       ───▶    (same source, next message on its tag)
                            ◀───    Work … | Stop
     Failed message         ───▶    (instead of Done; rank 0 answers Stop from then on)

   Each worker has at most one request outstanding, so rank 0 answers them in any order.
   Rank 0 renders units as well, on a domain of its own (see [local] below). *)

open Lancer_job
open Work

type request =
  | Ready of int
  | Done of work_unit * Counters.t * float * (string * string) list
  | Failed of string

type reply = Work of work_unit | Stop

let tag_request = 1
let tag_pixels = 2
let tag_reply = 3

(* The floats of a unit travel as the rows of each tile in turn, 3 per pixel. Copying
   between [fb] and [buf] in one direction or the other. *)
let pixel_count (all : (int * int * int * int) array) idxs =
  Array.fold_left
    (fun acc k ->
      let x0, y0, x1, y1 = all.(k) in
      acc + (3 * (x1 - x0) * (y1 - y0)))
    0 idxs

let transfer ~to_buf (fb : Framebuffer.t) all idxs (buf : Mpi.floats) =
  let pos = ref 0 in
  Array.iter
    (fun k ->
      let x0, y0, x1, y1 = all.(k) in
      for j = y0 to y1 - 1 do
        let row = 3 * ((j * fb.width) + x0) in
        for c = 0 to (3 * (x1 - x0)) - 1 do
          if to_buf then
            Bigarray.Array1.unsafe_set buf (!pos + c)
              (Float.Array.unsafe_get fb.data (row + c))
          else
            Float.Array.unsafe_set fb.data (row + c)
              (Bigarray.Array1.unsafe_get buf (!pos + c))
        done;
        pos := !pos + (3 * (x1 - x0))
      done)
    idxs

let floats n = Bigarray.Array1.create Bigarray.float64 Bigarray.c_layout (max n 1)

exception Worker_failed of int * string

(* ---- Rank 0 ---- *)

let plan = Work.plan

(* What rank 0 learns about the scheme while serving: per rank, the units and tiles it
   rendered and how long it waited each time between handing in a unit and being given
   the next (seconds). *)
type report = { units : int array; tiles : int array; waits : float list array }

let percentile p = function
  | [] -> Float.nan
  | l ->
      let a = Array.of_list l in
      Array.sort Float.compare a;
      a.(max 0
           (min
              (Array.length a - 1)
              (int_of_float (Float.ceil (p *. Float.of_int (Array.length a))) - 1)))

let report_json r =
  let ms x =
    if not (Float.is_finite x) then `Null else `Float (Float.round (x *. 1e6) /. 1e3)
  in
  let waits l =
    `Assoc
      [
        ("count", `Int (List.length l));
        ("median", ms (percentile 0.5 l));
        ("p90", ms (percentile 0.9 l));
        ("max", ms (List.fold_left Float.max Float.neg_infinity l));
      ]
  in
  let others =
    List.concat (Array.to_list (Array.sub r.waits 1 (Array.length r.waits - 1)))
  in
  let rank k =
    `Assoc
      [
        ("rank", `Int k);
        ("units", `Int r.units.(k));
        ("tiles", `Int r.tiles.(k));
        ("wait_ms", waits r.waits.(k));
      ]
  in
  `Assoc
    [
      ("units", `Int (Array.fold_left ( + ) 0 r.units));
      ("reply_wait_ms", waits others);
      ("ranks", `List (List.init (Array.length r.units) rank));
    ]

(* Rank 0's own worker: a domain that renders, over rank 0's pool, the units the serving
   loop hands it, so that the serving loop (the only domain allowed to call MPI) stays
   free to answer the other ranks. One unit at a time is handed over under [lock]; the
   result comes back through [result] (with the time it was posted), which the serving
   loop polls between probes. *)
type local = {
  lock : Mutex.t;
  given : Condition.t;
  mutable task : (work_unit * frame) option;
  mutable quit : bool;
  result : (work_unit * (Counters.t, exn) result * float) option Atomic.t;
  crashed : exn option Atomic.t;
}

let local_worker ~render l () =
  let rec loop () =
    Mutex.lock l.lock;
    while Option.is_none l.task && not l.quit do
      Condition.wait l.given l.lock
    done;
    let task = l.task in
    l.task <- None;
    Mutex.unlock l.lock;
    match task with
    | None -> ()
    | Some (u, f) ->
        let r = try Ok (render f.sc f.fb u.tiles) with e -> Error e in
        Atomic.set l.result (Some (u, r, Unix.gettimeofday ()));
        loop ()
  in
  (* An interrupt raised on this domain outside a unit is handed on like one inside. *)
  try loop () with e -> Atomic.set l.crashed (Some e)

type renderer = pool:Pool.t option -> Scene.t -> Framebuffer.t -> int array -> Counters.t

(* The first file whose digest differs between a worker's scene and rank 0's, or that
   one of them read and the other did not. *)
let differing mine theirs =
  let differs b (f, d) =
    match List.assoc_opt f b with Some d' -> not (String.equal d d') | None -> true
  in
  match List.find_opt (differs theirs) mine with
  | Some (f, _) -> Some f
  | None -> Option.map fst (List.find_opt (differs mine) theirs)

let serve ?(start = fun _ -> None) ?(on_unit = fun _ _ _ -> ()) ?(inputs = fun _ -> None)
    ?(render : renderer option) ?(local = true) ?cancel ~fatal ~pool ~domains ~on_tiles
    ~on_frame frames =
  let ranks = Mpi.size () in
  let total_tiles = ref 0 in
  (* Every rank renders, rank 0 included. *)
  let c = Work.cutter ~start ~ranks frames in
  let report =
    {
      units = Array.make ranks 0;
      tiles = Array.make ranks 0;
      waits = Array.make ranks [];
    }
  in
  let failure = ref None in
  let finished key (f : frame) =
    match !failure with
    | Some _ -> ()
    | None -> ( try on_frame key f.sc f.fb f.st with e -> failure := Some e)
  in
  let deposit rank key tiles st =
    let n = Array.length tiles in
    let complete = Work.deposit c key tiles st in
    on_unit key tiles st;
    total_tiles := !total_tiles + n;
    report.units.(rank) <- report.units.(rank) + 1;
    report.tiles.(rank) <- report.tiles.(rank) + n;
    Option.iter (finished key) complete
  in
  (if ranks = 1 then
     (* One rank works alone: whole frames over its own pool, progress tile by tile. *)
     let rec loop () =
       match (!failure, Work.next c ~domains) with
       | Some _, _ | None, None -> ()
       | None, Some u ->
           let f = Work.frame c u.key in
           let base = !total_tiles and done_ = Atomic.make 0 in
           let on_tile () = on_tiles (base + Atomic.fetch_and_add done_ 1 + 1) in
           let st =
             match render with
             | Some r -> r ~pool f.sc f.fb u.tiles
             | None -> render_unit ?cancel ~on_tile ~pool f.sc f.fb u.tiles
           in
           deposit 0 u.key u.tiles st;
           loop ()
     in
     loop ()
   else
     let render =
       match render with
       | Some r -> r ~pool
       | None -> fun sc fb tiles -> render_unit ?cancel ~pool sc fb tiles
     in
     let buf = ref (floats 0) in
     let active = ref (ranks - 1) in
     let rank_domains = Array.make ranks 1 in
     let reply dest =
       let r =
         match !failure with
         | Some _ -> None
         | None -> Work.next c ~domains:rank_domains.(dest)
       in
       match r with
       | Some u -> Mpi.send (Work u) ~dest ~tag:tag_reply
       | None ->
           Mpi.send Stop ~dest ~tag:tag_reply;
           decr active
     in
     let l =
       {
         lock = Mutex.create ();
         given = Condition.create ();
         task = None;
         quit = false;
         result = Atomic.make None;
         crashed = Atomic.make None;
       }
     in
     (* While rank 0's worker lives, an interrupt only cancels the token, as it does
        while a pool lives ({!Render.with_pool}): raised by the signal handler in either
        domain, it could leave [l.lock] held (the worker interrupted in its wait) and the
        serving loop blocked on it. The serving loop polls the token
        ([collect_local]), the worker's renders too. *)
     let deferred f = match cancel with Some t -> Cancel.deferring t f | None -> f () in
     deferred @@ fun () ->
     let helper = Domain.spawn (local_worker ~render l) in
     let stop_local () =
       Mutex.lock l.lock;
       l.quit <- true;
       Condition.signal l.given;
       Mutex.unlock l.lock;
       Domain.join helper
     in
     (* Whether rank 0's worker has a unit. *)
     let local_busy = ref false in
     let feed_local ~posted =
       match match !failure with Some _ -> None | None -> Work.next c ~domains with
       | None -> ()
       | Some u ->
           Option.iter
             (fun t ->
               report.waits.(0) <- (Unix.gettimeofday () -. t) :: report.waits.(0))
             posted;
           Mutex.lock l.lock;
           l.task <- Some (u, Work.frame c u.key);
           Condition.signal l.given;
           Mutex.unlock l.lock;
           local_busy := true
     in
     (* Rank 0's own unit, if it is done: deposited, and the next one handed over. *)
     let collect_local () =
       Option.iter raise (Atomic.get l.crashed);
       Option.iter Cancel.check cancel;
       match Atomic.get l.result with
       | None -> false
       | Some (u, r, posted) ->
           Atomic.set l.result None;
           local_busy := false;
           (match r with
           | Ok st ->
               deposit 0 u.key u.tiles st;
               on_tiles !total_tiles
           | Error Sys.Break -> raise Sys.Break
           | Error e -> if !failure = None then failure := Some e);
           feed_local ~posted:(Some posted);
           true
     in
     let handle src =
       let (req : request), _, _ = Mpi.recv ~source:src ~tag:tag_request in
       match req with
       | Ready d ->
           rank_domains.(src) <- max 1 d;
           reply src
       | Done (u, st, waited, theirs) -> (
           let f = Work.frame c u.key in
           let n = pixel_count f.all u.tiles in
           if Bigarray.Array1.dim !buf < n then buf := floats n;
           let count, _, _ = Mpi.recv_floats !buf ~source:src ~tag:tag_pixels in
           if count <> n then
             failwith
               (Printf.sprintf "rank %d sent %d floats for a unit of %d" src count n);
           report.waits.(src) <- waited :: report.waits.(src);
           (* Pixels made of other bytes than rank 0's scene are refused, not mixed in. *)
           match Option.bind (inputs u.key) (fun mine -> differing mine theirs) with
           | Some file ->
               if !failure = None then
                 failure :=
                   Some
                     (Worker_failed
                        ( src,
                          Printf.sprintf
                            "it read %s with other contents than rank 0 did: the file \
                             changed while the job ran; run again"
                            file ));
               reply src
           | None ->
               transfer ~to_buf:false f.fb f.all u.tiles !buf;
               deposit src u.key u.tiles st;
               on_tiles !total_tiles;
               reply src)
       | Failed m ->
           if !failure = None then failure := Some (Worker_failed (src, m));
           reply src
     in
     (* Serve without spinning, so that rank 0 leaves the cores to the rendering domains
       (MPI's blocking probe polls at full speed), yet answers within a quarter of a
       millisecond: a worker waits for its next unit meanwhile. *)
     let pause = ref 0.00002 in
     (* An exception here leaves workers waiting for an answer: end the whole job. *)
     (try
        if local then feed_local ~posted:None;
        while !active > 0 || !local_busy do
          let mine = collect_local () in
          let theirs =
            match Mpi.iprobe ~source:Mpi.any_source ~tag:tag_request with
            | Some (src, _, _) ->
                handle src;
                true
            | None -> false
          in
          if mine || theirs then pause := 0.00002
          else (
            Unix.sleepf !pause;
            pause := Float.min 0.00025 (!pause *. 2.))
        done
      with e -> Mpi.abort (fatal e));
     stop_local ());
  match !failure with Some e -> raise e | None -> report

(* ---- Other ranks ---- *)

let work ?cancel ?render ?(prepare = ignore) ~describe ~pool ~domains scene_of =
  let render : renderer =
    match render with
    | Some r -> r
    | None -> fun ~pool sc fb tiles -> render_unit ?cancel ~pool sc fb tiles
  in
  let cache = ref None in
  let scene key =
    match !cache with
    | Some (k, sc, inputs, all, fb) when k = key -> (sc, inputs, all, fb)
    | _ ->
        let (sc : Scene.t), inputs = scene_of key in
        let fb =
          match !cache with
          | Some (_, _, _, _, (fb : Framebuffer.t))
            when fb.width = sc.settings.width && fb.height = sc.settings.height ->
              fb
          | _ -> Framebuffer.create sc.settings.width sc.settings.height
        in
        let all = Render.tiles sc in
        cache := Some (key, sc, inputs, all, fb);
        (sc, inputs, all, fb)
  in
  let buf = ref (floats 0) in
  (* [asked]: when this rank last handed in a request; the wait until the answer goes
     back to rank 0 with the unit it brought. *)
  let rec loop asked =
    match (Mpi.recv ~source:0 ~tag:tag_reply : reply * int * int) with
    | Stop, _, _ -> ()
    | Work u, _, _ -> (
        let waited = Unix.gettimeofday () -. asked in
        match
          let sc, inputs, all, fb = scene u.key in
          let st = render ~pool sc fb u.tiles in
          let n = pixel_count all u.tiles in
          if Bigarray.Array1.dim !buf < n then buf := floats n;
          transfer ~to_buf:true fb all u.tiles !buf;
          (st, n, inputs)
        with
        | st, n, inputs ->
            let asked = Unix.gettimeofday () in
            Mpi.send (Done (u, st, waited, inputs)) ~dest:0 ~tag:tag_request;
            Mpi.send_floats !buf ~len:n ~dest:0 ~tag:tag_pixels;
            loop asked
        | exception (Sys.Break as e) -> raise e
        | exception e ->
            let asked = Unix.gettimeofday () in
            Mpi.send (Failed (describe e)) ~dest:0 ~tag:tag_request;
            loop asked)
  in
  (* Anything unexpected here (an interrupt, a broken message) leaves rank 0 waiting:
     end the whole job. Rank 0 tells the user. *)
  try
    let asked = Unix.gettimeofday () in
    (* What the rank cannot prepare is its first message, so that rank 0, which waits
       for every rank, always hears of it. *)
    (match prepare () with
    | () -> Mpi.send (Ready domains) ~dest:0 ~tag:tag_request
    | exception (Sys.Break as e) -> raise e
    | exception e -> Mpi.send (Failed (describe e)) ~dest:0 ~tag:tag_request);
    loop asked
  with e -> Mpi.abort (match e with Sys.Break -> 130 | _ -> 2)
