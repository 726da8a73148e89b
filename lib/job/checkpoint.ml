(* See checkpoint.mli. *)

(* The payload is marshalled: the number changes with its types (2: counters carry their
   cancellation token), so that a file of another layout is ignored, never misread. *)
let magic = "lancer-checkpoint-2\n"

(* What the file holds after the magic and the MD5 of the rest. *)
type payload = {
  key : string;
  width : int;
  height : int;
  finished : bool array; (* by tile *)
  pixels : Float.Array.t; (* the framebuffer; only finished tiles' pixels count *)
  counters : Stats.t option array; (* by tile; a unit's counters on its first tile *)
}

type t = {
  path : string;
  p : payload;
  fb : Image.t;
  todo : int array;
  lock : Mutex.t;
  writing : bool Atomic.t;
  resumed : int; (* tiles loaded from the file *)
  mutable count : int;
  mutable last : float; (* when it was last written *)
  mutable interval : float;
}

let path_for out = out ^ ".checkpoint"

let key (src : Source.t) overrides ~time ~frame ~files =
  Digest.to_hex
    (Digest.string
       (String.concat "|"
          ([
             "lancer-still-v1";
             src.text_digest ();
             String.concat "," (List.map (fun f -> f ^ "=" ^ src.input_digest f) files);
             Printf.sprintf "%h" time;
             string_of_int frame;
           ]
          @ Overrides.digest_fields overrides)))

let load path ~key ~width ~height ~tiles =
  match In_channel.with_open_bin path In_channel.input_all with
  | exception Sys_error _ -> None
  | s -> (
      let m = String.length magic in
      if String.length s < m + 16 || String.sub s 0 m <> magic then None
      else
        let body = String.sub s (m + 16) (String.length s - m - 16) in
        if not (String.equal (Digest.string body) (String.sub s m 16)) then None
        else
          match (Marshal.from_string body 0 : payload) with
          | p
            when String.equal p.key key && p.width = width && p.height = height
                 && Array.length p.finished = tiles
                 && Array.length p.counters = tiles
                 && Float.Array.length p.pixels = 3 * width * height ->
              Some p
          | _ -> None
          | exception _ -> None)

let start ~out ~key (sc : Scene.t) =
  let path = path_for out in
  Files.check_writable path;
  let width = sc.settings.width and height = sc.settings.height in
  let tiles = Array.length (Render.tiles sc) in
  let p =
    match load path ~key ~width ~height ~tiles with
    | Some p -> p
    | None ->
        {
          key;
          width;
          height;
          finished = Array.make tiles false;
          pixels = (Image.create width height).data;
          counters = Array.make tiles None;
        }
  in
  let count = Array.fold_left (fun n b -> if b then n + 1 else n) 0 p.finished in
  let todo =
    Array.of_list (List.filter (fun k -> not p.finished.(k)) (List.init tiles Fun.id))
  in
  {
    path;
    p;
    fb = { width; height; data = p.pixels };
    todo;
    resumed = count;
    lock = Mutex.create ();
    writing = Atomic.make false;
    count;
    last = 0.;
    interval = 1.;
  }

let framebuffer t = t.fb
let resumed t = t.resumed
let tiles t = Array.length t.p.finished
let todo t = t.todo
let finished t = Mutex.protect t.lock (fun () -> t.count)

let write t =
  let finished, counters =
    Mutex.protect t.lock (fun () -> (Array.copy t.p.finished, Array.copy t.p.counters))
  in
  (* The finished tiles' pixels were written before they were marked, under the lock
     taken above; other domains write only into unfinished tiles meanwhile. *)
  let body = Marshal.to_string { t.p with finished; counters } [ Marshal.No_sharing ] in
  match
    Image.write_atomic t.path (fun oc ->
        output_string oc magic;
        output_string oc (Digest.string body);
        output_string oc body)
  with
  | Ok () -> ()
  | Error m -> Job_error.user "the checkpoint: %s" m

let save t = write t

let due t =
  let now = Unix.gettimeofday () in
  if now -. t.last >= t.interval && Atomic.compare_and_set t.writing false true then
    Fun.protect
      ~finally:(fun () -> Atomic.set t.writing false)
      (fun () ->
        write t;
        let after = Unix.gettimeofday () in
        t.last <- after;
        t.interval <- Float.max 1. (10. *. (after -. now)))

let tiles_done t tiles st =
  Mutex.protect t.lock (fun () ->
      Array.iteri
        (fun i k ->
          (* Counters first: an interrupt between the two leaves the tile to do again. *)
          t.p.counters.(k) <- Some (if i = 0 then st else Stats.create ());
          if not t.p.finished.(k) then t.count <- t.count + 1;
          t.p.finished.(k) <- true)
        tiles);
  due t

let stats t =
  let total = Stats.create () in
  Mutex.protect t.lock (fun () ->
      Array.iter (Option.iter (Stats.add_into total)) t.p.counters);
  total

let remove t = try Unix.unlink t.path with Unix.Unix_error _ -> ()

let render ?cancel ?pool ?(on_tile = fun _ _ -> ()) t sc =
  (* The one tile loop, over the tiles still to do; each is recorded as it finishes. *)
  ignore
    (Render.render_tiles ?cancel ?pool
       ~on_tile:(fun _ k st ->
         tiles_done t [| k |] st;
         on_tile (finished t) (Stats.total_rays st))
       sc t.fb t.todo)
