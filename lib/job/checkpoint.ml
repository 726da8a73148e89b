(* See checkpoint.mli. *)

(* Version 3: the layout below, read field by field; 2 was a marshalled record. *)
let magic = "lancer-checkpoint-3\n"
let seal_length = 32 (* BLAKE2b-256 *)

(* The body's layout: the image's width, height and tile count; per tile a flag byte and
   seven counter words; the pixel count; the pixels. Every number is 8 bytes,
   little-endian: integers two's complement, pixels IEEE 754 binary64. *)
let word = 8
let header_length = 3 * word
let counter_words = 7 (* primary, shadow, reflected, refracted, bad, first bad (i, j) *)
let tile_length = 1 + (counter_words * word)

let body_length ~width ~height ~tiles =
  header_length + (tiles * tile_length) + word + (3 * width * height * word)

type t = {
  path : string;
  key : string;
  width : int;
  height : int;
  finished : bool array; (* by tile *)
  counters : Counters.t option array; (* by tile; a unit's counters on its first tile *)
  fb : Framebuffer.t; (* only finished tiles' pixels count *)
  todo : int array;
  lock : Mutex.t;
  writing : bool Atomic.t;
  resumed : int; (* tiles loaded from the file *)
  resumed_rays : int; (* the rays of those tiles *)
  mutable count : int;
  mutable last : float; (* when it was last written *)
  mutable interval : float;
}

let path_for out = out ^ ".checkpoint"

let key (src : Scenes.t) overrides ~time ~frame ~files =
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

(* ---- The seal ---- *)

(* What the seal digests is the key's length (a word), the key, then the body. The
   buffer holds the first two and room for a body of [n] bytes after them, at [skip]. *)
let sealing_buffer key n =
  let k = String.length key in
  let b = Bytes.create (word + k + n) in
  Bytes.set_int64_le b 0 (Int64.of_int k);
  Bytes.blit_string key 0 b word k;
  (b, word + k)

let seal_of_buffer b = Digest.BLAKE256.bytes b

let seal ~key body =
  let n = String.length body in
  let b, skip = sealing_buffer key n in
  Bytes.blit_string body 0 b skip n;
  seal_of_buffer b

(* ---- Writing ---- *)

let put_int b off n = Bytes.set_int64_le b off (Int64.of_int n)

(* The body of the given state into [b] from [off]. *)
let encode b off ~width ~height ~finished ~counters ~(pixels : Float.Array.t) =
  put_int b off width;
  put_int b (off + word) height;
  put_int b (off + (2 * word)) (Array.length finished);
  Array.iteri
    (fun k done_ ->
      let o = off + header_length + (k * tile_length) in
      let at w n = put_int b (o + 1 + (w * word)) n in
      Bytes.set_uint8 b o (if done_ then 1 else 0);
      let (s : Counters.t) =
        match counters.(k) with Some s when done_ -> s | _ -> Counters.zero
      in
      at 0 s.primary;
      at 1 s.shadow;
      at 2 s.reflected;
      at 3 s.refracted;
      at 4 s.bad_samples;
      let i, j = Option.value s.first_bad ~default:(-1, -1) in
      at 5 i;
      at 6 j)
    finished;
  let o = off + header_length + (Array.length finished * tile_length) in
  let n = 3 * width * height in
  put_int b o n;
  let o = o + word in
  for p = 0 to n - 1 do
    Bytes.set_int64_le b (o + (p * word)) (Int64.bits_of_float (Float.Array.get pixels p))
  done

(* ---- Reading ---- *)

exception Refused

let refuse () = raise Refused
let require c = if not c then refuse ()

(* A word that must be an integer in [lo, max_int]. *)
let get_int b off ~lo =
  let v = Bytes.get_int64_le b off in
  require
    (Int64.compare v (Int64.of_int lo) >= 0 && Int64.compare v (Int64.of_int max_int) <= 0);
  Int64.to_int v

(* The state a body describes, or [Refused]: the image's size and tiles must be these,
   each flag 0 or 1, an unfinished tile's counters zero and its first bad pixel (−1, −1), a
   finished tile's counters non-negative with at most as many bad samples as primary rays,
   a first bad pixel exactly when there are bad samples and then in a finished tile, each
   counter's total over the tiles an integer, and every pixel finite. *)
let decode b off ~width ~height ~(rects : (int * int * int * int) array) =
  let tiles = Array.length rects in
  require (get_int b off ~lo:0 = width);
  require (get_int b (off + word) ~lo:0 = height);
  require (get_int b (off + (2 * word)) ~lo:0 = tiles);
  let totals = Array.make 5 0 in
  let bad_at = ref [] in
  let tile k =
    let o = off + header_length + (k * tile_length) in
    let at w ~lo = get_int b (o + 1 + (w * word)) ~lo in
    match Bytes.get_uint8 b o with
    | 0 ->
        for w = 0 to 4 do
          require (at w ~lo:0 = 0)
        done;
        require (at 5 ~lo:(-1) = -1 && at 6 ~lo:(-1) = -1);
        (false, None)
    | 1 ->
        let c = Array.init 5 (fun w -> at w ~lo:0) in
        Array.iteri
          (fun w v ->
            require (totals.(w) <= max_int - v);
            totals.(w) <- totals.(w) + v)
          c;
        let bad = c.(4) in
        require (bad <= c.(0));
        let first_bad =
          match (at 5 ~lo:(-1), at 6 ~lo:(-1)) with
          | -1, -1 ->
              require (bad = 0);
              None
          | i, j ->
              require (bad > 0 && i >= 0 && i < width && j >= 0 && j < height);
              bad_at := (i, j) :: !bad_at;
              Some (i, j)
        in
        let s : Counters.t =
          {
            primary = c.(0);
            shadow = c.(1);
            reflected = c.(2);
            refracted = c.(3);
            bad_samples = bad;
            first_bad;
            noise_sq = 0;
            noise_n = 0;
          }
        in
        (true, Some s)
    | _ -> refuse ()
  in
  let read = Array.init tiles tile in
  let finished = Array.map fst read and counters = Array.map snd read in
  List.iter
    (fun (i, j) ->
      require
        (Seq.exists
           (fun (k, (x0, y0, x1, y1)) ->
             finished.(k) && x0 <= i && i < x1 && y0 <= j && j < y1)
           (Array.to_seqi rects)))
    !bad_at;
  let o = off + header_length + (tiles * tile_length) in
  let n = 3 * width * height in
  require (get_int b o ~lo:0 = n);
  let o = o + word in
  let pixels = Float.Array.create n in
  for p = 0 to n - 1 do
    let x = Int64.float_of_bits (Bytes.get_int64_le b (o + (p * word))) in
    require (Float.is_finite x);
    Float.Array.set pixels p x
  done;
  (finished, counters, pixels)

(* The whole file, sealed for [key] and of the size this image's checkpoint has, into a
   sealing buffer; [None] for anything else (no file, not a regular file, another size,
   a read error). The size is checked before anything is read. *)
let read_sealed path ~key ~length =
  let m = String.length magic in
  match Unix.openfile path [ Unix.O_RDONLY; Unix.O_NONBLOCK; Unix.O_CLOEXEC ] 0 with
  | exception Unix.Unix_error _ -> None
  | fd ->
      let ic = Unix.in_channel_of_descr fd in
      set_binary_mode_in ic true;
      Fun.protect
        ~finally:(fun () -> close_in_noerr ic)
        (fun () ->
          match Unix.fstat fd with
          | exception Unix.Unix_error _ -> None
          | st when st.st_kind <> Unix.S_REG || st.st_size <> m + seal_length + length ->
              None
          | _ -> (
              let head = Bytes.create (m + seal_length) in
              let b, skip = sealing_buffer key length in
              match
                really_input ic head 0 (m + seal_length);
                really_input ic b skip length
              with
              | exception (End_of_file | Sys_error _) -> None
              | () ->
                  if
                    Bytes.sub_string head 0 m = magic
                    && String.equal
                         (Bytes.sub_string head m seal_length)
                         (seal_of_buffer b)
                  then Some (b, skip)
                  else None))

let load path ~key ~width ~height ~rects =
  let length = body_length ~width ~height ~tiles:(Array.length rects) in
  match read_sealed path ~key ~length with
  | None -> None
  | Some (b, skip) -> (
      match decode b skip ~width ~height ~rects with
      | state -> Some state
      | exception Refused -> None)

let start ~out ~key (sc : Scene.t) =
  let path = path_for out in
  Files.check_writable path;
  let width = sc.settings.width and height = sc.settings.height in
  let rects = Render.tiles sc in
  let tiles = Array.length rects in
  let finished, counters, pixels =
    match load path ~key ~width ~height ~rects with
    | Some state -> state
    | None ->
        ( Array.make tiles false,
          Array.make tiles None,
          (Framebuffer.create width height).data )
  in
  let count = Array.fold_left (fun n b -> if b then n + 1 else n) 0 finished in
  let todo =
    Array.of_list (List.filter (fun k -> not finished.(k)) (List.init tiles Fun.id))
  in
  {
    path;
    key;
    width;
    height;
    finished;
    counters;
    fb = { width; height; data = pixels };
    todo;
    resumed = count;
    resumed_rays =
      Array.fold_left
        (fun n -> function Some st -> n + Counters.total_rays st | None -> n)
        0 counters;
    lock = Mutex.create ();
    writing = Atomic.make false;
    count;
    last = 0.;
    interval = 1.;
  }

let framebuffer t = t.fb
let resumed_rays t = t.resumed_rays
let resumed t = t.resumed
let tiles t = Array.length t.finished
let todo t = t.todo
let finished t = Mutex.protect t.lock (fun () -> t.count)

let write t =
  let finished, counters =
    Mutex.protect t.lock (fun () -> (Array.copy t.finished, Array.copy t.counters))
  in
  (* The finished tiles' pixels were written before they were marked, under the lock
     taken above; other domains write only into unfinished tiles meanwhile. *)
  let length =
    body_length ~width:t.width ~height:t.height ~tiles:(Array.length finished)
  in
  let b, skip = sealing_buffer t.key length in
  encode b skip ~width:t.width ~height:t.height ~finished ~counters ~pixels:t.fb.data;
  match
    Image.write_atomic t.path (fun oc ->
        output_string oc magic;
        output_string oc (seal_of_buffer b);
        output oc b skip length)
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
          t.counters.(k) <- Some (if i = 0 then st else Counters.zero);
          if not t.finished.(k) then t.count <- t.count + 1;
          t.finished.(k) <- true)
        tiles);
  due t

let stats t =
  Mutex.protect t.lock (fun () ->
      Array.fold_left
        (fun acc c -> Option.fold ~none:acc ~some:(Counters.add acc) c)
        Counters.zero t.counters)

let remove t = try Unix.unlink t.path with Unix.Unix_error _ -> ()

let render ?cancel ?pool ?(on_tile = fun _ _ -> ()) t sc =
  (* The one tile loop, over the tiles still to do; each is recorded as it finishes. *)
  ignore
    (Render.render_tiles ?cancel ?pool
       ~on_tile:(fun _ k st ->
         tiles_done t [| k |] st;
         on_tile (finished t) (Counters.total_rays st))
       sc t.fb t.todo)
