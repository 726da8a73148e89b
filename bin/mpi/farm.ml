(* See farm.mli. The protocol, one worker at a time:

     worker                         rank 0
     Ready domains          ───▶
                            ◀───    Work { key; tiles } | Stop
     Done (unit, stats)     ───▶
     pixels (doubles)       ───▶    (same source, next message on its tag)
                            ◀───    Work … | Stop
     Failed message         ───▶    (instead of Done; rank 0 answers Stop from then on)

   Each worker has at most one request outstanding, so rank 0 answers them in any order. *)

open Lancer

type work_unit = { key : int; tiles : int array }
type request = Ready of int | Done of work_unit * Stats.t | Failed of string
type reply = Work of work_unit | Stop

let tag_request = 1
let tag_pixels = 2
let tag_reply = 3

let render_unit ?(on_tile = fun () -> ()) ~pool sc fb idxs =
  let all = Render.tiles sc in
  let n = Array.length idxs in
  let stats = Array.init n (fun _ -> Stats.create ()) in
  let body i =
    let x0, y0, x1, y1 = all.(idxs.(i)) in
    Render.render_tile sc stats.(i) fb x0 y0 x1 y1;
    on_tile ()
  in
  (match pool with
  | None -> for i = 0 to n - 1 do body i done
  | Some pool ->
      Pool.parallel_for pool n body);
  let total = Stats.create () in
  Array.iter (Stats.add_into total) stats;
  total

(* The floats of a unit travel as the rows of each tile in turn, 3 per pixel. Copying
   between [fb] and [buf] in one direction or the other. *)
let pixel_count (all : (int * int * int * int) array) idxs =
  Array.fold_left (fun acc k -> let x0, y0, x1, y1 = all.(k) in acc + (3 * (x1 - x0) * (y1 - y0))) 0 idxs

let transfer ~to_buf (fb : Image.t) all idxs (buf : Mpi.floats) =
  let pos = ref 0 in
  Array.iter
    (fun k ->
      let x0, y0, x1, y1 = all.(k) in
      for j = y0 to y1 - 1 do
        let row = 3 * ((j * fb.width) + x0) in
        for c = 0 to (3 * (x1 - x0)) - 1 do
          if to_buf then Bigarray.Array1.unsafe_set buf (!pos + c) (Float.Array.unsafe_get fb.data (row + c))
          else Float.Array.unsafe_set fb.data (row + c) (Bigarray.Array1.unsafe_get buf (!pos + c))
        done;
        pos := !pos + (3 * (x1 - x0))
      done)
    idxs

let floats n = Bigarray.Array1.create Bigarray.float64 Bigarray.c_layout (max n 1)
exception Worker_failed of int * string

(* ---- Rank 0 ---- *)

(* A frame whose units are out: its framebuffer, and how many tiles are still to come. *)
type open_frame = {
  sc : Scene.t;
  all : (int * int * int * int) array;
  todo : int array;  (* the tiles to render: all of them, or those a checkpoint lacks *)
  fb : Image.t;
  mutable left : int;
  st : Stats.t;
}

(* Units are cut from [frames] in order. With [whole] a unit is a frame; otherwise at
   most [chunk] tiles, or what the worker asked for if less. *)
type cutter = {
  mutable pending : (int * (unit -> Scene.t)) list;
  mutable current : (int * open_frame * int ref) option;  (* key, frame, next tile *)
  opened : (int, open_frame) Hashtbl.t;
  whole : bool;
  mutable chunk : int;
  start : int -> (Image.t * int array) option;
}

let open_next c =
  match c.pending with
  | [] -> None
  | (key, scene) :: rest ->
      c.pending <- rest;
      let sc = scene () in
      let all = Render.tiles sc in
      let fb, todo =
        match c.start key with
        | Some (fb, todo) -> (fb, todo)
        | None -> (Image.create sc.settings.width sc.settings.height, Array.init (Array.length all) Fun.id)
      in
      let f = { sc; all; todo; fb; left = Array.length todo; st = Stats.create () } in
      Hashtbl.replace c.opened key f;
      Some (key, f)

let rec next_unit c ~want =
  match c.current with
  | Some (key, f, next) when !next < Array.length f.todo ->
      let n = min (Array.length f.todo - !next) (if c.whole then max_int else min want c.chunk) in
      let u = { key; tiles = Array.sub f.todo !next n } in
      next := !next + n;
      Some u
  | _ -> (
      match open_next c with
      | None -> None
      | Some (key, f) ->
          c.current <- Some (key, f, ref 0);
          next_unit c ~want)

let serve ?(start = fun _ -> None) ?(on_unit = fun _ _ _ -> ()) ~fatal ~pool ~frames ~on_tiles ~on_frame () =
  let workers = Mpi.size () - 1 in
  let total_tiles = ref 0 in
  (* One frame alone (a still) is always cut, so that units come back, and can be kept,
     as the render goes. *)
  let whole = workers = 0 || (List.length frames >= workers && List.length frames > 1) in
  let c = { pending = frames; current = None; opened = Hashtbl.create 8; whole; chunk = max_int; start } in
  (* Otherwise chunks small enough that every worker gets several, for an even finish:
     sized from the first frame's tile count, cut now. *)
  if not whole then begin
    match open_next c with
    | Some (key, f) ->
        c.current <- Some (key, f, ref 0);
        c.chunk <- max 1 (Array.length f.todo * List.length frames / (4 * workers))
    | None -> ()
  end;
  let failure = ref None in
  let finished key f =
    Hashtbl.remove c.opened key;
    match !failure with
    | Some _ -> ()
    | None -> ( try on_frame key f.sc f.fb f.st with e -> failure := Some e)
  in
  let deposit key tiles st =
    let n = Array.length tiles in
    let f = Hashtbl.find c.opened key in
    f.left <- f.left - n;
    Stats.add_into f.st st;
    on_unit key tiles st;
    total_tiles := !total_tiles + n;
    if f.left = 0 then finished key f
  in
  if workers = 0 then begin
    (* One rank works alone: whole frames over its own pool, progress tile by tile. *)
    let rec loop () =
      match (!failure, next_unit c ~want:max_int) with
      | Some _, _ | None, None -> ()
      | None, Some u ->
          let f = Hashtbl.find c.opened u.key in
          let base = !total_tiles and done_ = Atomic.make 0 in
          let on_tile () = on_tiles (base + Atomic.fetch_and_add done_ 1 + 1) in
          deposit u.key u.tiles (render_unit ~on_tile ~pool f.sc f.fb u.tiles);
          loop ()
    in
    loop ()
  end
  else begin
    let buf = ref (floats 0) in
    let active = ref workers in
    let reply dest ~want =
      let r = match !failure with Some _ -> None | None -> next_unit c ~want in
      match r with
      | Some u -> Mpi.send (Work u) ~dest ~tag:tag_reply
      | None ->
          Mpi.send Stop ~dest ~tag:tag_reply;
          decr active
    in
    let wants = Array.make (workers + 1) 1 in
    (* Wait for a request without spinning, so that rank 0 leaves the cores to the
       workers (MPI's blocking probe polls at full speed), yet answers within a quarter
       of a millisecond: a worker waits for its next unit meanwhile. *)
    let rec wait pause =
      match Mpi.iprobe ~source:Mpi.any_source ~tag:tag_request with
      | Some (src, _, _) -> src
      | None ->
          Unix.sleepf pause;
          wait (Float.min 0.00025 (pause *. 2.))
    in
    (* An exception here leaves workers waiting for an answer: end the whole job. *)
    try
    while !active > 0 do
      let src = wait 0.00002 in
      let (req : request), _, _ = Mpi.recv ~source:src ~tag:tag_request in
      match req with
      | Ready d ->
          wants.(src) <- max 1 (4 * d);
          reply src ~want:wants.(src)
      | Done (u, st) ->
          let f = Hashtbl.find c.opened u.key in
          let n = pixel_count f.all u.tiles in
          if Bigarray.Array1.dim !buf < n then buf := floats n;
          let count, _, _ = Mpi.recv_floats !buf ~source:src ~tag:tag_pixels in
          if count <> n then failwith (Printf.sprintf "rank %d sent %d floats for a unit of %d" src count n);
          transfer ~to_buf:false f.fb f.all u.tiles !buf;
          deposit u.key u.tiles st;
          on_tiles !total_tiles;
          reply src ~want:wants.(src)
      | Failed m ->
          if !failure = None then failure := Some (Worker_failed (src, m));
          reply src ~want:0
    done
    with e -> Mpi.abort (fatal e)
  end;
  match !failure with Some e -> raise e | None -> ()

(* ---- Other ranks ---- *)

let work ~describe ~pool ~domains ~scene_of =
  let cache = ref None in
  let scene key =
    match !cache with
    | Some (k, sc, all, fb) when k = key -> (sc, all, fb)
    | _ ->
        let (sc : Scene.t) = scene_of key in
        let fb =
          match !cache with
          | Some (_, _, _, (fb : Image.t)) when fb.width = sc.settings.width && fb.height = sc.settings.height -> fb
          | _ -> Image.create sc.settings.width sc.settings.height
        in
        let all = Render.tiles sc in
        cache := Some (key, sc, all, fb);
        (sc, all, fb)
  in
  let buf = ref (floats 0) in
  let rec loop () =
    match (Mpi.recv ~source:0 ~tag:tag_reply : reply * int * int) with
    | Stop, _, _ -> ()
    | Work u, _, _ ->
        (match
           let sc, all, fb = scene u.key in
           let st = render_unit ~pool sc fb u.tiles in
           let n = pixel_count all u.tiles in
           if Bigarray.Array1.dim !buf < n then buf := floats n;
           transfer ~to_buf:true fb all u.tiles !buf;
           (st, n)
         with
        | st, n ->
            Mpi.send (Done (u, st)) ~dest:0 ~tag:tag_request;
            Mpi.send_floats !buf ~len:n ~dest:0 ~tag:tag_pixels
        | exception (Sys.Break as e) -> raise e
        | exception e -> Mpi.send (Failed (describe e)) ~dest:0 ~tag:tag_request);
        loop ()
  in
  (* Anything unexpected here (an interrupt, a broken message) leaves rank 0 waiting:
     end the whole job. Rank 0 tells the user. *)
  try
    Mpi.send (Ready domains) ~dest:0 ~tag:tag_request;
    loop ()
  with e -> Mpi.abort (match e with Sys.Break -> 130 | _ -> 2)
