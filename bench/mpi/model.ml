(* The scaling model of lancer-mpi (make bench-mpi, bench/mpi/bench.sh): the time of a job
   on N ranks of d domains, predicted from figures measured on one machine. It replays
   the job as lancer-mpi runs it: the units are those Farm.plan cuts, in its order, and
   whichever rank is free first asks rank 0 for the next one (on demand). Rank 0's
   serving domain is one queue: each request it answers costs it the measured time per
   unit and per byte of the unit handed in; opening a frame costs it that frame's scene
   evaluation and finishing one costs it the write, before it answers. A unit's tiles
   are spread over the rank's domains in order, each tile costing its pixel count times
   the measured time per pixel; a rank evaluates a frame's scene the first time it gets
   one of its units. The fixed cost (mpirun, start-up, evaluating the scene, writing
   nothing) is added as measured.

   usage: model.exe KEY=VALUE ... ; keys (seconds unless said):
     width, height, frames     the job
     ranks, domains            N and d
     cores                     cores that run them (default N·d; fewer slows rendering)
     pixel                     one domain's render time per pixel
     eval                      a frame's scene evaluation (0 for a still: it is fixed cost)
     write                     writing one finished frame
     unit, byte                rank 0's serving time per unit and per byte handed in
     link_gbps                 rank 0's link in Gbit/s (0: none, the ranks share memory)
     fixed                     the fixed cost at this N
   Prints: seconds S render_seconds R server_busy B units U limit L bound WHAT, where
   WHAT is the largest part of the time and L the largest but the rendering itself (the
   words joined by _). *)
module Farm = Lancer_mpi.Farm

let () =
  let args = Hashtbl.create 16 in
  Array.iteri
    (fun i a ->
      if i > 0 then
        match String.index_opt a '=' with
        | Some k ->
            Hashtbl.replace args (String.sub a 0 k)
              (float_of_string (String.sub a (k + 1) (String.length a - k - 1)))
        | None ->
            prerr_endline ("model: not KEY=VALUE: " ^ a);
            exit 1)
    Sys.argv;
  let get ?default k =
    match (Hashtbl.find_opt args k, default) with
    | Some v, _ -> v
    | None, Some d -> d
    | None, None ->
        prerr_endline ("model: missing " ^ k);
        exit 1
  in
  let width = int_of_float (get "width") and height = int_of_float (get "height") in
  let frames = int_of_float (get ~default:1. "frames") in
  let ranks = int_of_float (get "ranks")
  and domains = int_of_float (get ~default:1. "domains") in
  let cores = get ~default:(Float.of_int (ranks * domains)) "cores" in
  let pixel = get "pixel"
  and eval = get ~default:0. "eval"
  and write = get ~default:0. "write" in
  let per_unit = get "unit" and per_byte = get "byte" in
  let link = get ~default:0. "link_gbps" in
  let fixed = get ~default:0. "fixed" in
  let per_byte = per_byte +. if link > 0. then 8. /. (link *. 1e9) else 0. in
  (* Rendering domains beyond the cores share them. *)
  let slow = Float.max 1. (Float.of_int (ranks * domains) /. cores) in
  let ts = Lancer.Render.tile_size in
  let tiles =
    Array.concat
      (List.init
         ((height + ts - 1) / ts)
         (fun j ->
           Array.init
             ((width + ts - 1) / ts)
             (fun i -> min ts (width - (i * ts)) * min ts (height - (j * ts)))))
  in
  let units =
    Farm.plan ~ranks ~domains (List.init frames (fun _ -> Array.length tiles))
  in
  (* A unit of [k] tiles from tile [first], its tiles in order to the first free domain. *)
  let duration first k =
    let free = Array.make domains 0. in
    for t = first to first + k - 1 do
      let m = ref 0 in
      Array.iteri (fun i f -> if Float.compare f free.(!m) < 0 then m := i) free;
      free.(!m) <- free.(!m) +. (Float.of_int tiles.(t) *. pixel *. slow)
    done;
    Array.fold_left Float.max 0. free
  in
  let next_tile = Array.make frames 0 and left = Array.make frames 0 in
  List.iter (fun (f, _) -> left.(f) <- left.(f) + 1) units;
  let free = Array.make ranks 0. in
  let holding = Array.make ranks None and last_frame = Array.make ranks (-1) in
  let server = ref 0. and busy = ref 0. and render = ref 0. in
  (* Rank 0's serving domain's time, by what it was spent on. *)
  let on_units = ref 0.
  and on_bytes = ref 0.
  and on_writes = ref 0.
  and on_evals = ref 0. in
  let serve t cost =
    server := Float.max t !server +. cost;
    busy := !busy +. cost
  in
  (* Rank [i] hands in what it holds at [t]: rank 0's own unit costs its server nothing
     but the write of a frame it completes. *)
  let hand_in i t =
    let units, bytes, writes =
      match holding.(i) with
      | None -> ((if i = 0 then 0. else per_unit), 0., 0.)
      | Some (f, px) ->
          left.(f) <- left.(f) - 1;
          ( (if i = 0 then 0. else per_unit),
            (if i = 0 then 0. else Float.of_int (24 * px) *. per_byte),
            if left.(f) = 0 then write else 0. )
    in
    on_units := !on_units +. units;
    on_bytes := !on_bytes +. bytes;
    on_writes := !on_writes +. writes;
    let cost = units +. bytes +. writes in
    holding.(i) <- None;
    serve t cost
  in
  List.iter
    (fun (f, k) ->
      let i = ref 0 in
      Array.iteri (fun r t -> if Float.compare t free.(!i) < 0 then i := r) free;
      let i = !i in
      hand_in i free.(i);
      if next_tile.(f) = 0 then (
        serve !server eval;
        on_evals := !on_evals +. eval);
      let first = next_tile.(f) in
      next_tile.(f) <- first + k;
      let d = duration first k +. if last_frame.(i) <> f then eval else 0. in
      last_frame.(i) <- f;
      let px = ref 0 in
      for t = first to first + k - 1 do
        px := !px + tiles.(t)
      done;
      holding.(i) <- Some (f, !px);
      render := Float.max !render (!server +. d);
      free.(i) <- !server +. d)
    units;
  (* The last hand-ins, in the order the ranks finish. *)
  let order =
    List.sort (fun a b -> Float.compare free.(a) free.(b)) (List.init ranks Fun.id)
  in
  List.iter (fun i -> if holding.(i) <> None || i > 0 then hand_in i free.(i)) order;
  let total = fixed +. !server in
  (* What bounds the job: the largest of the fixed cost, the rendering itself spread
     evenly over every domain, the time ranks spend idle (uneven units) or waiting for a
     busy rank 0, and each kind of rank 0's serial work. *)
  let pixels = Float.of_int (Array.fold_left ( + ) 0 tiles * frames) in
  let even = pixels *. pixel *. slow /. Float.of_int (ranks * domains) in
  let parts =
    [
      ("fixed cost", fixed);
      ("rendering", even);
      ("ranks idle or waiting for rank 0", !render -. even);
      ("rank 0 writing frames", !on_writes);
      ("rank 0 evaluating frames", !on_evals);
      ("rank 0 receiving bytes", !on_bytes);
      ("rank 0 answering requests", !on_units);
    ]
  in
  let largest parts =
    fst
      (List.fold_left
         (fun (b, v) (n, x) -> if Float.compare x v > 0 then (n, x) else (b, v))
         ("rendering", Float.neg_infinity)
         parts)
  in
  let word s = String.concat "_" (String.split_on_char ' ' s) in
  (* [limit]: the largest part that is not rendering, what keeps the job from scaling. *)
  Printf.printf
    "seconds %.4f render_seconds %.4f server_busy %.4f units %d limit %s bound %s\n" total
    !render !busy (List.length units)
    (word (largest (List.filter (fun (n, _) -> n <> "rendering") parts)))
    (word (largest parts))
