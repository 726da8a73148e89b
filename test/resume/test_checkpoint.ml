(* The still checkpoint read as input: a real checkpoint changed in every way (bits
   flipped, cut short, lengthened, ranges swapped, fields rewritten) and sealed again,
   once from the file alone and once with the job's key. Nothing raises or crashes; a
   file sealed without the key is never used; a refused file gives the uninterrupted
   image; an accepted one holds only what a render could have written. *)
open Lancer

let tmpdir () =
  let d = Filename.temp_dir "lancer-checkpoint-test" "" in
  at_exit (fun () -> ignore (Sys.command ("rm -rf " ^ Filename.quote d)));
  d

let write_file p s = Out_channel.with_open_bin p (fun oc -> output_string oc s)
let read_file p = In_channel.with_open_bin p In_channel.input_all

(* ---- A small still: 48×40, four tiles (32×32, 16×32, 32×8, 16×8) ---- *)

let scene_text =
  {|settings { width: 48, height: 40 }
camera { position: (0, 1, -5), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0, material: material { reflection: 0.3 } }
sphere { center: (0, 1, 0), radius: 1, material: material { color: (0.9, 0.2, 0.2) } }
|}

let load text =
  match Program.load_string ~filename:"small.rts" text with
  | Error _ -> failwith "the test scene does not load"
  | Ok p -> (
      match Program.scene_at p ~time:0. ~frame:0 with
      | Ok sc -> sc
      | Error _ -> failwith "the test scene does not evaluate")

let sc = load scene_text
let width = sc.settings.width
let height = sc.settings.height
let rects = Render.tiles sc
let tiles = Array.length rects

(* A key as Checkpoint.key makes them: an MD5 in hexadecimal. *)
let key = Digest.to_hex (Digest.string "the small still, its inputs and options")

let bits (a : Float.Array.t) =
  Array.init (Float.Array.length a) (fun i -> Int64.bits_of_float (Float.Array.get a i))

let reference = bits (fst (Render.render sc)).data

(* The checkpoint of [out] after tiles 0 and 2 were rendered, tile 2 counting one bad
   sample at (5, 35) (a pixel of its own), and the checkpoint saved. *)
let checkpoint_of_half out =
  let ck = Checkpoint.start ~out ~key sc in
  ignore
    (Render.render_tiles
       ~on_tile:(fun _ k (st : Counters.t) ->
         let st =
           if k = 2 then { st with bad_samples = 1; first_bad = Some (5, 35) } else st
         in
         Checkpoint.tiles_done ck [| k |] st)
       sc (Checkpoint.framebuffer ck) [| 0; 2 |]);
  Checkpoint.save ck;
  read_file (Checkpoint.path_for out)

(* ---- The layout, as checkpoint.mli gives it ---- *)

let magic_length = String.length "lancer-checkpoint-3\n"
let seal_length = 32
let body_at = magic_length + seal_length
let header_at = body_at
let tile_at k = body_at + 24 + (k * 57)
let counter_at k w = tile_at k + 1 + (8 * w)
let count_at = tile_at tiles
let pixel_at p = count_at + 8 + (8 * p)

let set_word s off v =
  let b = Bytes.of_string s in
  Bytes.set_int64_le b off v;
  Bytes.to_string b

let set_int s off n = set_word s off (Int64.of_int n)

let set_byte s off n =
  let b = Bytes.of_string s in
  Bytes.set_uint8 b off n;
  Bytes.to_string b

let set_float s off x = set_word s off (Int64.bits_of_float x)
let get_int s off = Int64.to_int (String.get_int64_le s off)

(* The file with its seal made again over what follows it: with the job's key, or as one
   who reads the file alone can: an unkeyed digest of the same length, or the seal for a
   key of their own. *)
let reseal how s =
  if String.length s < body_at then s
  else
    let body = String.sub s body_at (String.length s - body_at) in
    let seal =
      match how with
      | `Key -> Checkpoint.seal ~key body
      | `File_alone -> Digest.BLAKE256.string body
      | `Another_key ->
          Checkpoint.seal ~key:(Digest.to_hex (Digest.string "another job")) body
    in
    String.sub s 0 magic_length ^ seal ^ body

(* ---- Loading one file ---- *)

let dir = tmpdir ()
let out = Filename.concat dir "still.png"
let path = Checkpoint.path_for out

(* [Checkpoint.start] on [text] in the checkpoint's place; a failure names what raised. *)
let start_on text =
  write_file path text;
  match Checkpoint.start ~out ~key sc with
  | ck -> ck
  | exception e ->
      Alcotest.failf "loading a changed checkpoint raised %s" (Printexc.to_string e)

(* Render what is still to do, as a resumed render does; the framebuffer's bits. *)
let finish ck =
  ignore (Render.render_tiles sc (Checkpoint.framebuffer ck) (Checkpoint.todo ck));
  bits (Checkpoint.framebuffer ck).data

(* What a refused file must give: nothing resumed, every tile to do, and after the
   render the uninterrupted image. *)
let check_refused what ck =
  Alcotest.(check int) (what ^ ": nothing resumed") 0 (Checkpoint.resumed ck);
  Alcotest.(check (array int))
    (what ^ ": every tile to do") (Array.init tiles Fun.id) (Checkpoint.todo ck);
  Alcotest.(check bool) (what ^ ": the uninterrupted image") true (finish ck = reference)

(* What an accepted file must hold: the tiles it names finished and the others to do,
   counters a render could have counted, finite pixels, the same bytes when saved
   again, and after the render the uninterrupted pixels wherever a tile was to do. *)
let check_accepted what text ck =
  let todo = Checkpoint.todo ck in
  Alcotest.(check int)
    (what ^ ": resumed and to do make the tiles")
    tiles
    (Checkpoint.resumed ck + Array.length todo);
  let (st : Counters.t) = Checkpoint.stats ck in
  Alcotest.(check bool)
    (what ^ ": counters a render could count")
    true
    (st.primary >= 0 && st.shadow >= 0 && st.reflected >= 0 && st.refracted >= 0
   && st.bad_samples >= 0 && st.bad_samples <= st.primary
    && st.bad_samples > 0 = Option.is_some st.first_bad);
  Alcotest.(check bool)
    (what ^ ": pixels finite") true
    (Float.Array.for_all Float.is_finite (Checkpoint.framebuffer ck).data);
  Checkpoint.save ck;
  Alcotest.(check bool)
    (what ^ ": saved again, the same bytes")
    true
    (read_file path = text);
  let fb = finish ck in
  Array.iter
    (fun k ->
      let x0, y0, x1, y1 = rects.(k) in
      for j = y0 to y1 - 1 do
        for i = x0 to x1 - 1 do
          for c = 0 to 2 do
            let p = (3 * ((j * width) + i)) + c in
            if fb.(p) <> reference.(p) then
              Alcotest.failf "%s: pixel (%d, %d) of tile %d to do is not the render's"
                what i j k
          done
        done
      done)
    todo

let base = checkpoint_of_half out

(* ---- The attack the former seal allowed ---- *)

(* A finished pixel's value changed in place and the file sealed again as one who reads
   it alone can: after the first line, an unkeyed digest of the rest, for each digest
   the standard library offers. Written against the file as bytes (the first line, the
   seal, the body), so that it holds for any layout of that shape. *)
let resealed_from_the_file_alone () =
  (* A pixel of finished tile 0 whose value occurs once in the file. *)
  let le x =
    let b = Bytes.create 8 in
    Bytes.set_int64_le b 0 (Int64.bits_of_float x);
    Bytes.to_string b
  in
  let occurrences sub =
    let n = String.length base and m = String.length sub in
    let rec matches i k = k = m || (base.[i + k] = sub.[k] && matches i (k + 1)) in
    let rec go i acc =
      if i + m > n then List.rev acc
      else go (i + 1) (if matches i 0 then i :: acc else acc)
    in
    go 0 []
  in
  let at, value =
    let x0, y0, x1, y1 = rects.(0) in
    let rec find i j c =
      if j >= y1 then Alcotest.fail "no pixel of tile 0 occurs once in the file"
      else if i >= x1 then find x0 (j + 1) 0
      else if c > 2 then find (i + 1) j 0
      else
        let x = Int64.float_of_bits reference.((3 * ((j * width) + i)) + c) in
        match occurrences (le x) with
        | [ at ] when x > 0. -> (at, x)
        | _ -> find i j (c + 1)
    in
    find x0 y0 0
  in
  let changed =
    String.sub base 0 at
    ^ le (value +. 0.25)
    ^ String.sub base (at + 8) (String.length base - at - 8)
  in
  let first_line = String.index base '\n' + 1 in
  List.iter
    (fun (name, length, digest) ->
      let body_at = first_line + length in
      let body = String.sub changed body_at (String.length changed - body_at) in
      let forged = String.sub changed 0 first_line ^ digest body ^ body in
      write_file path forged;
      let ck = Checkpoint.start ~out ~key sc in
      Alcotest.(check int) (name ^ ": not resumed") 0 (Checkpoint.resumed ck);
      Alcotest.(check bool)
        (name ^ ": the uninterrupted image")
        true
        (finish ck = reference))
    [
      ("MD5", 16, Digest.string);
      ("BLAKE2b-128", 16, Digest.BLAKE128.string);
      ("BLAKE2b-256", 32, Digest.BLAKE256.string);
      ("BLAKE2b-512", 64, Digest.BLAKE512.string);
    ]

(* ---- Targeted changes, sealed with the key ---- *)

let the_writers_file_is_resumed () =
  let ck = start_on base in
  Alcotest.(check int) "two tiles resumed" 2 (Checkpoint.resumed ck);
  Alcotest.(check (array int)) "two to do" [| 1; 3 |] (Checkpoint.todo ck);
  let (st : Counters.t) = Checkpoint.stats ck in
  Alcotest.(check (pair int (option (pair int int))))
    "the bad sample kept"
    (1, Some (5, 35))
    (st.bad_samples, st.first_bad);
  check_accepted "the writer's file" base ck;
  Alcotest.(check bool) "the uninterrupted image" true (finish (start_on base) = reference)

(* A pixel of finished tile 0, (3, 4), green. *)
let finished_pixel = pixel_at ((3 * ((4 * width) + 3)) + 1)

let refused_changes () =
  let tile2 w = counter_at 2 w in
  let cases =
    [
      ("a NaN pixel", fun s -> set_float s finished_pixel Float.nan);
      ("an infinite pixel", fun s -> set_float s finished_pixel Float.infinity);
      ("a pixel of minus infinity", fun s -> set_float s finished_pixel Float.neg_infinity);
      ("a NaN in a tile still to do", fun s -> set_float s (pixel_at (3 * 40)) Float.nan);
      ("another width", fun s -> set_int s header_at 47);
      ("another height", fun s -> set_int s (header_at + 8) 41);
      ("another tile count", fun s -> set_int s (header_at + 16) 5);
      ("another pixel count", fun s -> set_int s count_at ((3 * width * height) - 1));
      ("a tile flag of 2", fun s -> set_byte s (tile_at 1) 2);
      ("a tile flag of 255", fun s -> set_byte s (tile_at 3) 255);
      ("a negative ray count", fun s -> set_int s (counter_at 0 1) (-1));
      ("a ray count past the integers", fun s -> set_word s (counter_at 0 0) Int64.max_int);
      ( "counters whose sum overflows",
        fun s -> set_int (set_int s (counter_at 0 1) max_int) (counter_at 2 1) max_int );
      ( "more bad samples than primary rays",
        fun s -> set_int s (tile2 4) (get_int s (tile2 0) + 1) );
      ( "bad samples without a first bad pixel",
        fun s -> set_int (set_int s (tile2 5) (-1)) (tile2 6) (-1) );
      ("a first bad pixel without bad samples", fun s -> set_int s (tile2 4) 0);
      ("a first bad pixel outside the image", fun s -> set_int s (tile2 6) height);
      ( "a first bad pixel in a tile still to do",
        fun s -> set_int (set_int s (tile2 5) 40) (tile2 6) 10 );
      ("counters on a tile still to do", fun s -> set_int s (counter_at 1 0) 7);
      ("a first bad column on a tile still to do", fun s -> set_int s (counter_at 3 5) 0);
      ("a byte more", fun s -> s ^ "\000");
      ("a byte less", fun s -> String.sub s 0 (String.length s - 1));
      ("nothing", fun _ -> "");
      ( "the first line of another layout",
        fun s ->
          "lancer-checkpoint-4\n"
          ^ String.sub s magic_length (String.length s - magic_length) );
    ]
  in
  List.iter
    (fun (what, change) ->
      let changed = reseal `Key (change base) in
      Alcotest.(check bool) (what ^ ": the file changed") false (changed = base);
      check_refused what (start_on changed))
    cases

(* What the seal does not hold back: a file sealed with the key whose changes pass every
   check. Its finished tiles' pixels are used as they are. *)
let accepted_changes () =
  List.iter
    (fun x ->
      let changed = reseal `Key (set_float base finished_pixel x) in
      let ck = start_on changed in
      Alcotest.(check int) "resumed" 2 (Checkpoint.resumed ck);
      Alcotest.(check (float 0.))
        "the pixel as the file has it" x
        (Float.Array.get (Checkpoint.framebuffer ck).data ((3 * ((4 * width) + 3)) + 1));
      check_accepted (Printf.sprintf "a pixel of %g" x) changed ck)
    [ 0.125; 1e300; -0.25 ];
  (* Tile 1 marked finished with zero counters: a unit's tile other than its first. *)
  let changed = reseal `Key (set_byte base (tile_at 1) 1) in
  let ck = start_on changed in
  Alcotest.(check (array int)) "tile 1 is not to do" [| 3 |] (Checkpoint.todo ck);
  check_accepted "tile 1 marked finished" changed ck

(* A glass whose reflection and transparency sum to 1 up to rounding: the weight of its
   own shading, 1 − r − τ, is a hair below zero, and so are pixels where nothing is seen
   through it or in it. Its checkpoint is resumed like any other. *)
let pixels_below_zero_are_resumed () =
  let sc =
    load
      {|settings { width: 48, height: 40 }
camera { position: (0, 0, -5), look_at: (0, 0, 0) }
light { position: (-3, 5, -4) }
sphere { center: (0, 0, 0), radius: 2, material: material { reflection: 0.5, transparency: 0.5000000000000001, ior: 1 } }
|}
  in
  let uninterrupted = bits (fst (Render.render sc)).data in
  let out = Filename.concat dir "glass.png" in
  let ck = Checkpoint.start ~out ~key sc in
  ignore
    (Render.render_tiles
       ~on_tile:(fun _ k st -> Checkpoint.tiles_done ck [| k |] st)
       sc (Checkpoint.framebuffer ck) [| 0; 1; 2 |]);
  Checkpoint.save ck;
  let back = Checkpoint.start ~out ~key sc in
  Alcotest.(check int) "three tiles resumed" 3 (Checkpoint.resumed back);
  let x0, y0, x1, y1 = (Render.tiles sc).(0) in
  let below = ref 0 in
  for j = y0 to y1 - 1 do
    for i = x0 to x1 - 1 do
      for c = 0 to 2 do
        if
          Float.Array.get (Checkpoint.framebuffer back).data ((3 * ((j * width) + i)) + c)
          < 0.
        then incr below
      done
    done
  done;
  Alcotest.(check bool) "finished tile 0 holds values below zero" true (!below > 0);
  ignore (Render.render_tiles sc (Checkpoint.framebuffer back) (Checkpoint.todo back));
  Alcotest.(check bool)
    "the uninterrupted image" true
    (bits (Checkpoint.framebuffer back).data = uninterrupted)

(* A pipe in the checkpoint's place that nobody writes into: not waited on (an alarm
   after two seconds would say so), and nothing resumed. *)
let a_pipe_is_not_waited_on () =
  let out = Filename.concat dir "pipe.png" in
  Unix.mkfifo (Checkpoint.path_for out) 0o600;
  let waited = Atomic.make false in
  let previous =
    Sys.signal Sys.sigalrm (Sys.Signal_handle (fun _ -> Atomic.set waited true))
  in
  ignore (Unix.alarm 2);
  let ck = Checkpoint.start ~out ~key sc in
  ignore (Unix.alarm 0);
  Sys.set_signal Sys.sigalrm previous;
  Alcotest.(check bool) "not waited on" false (Atomic.get waited);
  Alcotest.(check int) "nothing resumed" 0 (Checkpoint.resumed ck)

(* ---- Fuzzing ---- *)

(* Interesting values for a word: edges of the integers and of the floats. *)
let words rng s off =
  let cur = String.get_int64_le s off in
  let floats =
    [
      Float.nan;
      Float.infinity;
      Float.neg_infinity;
      -1.;
      -0.;
      0.;
      1.;
      1e308;
      5e-324;
      -5e-324;
      0.5;
    ]
  in
  let ints =
    [
      0L;
      1L;
      -1L;
      2L;
      Int64.max_int;
      Int64.min_int;
      Int64.of_int max_int;
      Int64.shift_left 1L 62;
      Int64.add cur 1L;
      Int64.sub cur 1L;
      Int64.neg cur;
      47L;
      48L;
      40L;
      4L;
      5760L;
    ]
  in
  match Random.State.int rng 3 with
  | 0 -> Int64.bits_of_float (List.nth floats (Random.State.int rng (List.length floats)))
  | 1 -> List.nth ints (Random.State.int rng (List.length ints))
  | _ -> Random.State.int64 rng Int64.max_int

(* One change of the file, drawn from [rng]. *)
let mutate rng s =
  let n = String.length s in
  let b = Bytes.of_string s in
  let pos () = Random.State.int rng n in
  match Random.State.int rng 6 with
  | 0 ->
      (* Bits flipped: one to four, anywhere. *)
      for _ = 1 to 1 + Random.State.int rng 4 do
        let p = pos () in
        Bytes.set_uint8 b p (Bytes.get_uint8 b p lxor (1 lsl Random.State.int rng 8))
      done;
      ("bits flipped", Bytes.to_string b)
  | 1 -> ("cut short", String.sub s 0 (pos ()))
  | 2 ->
      let extra =
        String.init
          (1 + Random.State.int rng 64)
          (fun _ -> Char.chr (Random.State.int rng 256))
      in
      if Random.State.bool rng then ("lengthened", s ^ extra)
      else
        let p = pos () in
        ("bytes inserted", String.sub s 0 p ^ extra ^ String.sub s p (n - p))
  | 3 ->
      (* Two ranges of one length swapped. *)
      let len = 1 + Random.State.int rng 64 in
      let a = Random.State.int rng (n - len) and c = Random.State.int rng (n - len) in
      let ra = Bytes.sub b a len and rc = Bytes.sub b c len in
      Bytes.blit rc 0 b a len;
      Bytes.blit ra 0 b c len;
      ("ranges swapped", Bytes.to_string b)
  | 4 ->
      (* A field of the body rewritten: header, flag, counter, pixel count or pixel. *)
      let off =
        match Random.State.int rng 5 with
        | 0 -> header_at + (8 * Random.State.int rng 3)
        | 1 -> counter_at (Random.State.int rng tiles) (Random.State.int rng 7)
        | 2 -> count_at
        | 3 -> pixel_at (Random.State.int rng (3 * width * height))
        | _ -> -1
      in
      if off >= 0 then (
        Bytes.set_int64_le b off (words rng s off);
        ("a field rewritten", Bytes.to_string b))
      else (
        Bytes.set_uint8 b
          (tile_at (Random.State.int rng tiles))
          (if Random.State.bool rng then Random.State.int rng 256
           else Random.State.int rng 2);
        ("a flag rewritten", Bytes.to_string b))
  | _ ->
      let p = pos () in
      let len = min (n - p) (1 + Random.State.int rng 64) in
      ("bytes removed", String.sub s 0 p ^ String.sub s (p + len) (n - p - len))

let cases = 1500

let fuzz () =
  let rng = Random.State.make [| 33; 2024 |] in
  let accepted = ref 0 in
  for c = 1 to cases do
    let how, changed = mutate rng base in
    let what = Printf.sprintf "case %d (%s)" c how in
    (* Sealed from the file alone: never used. *)
    let how = if c mod 2 = 0 then `File_alone else `Another_key in
    check_refused (what ^ ", sealed without the key") (start_on (reseal how changed));
    (* Sealed with the key: refused, or only what a render could have written. *)
    let sealed = reseal `Key changed in
    let ck = start_on sealed in
    if Checkpoint.resumed ck = 0 && Checkpoint.todo ck = Array.init tiles Fun.id then
      check_refused (what ^ ", sealed with the key") ck
    else (
      incr accepted;
      check_accepted (what ^ ", sealed with the key") sealed ck)
  done;
  (* Some changes (a pixel's low bits, a flag 0 → 1) pass every check: the checks above
     ran on accepted files too. *)
  Alcotest.(check bool) "some files sealed with the key were accepted" true (!accepted > 0)

let () =
  Alcotest.run "checkpoint"
    [
      ( "checks",
        [
          Alcotest.test_case
            "a checkpoint whose pixel was changed and sealed again from the file alone \
             is not resumed"
            `Quick resealed_from_the_file_alone;
          Alcotest.test_case
            "the writer's own checkpoint is resumed to the uninterrupted image" `Quick
            the_writers_file_is_resumed;
          Alcotest.test_case
            "a checkpoint sealed with the key but holding what no render writes is \
             refused"
            `Quick refused_changes;
          Alcotest.test_case
            "a checkpoint sealed with the key whose changes pass every check is used as \
             it is"
            `Quick accepted_changes;
          Alcotest.test_case
            "a still whose pixels come out a hair below zero is resumed to the \
             uninterrupted image"
            `Quick pixels_below_zero_are_resumed;
          Alcotest.test_case "a pipe in the checkpoint's place is not waited on" `Quick
            a_pipe_is_not_waited_on;
        ] );
      ( "fuzz",
        [
          Alcotest.test_case
            "1500 changed checkpoints, each sealed without and with the key: none \
             raises, none sealed without the key is used, each refused one gives the \
             uninterrupted image"
            `Quick fuzz;
        ] );
    ]
