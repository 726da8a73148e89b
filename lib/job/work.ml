type work_unit = { key : int; tiles : int array }

let render_unit ?cancel ?(on_tile = fun () -> ()) ~pool sc fb idxs =
  Render.render_tiles ?cancel ?pool ~on_tile:(fun _ _ _ -> on_tile ()) sc fb idxs

(* The sizes of units: the rules {!plan} and the cutter share. Whole frames when every
   rank can have one; one frame alone (a still) is always cut, so that units come back,
   and can be kept, as the render goes. *)
let whole_frames ~ranks ~frames = ranks = 1 || (frames >= ranks && frames > 1)

(* A still, or fewer frames than ranks: chunks small enough that every rank gets several,
   for an even finish. *)
let chunk ~ranks ~frames ~tiles =
  if whole_frames ~ranks ~frames then None
  else Some (max 1 (tiles * frames / (4 * ranks)))

(* What a rank of [domains] domains is given: about four tiles per domain at most, and
   never fewer tiles than it has domains (while the frame has them), even when that
   leaves fewer units than ranks: a unit of fewer tiles leaves domains idle and costs
   rank 0 as much to serve, so many ranks of one-tile units finish later. *)
let unit_tiles ~chunk ~domains = min (max 1 (4 * domains)) (max domains chunk)

let plan ~ranks ~domains tiles =
  let frames = List.length tiles in
  let cap =
    match tiles with
    | [] -> max_int
    | first :: _ -> (
        match chunk ~ranks ~frames ~tiles:first with
        | None -> max_int
        | Some chunk -> unit_tiles ~chunk ~domains)
  in
  List.concat
    (List.mapi
       (fun k n ->
         let rec cut from =
           if from >= n then []
           else (k, min cap (n - from)) :: cut (from + min cap (n - from))
         in
         cut 0)
       tiles)

type frame = {
  sc : Scene.t;
  all : (int * int * int * int) array;
  todo : int array;
  fb : Framebuffer.t;
  mutable left : int;
  mutable st : Counters.t;
}

(* Units are cut from [pending] in order. With [whole] a unit is a frame; otherwise
   [unit_tiles] of [chunk] and the domains of the rank that asks. *)
type cutter = {
  mutable pending : (int * (unit -> Scene.t)) list;
  mutable current : (int * frame * int ref) option; (* key, frame, next tile *)
  opened : (int, frame) Hashtbl.t;
  whole : bool;
  mutable chunk : int;
  start : int -> (Framebuffer.t * int array) option;
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
        | None ->
            ( Framebuffer.create sc.settings.width sc.settings.height,
              Array.init (Array.length all) Fun.id )
      in
      let f = { sc; all; todo; fb; left = Array.length todo; st = Counters.zero } in
      Hashtbl.replace c.opened key f;
      Some (key, f)

let cutter ?(start = fun _ -> None) ~ranks frames =
  let whole = whole_frames ~ranks ~frames:(List.length frames) in
  let c =
    {
      pending = frames;
      current = None;
      opened = Hashtbl.create 8;
      whole;
      chunk = max_int;
      start;
    }
  in
  (* Otherwise chunks sized from the first frame's tile count, cut now. *)
  (if not whole then
     match open_next c with
     | Some (key, f) ->
         c.current <- Some (key, f, ref 0);
         c.chunk <-
           Option.value ~default:max_int
             (chunk ~ranks ~frames:(List.length frames) ~tiles:(Array.length f.todo))
     | None -> ());
  c

let rec next c ~domains =
  match c.current with
  | Some (key, f, next) when !next < Array.length f.todo ->
      let n =
        min
          (Array.length f.todo - !next)
          (if c.whole then max_int else unit_tiles ~chunk:c.chunk ~domains)
      in
      let u = { key; tiles = Array.sub f.todo !next n } in
      next := !next + n;
      Some u
  | _ -> (
      match open_next c with
      | None -> None
      | Some (key, f) ->
          c.current <- Some (key, f, ref 0);
          next c ~domains)

let frame c key = Hashtbl.find c.opened key

let deposit c key tiles st =
  let f = Hashtbl.find c.opened key in
  f.left <- f.left - Array.length tiles;
  f.st <- Counters.add f.st st;
  if f.left = 0 then (
    Hashtbl.remove c.opened key;
    Some f)
  else None
