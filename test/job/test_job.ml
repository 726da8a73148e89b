(* The job layer as lancer and lancer-mpi call it, without a command line: which frames a
   shard renders, the frames record and the still checkpoint on disk, how units are cut
   and rendered, the overrides, the guarded writes. *)
open Lancer
open Lancer_job

let user_error name f =
  match f () with
  | _ -> Alcotest.failf "%s: expected a user error" name
  | exception Job_error.User _ -> ()

(* ---- Temporary directories ---- *)

let tmpdir () =
  let d = Filename.temp_dir "lancer-job-test" "" in
  at_exit (fun () -> ignore (Sys.command ("rm -rf " ^ Filename.quote d)));
  d

let write path text = Out_channel.with_open_bin path (fun oc -> output_string oc text)

(* ---- A small scene, 40×36: four tiles of 32×32 at most ---- *)

let scene_text =
  {|settings { width: 40, height: 36, samples: 2 }
camera { position: (0, 1, -5), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0 }
sphere { center: (0, 1, 0), radius: 1, material: material { color: (0.9, 0.2, 0.2) } }
|}

let scene () =
  match Lancer.Program.load_string ~filename:"small.rts" scene_text with
  | Error _ -> Alcotest.fail "the test scene does not load"
  | Ok p -> (
      match Lancer.Program.scene_at p ~time:0. ~frame:0 with
      | Ok sc -> sc
      | Error _ -> Alcotest.fail "the test scene does not evaluate")

let floats_equal a b =
  Float.Array.length a = Float.Array.length b
  &&
  let ok = ref true in
  Float.Array.iteri
    (fun i x -> if not (Float.equal x (Float.Array.get b i)) then ok := false)
    a;
  !ok

(* ---- The frames of an animation ---- *)

(* An animated scene's program, and its frame k at 10 frames a second. *)
let load_anim text =
  match Lancer.Program.load_string ~filename:"anim.rts" text with
  | Error _ -> Alcotest.fail "the animated scene does not load"
  | Ok p -> p

let frames_of ?p text =
  let p = match p with Some p -> p | None -> load_anim text in
  fun k ->
    match Lancer.Program.scene_at p ~time:(Float.of_int k /. 10.) ~frame:k with
    | Error _ -> Alcotest.fail "the animated scene does not evaluate"
    | Ok sc -> sc

(* The scene of frame [k] of [p] with every statement evaluated and compiled again: a
   still of that instant, indexed whole. *)
let compiled_again p k =
  match
    Lancer_dsl.Dsl.describe ~again:true (Lancer.Program.language p)
      ~time:(Float.of_int k /. 10.)
      ~frame:k
  with
  | Error _ -> Alcotest.fail "the frame does not evaluate again"
  | Ok d -> (
      match Lancer_render.Compile.compile (Lancer.Program.assets p) d with
      | Ok sc -> sc
      | Error _ -> Alcotest.fail "the frame does not compile again")

(* The objects that do not move are compiled and indexed once for every frame, the first
   one included: every frame is layered over the program's static part, known by the
   positions of its statements (the plane and the loop: the fourth and fifth). *)
let frames_share_the_fixed_part () =
  let text =
    {|settings { width: 16, height: 12 }
animation { fps: 10, frames: 5 }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0 }
for i in 0 to 40 { sphere { center: (i / 10, 0.2, 1), radius: 0.1 } }
sphere { center: (-1 + time, 1, 0), radius: 0.5 }
|}
  in
  let frame = frames_of text in
  List.iter
    (fun k ->
      Alcotest.(check (option (array int)))
        (Printf.sprintf "frame %d is layered over statements 3 and 4" k)
        (Some [| 3; 4 |])
        (Lancer_render.Accel.fixed_key (frame k).accel))
    [ 0; 1; 3; 4 ];
  (* A still has no such part. *)
  Alcotest.(check bool)
    "a still is indexed whole" true
    (Option.is_none (Lancer_render.Accel.fixed_key (scene ()).accel))

(* A frame evaluates, compiles and places only what moves: the objects of the statements
   that do not are handed over as their positions in the static part, and taken whole,
   so that what a frame allocates does not grow with them (a word a fixed object for the
   frame's array of every primitive, where a copy of their list alone took three). *)
let rec frames_cost_what_moves () =
  let n = 20_000 in
  let text =
    Printf.sprintf
      {|settings { width: 8, height: 6 }
animation { fps: 10, frames: 5 }
light { position: (-3, 5, -4) }
for i in 0 to %d { sphere { center: (i / 1000, 0.2, 1), radius: 0.01 } }
sphere { center: (-1 + time, 1, 0), radius: 0.5 }
|}
      (n - 1)
  in
  let p = load_anim text in
  let frame = frames_of ~p text in
  let s0 = frame 0 and s1 = frame 1 in
  let words () =
    let minor, promoted, major = Gc.counters () in
    minor +. major -. promoted
  in
  let before = words () in
  let s2 = frame 2 in
  let used = words () -. before in
  Alcotest.(check int) "every object is there" (n + 1) (Array.length s2.objects);
  (* The fixed primitives are the same values in every frame, the moving one is new. *)
  Alcotest.(check bool)
    "the fixed primitives are shared" true
    (s0.objects.(0) == s2.objects.(0) && s1.objects.(n - 1) == s2.objects.(n - 1));
  Alcotest.(check bool)
    "the moving one is made again" false
    (s1.objects.(n) == s2.objects.(n));
  if used > 2. *. Float.of_int n then
    Alcotest.failf "a frame allocated %.0f words for %d objects that do not move" used n;
  same_as_again p 2 s2

(* Frame [k] of [p] is the scene every statement evaluated and compiled again makes: the
   same primitives, in the same order. *)
and same_as_again p k (sc : Lancer_render.Scene.t) =
  let again = compiled_again p k in
  Alcotest.(check int)
    (Printf.sprintf "frame %d: as many primitives" k)
    (Array.length again.objects) (Array.length sc.objects);
  Array.iteri
    (fun i (o : Lancer_render.Primitive.t) ->
      if o.shape <> again.objects.(i).shape then
        Alcotest.failf "frame %d: primitive %d differs" k i)
    sc.objects

(* Glass in the still part and in the moving one: a frame walks the two parts' structures
   where a still of the same instant walks one, and a shadow ray crossing several glass
   surfaces multiplies their factors in the order of their values, so the two give the
   same framebuffer, to the bit. *)
let glass_frames_are_their_stills () =
  let text =
    {|settings { width: 40, height: 30, depth: 4 }
animation { fps: 10, frames: 5 }
camera { position: (0, 5, -8), look_at: (0, 0, 0), fov: 50 }
light { position: (-4, 9, -3) }
light { position: (3, 6, -5) }
plane { normal: (0, 1, 0), offset: 0 }
for i in 0 to 5 { for j in 0 to 5 {
  sphere { center: (i - 2.5, 0.5 + 0.2 * sin(i * j), j - 2.5), radius: 0.6,
           material: material { color: (0.4 + i / 10, 0.5 + j / 12, 0.8), transparency: 0.7, ior: 1.2 } }
} }
sphere { center: (-2 + time * 10, 1.2, -0.5), radius: 0.7,
         material: material { color: (0.9, 0.6, 0.5), transparency: 0.8, ior: 1.4 } }
|}
  in
  let p = load_anim text in
  let frame = frames_of ~p text in
  ignore (frame 0);
  List.iter
    (fun k ->
      let layered = frame k in
      Alcotest.(check bool)
        (Printf.sprintf "frame %d is layered" k)
        true
        (Option.is_some (Lancer_render.Accel.fixed_key layered.accel));
      let whole = compiled_again p k in
      Alcotest.(check bool)
        (Printf.sprintf "the still of instant %d is not" k)
        true
        (Option.is_none (Lancer_render.Accel.fixed_key whole.accel));
      let a, _ = Render.render layered and b, _ = Render.render whole in
      Alcotest.(check bool)
        (Printf.sprintf "frame %d: the still's framebuffer, bit for bit" k)
        true (floats_equal a.data b.data))
    [ 1; 2; 4 ]

(* The pieces a frame is made of in other orders: a moving object between two still
   statements, and a still statement after one whose count of objects changes with time
   (it is evaluated again then, its objects new). Each frame is the scene made the long
   way. *)
let frames_in_pieces () =
  let text =
    {|settings { width: 8, height: 6 }
animation { fps: 10, frames: 5 }
light { position: (-3, 5, -4) }
for i in 0 to 30 { sphere { center: (i / 10, 0.2, 1), radius: 0.05 } }
sphere { center: (-1 + time, 1, 0), radius: 0.5 }
for i in 0 to 20 { box { min: (i / 10, 0, 2), max: (i / 10 + 0.05, 0.05, 2.05) } }
for i in 0 to floor(time * 20) { sphere { center: (i / 10, 2, 1), radius: 0.05 } }
for i in 0 to 15 { sphere { center: (i / 10, 3, 1), radius: 0.05 } }
|}
  in
  let p = load_anim text in
  let frame = frames_of ~p text in
  List.iter (fun k -> same_as_again p k (frame k)) [ 0; 1; 3; 4; 2 ]

(* The scenes of several instants of one frame (the samples of a shutter) are the scenes
   of each instant, each layered over the one static part; a time at which the program
   fails gives its error. *)
let scenes_of_one_frame () =
  let text =
    {|animation { fps: 10, frames: 5 }
settings { width: 6, height: 4 }
light { position: (2, 4, -4) }
for k in 0 to 12 { box { min: (k / 4, 0, 0), max: (k / 4 + 0.1, 0.1, 0.1) } }
sphere { center: (time, 0.5, 0), radius: 0.25 }
for k in 0 to 9 { sphere { center: (k / 5, 1, 2), radius: 0.08 } }
sphere { center: (0, 1, 0), radius: 0.3 - time }
|}
  in
  let p = load_anim text in
  let times = [| 0.1; 0.125; 0.15; 0.175 |] in
  (match Lancer.Program.scenes p ~times ~frame:1 with
  | Error _ -> Alcotest.fail "the instants of frame 1 do not evaluate"
  | Ok scs ->
      Alcotest.(check int) "one scene an instant" (Array.length times) (Array.length scs);
      Array.iteri
        (fun i (sc : Lancer_render.Scene.t) ->
          Alcotest.(check (float 0.)) "its time" times.(i) sc.time;
          Alcotest.(check int) "its frame" 1 sc.frame;
          Alcotest.(check (option (array int)))
            "layered over the static statements"
            (Some [| 3; 5 |])
            (Lancer_render.Accel.fixed_key sc.accel);
          match Lancer.Program.scene p ~time:times.(i) ~frame:1 with
          | Error _ -> Alcotest.fail "an instant does not evaluate alone"
          | Ok alone ->
              Alcotest.(check int)
                "as many primitives as alone" (Array.length alone.objects)
                (Array.length sc.objects);
              Array.iteri
                (fun j (o : Lancer_render.Primitive.t) ->
                  if o.shape <> alone.objects.(j).shape then
                    Alcotest.failf "instant %g: primitive %d differs" times.(i) j)
                sc.objects)
        scs);
  match Lancer.Program.scenes p ~times:[| 0.1; 0.35; 0.2 |] ~frame:1 with
  | Ok _ -> Alcotest.fail "a negative radius is accepted"
  | Error (e :: _) ->
      Alcotest.(check bool)
        ("the failing instant is named: " ^ e.message)
        true
        (String.ends_with ~suffix:"(at frame 1, time 0.35 s)" e.message)
  | Error [] -> Alcotest.fail "an error without a diagnostic"

(* ---- Plan ---- *)

let frames_syntax () =
  let r = Alcotest.(result (pair int int) string) in
  Alcotest.check r "A..B" (Ok (3, 7)) (Plan.frames_of_string "3..7");
  Alcotest.check r "K" (Ok (5, 5)) (Plan.frames_of_string "5");
  List.iter
    (fun s ->
      Alcotest.(check bool)
        (s ^ " is refused") true
        (Result.is_error (Plan.frames_of_string s)))
    [ "7..3"; "a"; "3."; "3..."; "-1"; "" ];
  (match Plan.shard_of_string "2/4" with
  | Ok (Plan.Shard (2, 4)) -> ()
  | _ -> Alcotest.fail "2/4");
  (match Plan.shard_of_string "slurm" with
  | Ok Plan.Slurm -> ()
  | _ -> Alcotest.fail "slurm");
  (match Plan.shard_of_string "4/4" with
  | Error m ->
      Alcotest.(check bool)
        ("says the range: " ^ m) true
        (String.ends_with ~suffix:"0 and 3" m)
  | Ok _ -> Alcotest.fail "4/4 accepted");
  List.iter
    (fun s ->
      Alcotest.(check bool)
        (s ^ " is refused") true
        (Result.is_error (Plan.shard_of_string s)))
    [ "1/0"; "-1/3"; "x"; "1/2/3" ]

(* Shards partition the range: every frame once, each shard's ascending. *)
let shards_partition () =
  let first = 3 and last = 17 in
  Alcotest.(check (list int))
    "no shard: the whole range"
    (List.init 15 (fun i -> 3 + i))
    (Plan.shard_frames ~first ~last None);
  for n = 1 to 6 do
    let shards = List.init n (fun k -> Plan.shard_frames ~first ~last (Some (k, n))) in
    List.iteri
      (fun k fs ->
        Alcotest.(check (list int))
          (Printf.sprintf "shard %d/%d ascending" k n)
          (List.sort compare fs) fs;
        List.iter
          (fun f ->
            Alcotest.(check int)
              (Printf.sprintf "frame %d in shard %d/%d" f k n)
              k
              ((f - first) mod n))
          fs)
      shards;
    Alcotest.(check (list int))
      (Printf.sprintf "%d shards cover the range once" n)
      (List.init 15 (fun i -> 3 + i))
      (List.sort compare (List.concat shards))
  done

let slurm () =
  let env l name = List.assoc_opt name l in
  Alcotest.(check (pair int int))
    "ID 5 of MIN 3 STEP 2" (1, 4)
    (Plan.slurm_shard
       (env
          [
            ("SLURM_ARRAY_TASK_ID", "5");
            ("SLURM_ARRAY_TASK_COUNT", "4");
            ("SLURM_ARRAY_TASK_MIN", "3");
            ("SLURM_ARRAY_TASK_STEP", "2");
          ]));
  Alcotest.(check (pair int int))
    "MIN 0 and STEP 1 by default" (7, 16)
    (Plan.slurm_shard
       (env [ ("SLURM_ARRAY_TASK_ID", "7"); ("SLURM_ARRAY_TASK_COUNT", "16") ]));
  user_error "unset" (fun () -> Plan.slurm_shard (env []));
  user_error "not a number" (fun () ->
      Plan.slurm_shard
        (env [ ("SLURM_ARRAY_TASK_ID", "x"); ("SLURM_ARRAY_TASK_COUNT", "4") ]));
  user_error "past the count" (fun () ->
      Plan.slurm_shard
        (env [ ("SLURM_ARRAY_TASK_ID", "4"); ("SLURM_ARRAY_TASK_COUNT", "4") ]))

(* A source of no file: only its animation matters to [time_of]. *)
let source ?animation () : Scenes.t =
  {
    file = "none.rts";
    builtin = true;
    animation;
    evaluate = (fun ~progress:_ ~cancel:_ ~time:_ ~frame:_ -> (scene (), []));
    inputs = (fun () -> []);
    names = (fun () -> []);
    text_digest = (fun () -> "text");
    input_digest = (fun _ -> "-");
  }

let still_time () =
  let anim = source ~animation:(10., 6) () and still = source () in
  let tf = Alcotest.(pair (float 1e-12) int) in
  Alcotest.check tf "nothing given" (0., 0) (Scenes.time_of still ~time:None ~frame:None);
  Alcotest.check tf "frame 3 at 10 fps" (0.3, 3)
    (Scenes.time_of anim ~time:None ~frame:(Some 3));
  Alcotest.check tf "time 0.25 s is frame 2" (0.25, 2)
    (Scenes.time_of anim ~time:(Some 0.25) ~frame:None);
  Alcotest.check tf "24 fps without an animation" (0.5, 12)
    (Scenes.time_of still ~time:(Some 0.5) ~frame:None);
  user_error "frame 6 of 6" (fun () -> Scenes.time_of anim ~time:None ~frame:(Some 6));
  user_error "a frame of a still" (fun () ->
      Scenes.time_of still ~time:None ~frame:(Some 0));
  user_error "both" (fun () -> Scenes.time_of anim ~time:(Some 0.) ~frame:(Some 0));
  user_error "not finite" (fun () ->
      Scenes.time_of anim ~time:(Some Float.nan) ~frame:None)

(* ---- The frames record ---- *)

(* What a run that wrote [text] records of it. *)
let written text : Image.written =
  { size = String.length text; md5 = lazy (Digest.to_hex (Digest.string text)) }

let frames_record () =
  let dir = tmpdir () in
  let frame k = Filename.concat dir (Frameset.frame_name k) in
  let current f = if f = "tex.ppm" then "d1" else "-" in
  let set = Frameset.open_ ~dir ~scene:"/scenes/a.rts" ~job:"J" ~count:2 () in
  Alcotest.(check bool)
    "nothing done yet" false
    (Frameset.is_done set 0 ~input_digest:current);
  write (frame 0) "frame zero";
  Frameset.record set 0 ~written:(written "frame zero") ~inputs:[ ("tex.ppm", "d1") ];
  Alcotest.(check bool) "frame 0 done" true (Frameset.is_done set 0 ~input_digest:current);
  Alcotest.(check bool)
    "not once its input changed" false
    (Frameset.is_done set 0 ~input_digest:(fun _ -> "d2"));
  Alcotest.(check bool)
    "not while frame 1 is missing: no merged view" false
    (Frameset.finish set ~input_digest:current);
  Alcotest.(check bool)
    "no view yet" false
    (Sys.file_exists (Filename.concat dir Frameset.view_name));
  (* Another run of the same job reads the first one's journal. *)
  let again = Frameset.open_ ~dir ~scene:"/scenes/a.rts" ~job:"J" ~count:2 () in
  Alcotest.(check bool)
    "a second run sees frame 0" true
    (Frameset.is_done again 0 ~input_digest:current);
  write (frame 1) "frame one";
  Frameset.record again 1 ~written:(written "frame one") ~inputs:[];
  Alcotest.(check bool)
    "every frame done: the view is written" true
    (Frameset.finish again ~input_digest:current);
  (* The merged view alone carries the record. *)
  let jdir = Filename.concat dir Frameset.journal_dir in
  Array.iter
    (fun n ->
      if Filename.check_suffix n ".jsonl" then Sys.remove (Filename.concat jdir n))
    (Sys.readdir jdir);
  let third = Frameset.open_ ~dir ~scene:"/scenes/a.rts" ~job:"J" ~count:2 () in
  List.iter
    (fun k ->
      Alcotest.(check bool)
        (Printf.sprintf "frame %d read back from the view" k)
        true
        (Frameset.is_done third k ~input_digest:current))
    [ 0; 1 ];
  let other = Frameset.open_ ~dir ~scene:"/scenes/a.rts" ~job:"K" ~count:2 () in
  Alcotest.(check bool)
    "another job's frames are not done" false
    (Frameset.is_done other 0 ~input_digest:current);
  write (frame 0) "frame 0 damaged";
  Alcotest.(check bool)
    "a frame of another size is not done" false
    (Frameset.is_done third 0 ~input_digest:current);
  write (frame 0) "frame zerO";
  Alcotest.(check bool)
    "a frame of the same size and other bytes is not done" false
    (Frameset.is_done third 0 ~input_digest:current);
  user_error "a directory of another scene" (fun () ->
      Frameset.open_ ~dir ~scene:"/scenes/b.rts" ~job:"J" ~count:2 ())

(* Another run may replace a frame between this run's write and its record: the record
   says what this run wrote, so the other run's bytes are not taken for this job's. *)
let frame_replaced_before_record () =
  let dir = tmpdir () in
  let frame0 = Filename.concat dir (Frameset.frame_name 0) in
  let set = Frameset.open_ ~dir ~scene:"/scenes/a.rts" ~job:"J" ~count:1 () in
  write frame0 "this job's frame";
  write frame0 "another job's frame";
  Frameset.record set 0 ~written:(written "this job's frame") ~inputs:[];
  Alcotest.(check bool)
    "the other run's frame is not done for this job" false
    (Frameset.is_done set 0 ~input_digest:(fun _ -> "-"));
  write frame0 "this job's frame";
  Alcotest.(check bool)
    "the frame as written is" true
    (Frameset.is_done set 0 ~input_digest:(fun _ -> "-"))

(* ---- An animation's plan, through a source of the test's own ---- *)

(* Four frames of the small scene, each reading one input whose digest [input] says. *)
let animation_source ?(text = "text") input : Scenes.t =
  {
    file = "anim.rts";
    builtin = false;
    animation = Some (4., 4);
    evaluate = (fun ~progress:_ ~cancel:_ ~time:_ ~frame:_ -> (scene (), [ "tex.ppm" ]));
    inputs = (fun () -> [ "anim.rts"; "tex.ppm" ]);
    names = (fun () -> [ "tex.ppm" ]);
    text_digest = (fun () -> text);
    input_digest = (fun _ -> !input);
  }

let animation_plan () =
  let dir = Filename.concat (tmpdir ()) "frames" in
  let input = ref "d1" in
  let plan ?text ?(resume = true) ?frames shard =
    Animation.plan ~dir:(Some dir) ~frames ~shard ~resume ~overrides:Overrides.none
      (fun () -> animation_source ?text input)
  in
  let written = ref [] in
  let render p =
    written := [];
    Animation.render ~domains:1 p ~on_frame:(fun k _ -> written := k :: !written);
    Animation.finish p;
    List.sort compare !written
  in
  let p = plan (Some (Plan.Shard (1, 2))) in
  Alcotest.(check (list int)) "shard 1/2: frames 1 and 3" [ 1; 3 ] p.todo;
  Alcotest.(check (list int)) "rendered" [ 1; 3 ] (render p);
  Alcotest.(check bool)
    "no merged view with half the frames" false
    (Sys.file_exists (Filename.concat dir Frameset.view_name));
  let p = plan None in
  Alcotest.(check int) "resumed: the other shard's two" 2 p.resumed;
  Alcotest.(check (list int)) "the rest" [ 0; 2 ] (render p);
  Alcotest.(check bool)
    "every frame done: the merged view" true
    (Sys.file_exists (Filename.concat dir Frameset.view_name));
  Alcotest.(check (list int)) "nothing left" [] (plan None).todo;
  Alcotest.(check (list int))
    "without resume, every frame of the range" [ 1; 2 ]
    (plan ~resume:false ~frames:(1, 2) None).todo;
  input := "d2";
  Alcotest.(check (list int))
    "an input changed: all again" [ 0; 1; 2; 3 ] (plan None).todo;
  input := "d1";
  Alcotest.(check (list int))
    "another text: all again" [ 0; 1; 2; 3 ] (plan ~text:"other" None).todo;
  let fb, _ = Render.render (scene ()) in
  let expected = Image.to_bytes (scene ()).settings.gamma fb in
  let w, h, bytes =
    match Image.read_rgb8 (Filename.concat dir (Frameset.frame_name 2)) with
    | Ok i -> i
    | Error m -> Alcotest.fail m
  in
  Alcotest.(check (pair int int)) "a frame's size" (40, 36) (w, h);
  Alcotest.(check bool)
    "a frame's bytes are the render's" true (Bytes.equal expected bytes);
  user_error "past the animation" (fun () -> plan ~frames:(2, 4) None);
  user_error "no directory" (fun () ->
      Animation.plan ~dir:None ~frames:None ~shard:None ~resume:false
        ~overrides:Overrides.none (fun () -> animation_source input))

(* ---- The still checkpoint ---- *)

let checkpoint_roundtrip () =
  let dir = tmpdir () in
  let out = Filename.concat dir "still.png" in
  let sc = scene () in
  let tiles = Array.length (Render.tiles sc) in
  Alcotest.(check int) "four tiles" 4 tiles;
  let ck = Checkpoint.start ~out ~key:"k1" sc in
  Alcotest.(check int) "a new checkpoint holds nothing" 0 (Checkpoint.resumed ck);
  Alcotest.(check int) "its tiles" 4 (Checkpoint.tiles ck);
  ignore
    (Render.render_tiles
       ~on_tile:(fun _ k st -> Checkpoint.tiles_done ck [| k |] st)
       sc (Checkpoint.framebuffer ck) [| 0; 2 |]);
  Checkpoint.save ck;
  Alcotest.(check bool)
    "saved beside the output" true
    (Sys.file_exists (Checkpoint.path_for out));
  let back = Checkpoint.start ~out ~key:"k1" sc in
  Alcotest.(check int) "two tiles come back" 2 (Checkpoint.resumed back);
  Alcotest.(check (array int)) "the other two are to do" [| 1; 3 |] (Checkpoint.todo back);
  Checkpoint.render back sc;
  let fb, st = Render.render sc in
  Alcotest.(check bool)
    "the resumed image is the uninterrupted one, bit for bit" true
    (floats_equal fb.data (Checkpoint.framebuffer back).data);
  Alcotest.(check int)
    "and its counters" (Counters.total_rays st)
    (Counters.total_rays (Checkpoint.stats back));
  Alcotest.(check int)
    "another key starts afresh" 0
    (Checkpoint.resumed (Checkpoint.start ~out ~key:"k2" sc));
  let text = In_channel.with_open_bin (Checkpoint.path_for out) In_channel.input_all in
  write (Checkpoint.path_for out) (String.sub text 0 (String.length text - 7));
  Alcotest.(check int)
    "a damaged checkpoint is ignored" 0
    (Checkpoint.resumed (Checkpoint.start ~out ~key:"k1" sc));
  Checkpoint.remove back;
  Alcotest.(check bool) "removed" false (Sys.file_exists (Checkpoint.path_for out))

(* A still's key names the files it read and their digests as the source gives them when
   the key is made: an edited texture is another key, the same one is the same key. *)
let checkpoint_key_follows_inputs () =
  let input = ref "d1" in
  let key () =
    Checkpoint.key (animation_source input) Overrides.none ~time:0. ~frame:0
      ~files:[ "tex.ppm" ]
  in
  let k1 = key () in
  Alcotest.(check string) "the same inputs, the same key" k1 (key ());
  input := "d2";
  Alcotest.(check bool) "an edited input, another key" false (String.equal k1 (key ()));
  Alcotest.(check bool)
    "no input file, another key" false
    (String.equal k1
       (Checkpoint.key (animation_source input) Overrides.none ~time:0. ~frame:0 ~files:[]))

(* ---- Work units ---- *)

(* What a cutter hands out is what [plan] predicts, and rendering the units through the
   one unit renderer gives the bytes of a whole render. *)
let units_cut_and_render () =
  let sc = scene () in
  let fb, _ = Render.render sc in
  List.iter
    (fun (ranks, frames, domains) ->
      let label = Printf.sprintf "%d frame(s) over %d ranks of %d" frames ranks domains in
      let c = Work.cutter ~ranks (List.init frames (fun k -> (k, fun () -> scene ()))) in
      let rec all acc =
        match Work.next c ~domains with
        | None -> List.rev acc
        | Some (u : Work.work_unit) -> all (u :: acc)
      in
      let units = all [] in
      Alcotest.(check (list (pair int int)))
        (label ^ ": the plan's units")
        (Work.plan ~ranks ~domains (List.init frames (fun _ -> 4)))
        (List.map (fun (u : Work.work_unit) -> (u.key, Array.length u.tiles)) units);
      let complete = ref [] in
      List.iter
        (fun (u : Work.work_unit) ->
          let f = Work.frame c u.key in
          let st = Work.render_unit ~pool:None f.sc f.fb u.tiles in
          Option.iter
            (fun (f : Work.frame) -> complete := (u.key, f) :: !complete)
            (Work.deposit c u.key u.tiles st))
        units;
      Alcotest.(check (list int))
        (label ^ ": every frame completes once")
        (List.init frames Fun.id)
        (List.sort compare (List.map fst !complete));
      List.iter
        (fun (k, (f : Work.frame)) ->
          Alcotest.(check bool)
            (Printf.sprintf "%s: frame %d is the whole render's bytes" label k)
            true
            (floats_equal fb.data f.fb.data))
        !complete)
    [ (1, 1, 2); (3, 1, 1); (3, 2, 1); (2, 2, 1); (4, 1, 2) ]

(* ---- Overrides and files ---- *)

let overrides () =
  let sc = scene () in
  Alcotest.(check (list string))
    "nothing overridden" [ "-"; "-"; "-"; "-"; "-" ]
    (Overrides.digest_fields Overrides.none);
  Alcotest.(check bool) "no change" true (Overrides.apply Overrides.none sc == sc);
  let s =
    (Overrides.apply { Overrides.none with width = Some 20; samples = Some 3 } sc)
      .settings
  in
  Alcotest.(check (pair int int)) "the size" (20, 36) (s.width, s.height);
  Alcotest.(check int) "the samples" 3 s.samples;
  let draft = Overrides.apply { Overrides.none with quality = Some Quality.Draft } sc in
  Alcotest.(check bool) "draft: at most depth 3" true (draft.settings.depth <= 3);
  user_error "a depth past the bound" (fun () ->
      Overrides.apply { Overrides.none with depth = Some (Settings.max_depth + 1) } sc)

let guarded_files () =
  let dir = tmpdir () in
  let a = Filename.concat dir "a.rts" in
  write a "x";
  user_error "writing over a file read" (fun () ->
      Files.guard_writes ~reads:[ (a, "the scene") ] [ (a, "the image") ]);
  user_error "by another name" (fun () ->
      Files.guard_writes
        ~reads:[ (a, "the scene") ]
        [ (Filename.concat (Filename.concat dir ".") "a.rts", "the image") ]);
  let b = Filename.concat dir "b.png" in
  user_error "two writes to one file" (fun () ->
      Files.guard_writes ~reads:[] [ (b, "the image"); (b, "the statistics") ]);
  Files.guard_writes ~distinct:false ~reads:[] [ (b, "the image"); (b, "the statistics") ];
  user_error "a missing directory" (fun () ->
      Files.check_writable (Filename.concat dir "no/such.png"));
  let cancel = Cancel.create () in
  Cancel.cancel cancel;
  let ran = ref false in
  (match Files.uninterrupted ~cancel "b.png" (fun () -> ran := true) with
  | () -> Alcotest.fail "a cancelled write ran"
  | exception Sys.Break -> ());
  Alcotest.(check bool) "nothing written once cancelled" false !ran;
  let c = Cancel.create () in
  match Files.uninterrupted ~cancel:c "b.png" (fun () -> Cancel.cancel c) with
  | () -> Alcotest.fail "an interrupt during the write went unsaid"
  | exception Job_error.Interrupted what ->
      Alcotest.(check string) "said once written" "b.png was written in full first" what

(* ---- A still's scene from its program ---- *)

let grid_text n =
  Printf.sprintf
    {|let n = %d
settings { width: 8, height: 6 }
camera { position: (0, 0.6 * n, -0.9 * n), look_at: (0, 0, 0) }
light { position: (-0.4 * n, 0.8 * n, -0.6 * n) }
for i in 0 to n - 1 { for j in 0 to n - 1 { sphere { center: (i - n / 2, 0.4, j - n / 2), radius: 0.4 } } }
|}
    n

let load ?single text =
  match Lancer.Program.load_string ?single ~filename:"grid.rts" text with
  | Ok p -> p
  | Error _ -> Alcotest.fail "the grid does not load"

let made = function Ok sc -> sc | Error _ -> Alcotest.fail "the grid does not compile"

(* A still loaded for its one scene has its objects compiled as the load makes them: the
   program never holds them, the scene is the one a description of them makes, and what
   check prints of them is made again. A program asked for several scenes keeps the
   load's description for them. *)
let still_compiles_as_it_loads () =
  let module Dsl = Lancer_dsl.Dsl in
  let q = load (grid_text 40) in
  let kept = made (Program.scene_at ~index:false q ~time:0. ~frame:0) in
  let json_before = Yojson.Safe.to_string (Program.to_json q kept) in
  Alcotest.(check bool)
    "not asked for one scene: not emitted" false
    (Dsl.emitted (Program.language q));
  Alcotest.(check int)
    "not asked for one scene: the program keeps the objects" 1600
    (List.length (Dsl.first (Program.language q)).objects);
  let p = load ~single:true (grid_text 40) in
  Alcotest.(check bool) "asked for one: emitted" true (Dsl.emitted (Program.language p));
  Alcotest.(check int)
    "the program keeps none" 0
    (List.length (Dsl.first (Program.language p)).objects);
  let overhead = (Gc.get ()).space_overhead in
  let sc = made (Program.scene_at p ~time:0. ~frame:0) in
  Alcotest.(check int) "the GC as it was" overhead (Gc.get ()).space_overhead;
  Alcotest.(check int) "every object compiled" 1600 (Array.length sc.objects);
  let whole = made (Program.scene_at q ~time:0. ~frame:0) in
  Alcotest.(check bool)
    "the primitives a description of them makes" true
    (Array.for_all2
       (fun (a : Primitive.t) (b : Primitive.t) -> a.shape = b.shape && a.color = b.color)
       sc.objects whole.objects);
  Alcotest.(check string)
    "check's objects, made again" json_before
    (Yojson.Safe.to_string (Program.to_json p sc));
  (match Dsl.describe (Program.language p) ~time:0. ~frame:0 with
  | Ok d -> Alcotest.(check int) "time 0 evaluated again" 1600 (List.length d.objects)
  | Error _ -> Alcotest.fail "time 0 does not evaluate again");
  let again = made (Program.scene_at p ~time:0. ~frame:0) in
  Alcotest.(check int) "a second scene" 1600 (Array.length again.objects)

(* A program that writes what could make it move (here a camera's shutter, closed) is not
   compiled as it loads; loaded for one scene, its first scene at time 0 of a still lets
   the load's objects go as they compile: nothing keeps them once they are primitives. *)
let still_lets_objects_go () =
  let module Dsl = Lancer_dsl.Dsl in
  let text =
    {|let n = 40
settings { width: 8, height: 6 }
camera { position: (0, 0.6 * n, -0.9 * n), look_at: (0, 0, 0), shutter: (0, 0) }
light { position: (-0.4 * n, 0.8 * n, -0.6 * n) }
for i in 0 to n - 1 { for j in 0 to n - 1 { sphere { center: (i - n / 2, 0.4, j - n / 2), radius: 0.4 } } }
|}
  in
  let p = load ~single:true text in
  Alcotest.(check bool)
    "a shutter written: not emitted" false
    (Dsl.emitted (Program.language p));
  let json_before =
    let q = load text in
    Yojson.Safe.to_string
      (Program.to_json q (made (Program.scene_at ~index:false q ~time:0. ~frame:0)))
  in
  let w = Weak.create 1 in
  (match (Dsl.first (Program.language p)).objects with
  | o :: _ -> Weak.set w 0 (Some o)
  | [] -> Alcotest.fail "no objects");
  let overhead = (Gc.get ()).space_overhead in
  let sc = made (Program.scene_at p ~time:0. ~frame:0) in
  Alcotest.(check int) "the GC as it was" overhead (Gc.get ()).space_overhead;
  Gc.full_major ();
  Alcotest.(check bool) "no description object is kept" false (Weak.check w 0);
  Alcotest.(check int)
    "the program keeps none" 0
    (List.length (Dsl.first (Program.language p)).objects);
  Alcotest.(check int) "every object compiled" 1600 (Array.length sc.objects);
  Alcotest.(check string)
    "check's objects, made again" json_before
    (Yojson.Safe.to_string (Program.to_json p sc));
  let again = made (Program.scene_at p ~time:0. ~frame:0) in
  Alcotest.(check int) "a second scene" 1600 (Array.length again.objects)

(* Without its hierarchy a scene answers and reports as with it: the same nearest hits,
   features and estimates. *)
let scene_without_index () =
  let p = load (grid_text 12) and q = load (grid_text 12) in
  let built = made (Program.scene_at p ~time:0. ~frame:0)
  and scan = made (Program.scene_at ~index:false q ~time:0. ~frame:0) in
  Alcotest.(check bool) "a tree built" true (Accel.uses_bvh built.accel);
  Alcotest.(check bool) "reported without one" true (Accel.uses_bvh scan.accel);
  Alcotest.(check bool) "the same features" true (built.features = scan.features);
  Alcotest.(check bool) "the same estimate" true (Cost.estimate built = Cost.estimate scan);
  Alcotest.(check string)
    "the same summary" (Program.summary p built) (Program.summary q scan);
  let rng = Random.State.make [| 7 |] in
  for _ = 1 to 200 do
    let f () = Random.State.float rng 2. -. 1. in
    let o = Vec3.v (f () *. 8.) (2. +. f ()) (f () *. 8.)
    and d = Vec3.v (f ()) (-1.) (f ()) in
    let r = Ray.make o d in
    let nearest a =
      let q = Probe.create () and h = Walk.hit () in
      Probe.of_ray q r;
      q.p_tmin <- 0.;
      q.p_tmax <- infinity;
      Accel.nearest (Accel.domain_scratch ()) a q h;
      (q.p_t, h.item)
    in
    let t1, i1 = nearest built.accel and t2, i2 = nearest scan.accel in
    Alcotest.(check bool) "the same hit" true (Float.equal t1 t2 && i1 = i2)
  done;
  let few = Array.sub built.objects 0 5 in
  Alcotest.(check bool) "too few for a tree" false (Accel.uses_bvh (Accel.unindexed few))

(* Moving many primitives at once is moving each, and those made without a shift share
   the one the move gives them. *)
let mover_shares_shift () =
  let d = Vec3.v (-1024.) 0. 2048. in
  let a =
    Primitive.make Material.default (Shape.sphere ~center:(Vec3.v 1. 2. 3.) ~radius:0.5)
  and b =
    Primitive.make Material.default (Shape.sphere ~center:(Vec3.v 4. 5. 6.) ~radius:1.)
  in
  let move = Primitive.mover d in
  let ma = move a and mb = move b in
  Alcotest.(check bool) "as translate" true (ma = Primitive.translate d a);
  Alcotest.(check bool) "as translate" true (mb = Primitive.translate d b);
  Alcotest.(check bool) "one shift" true (ma.shift == mb.shift)

(* ---- Frames that share their pixels ---- *)

(* The frames of an animation as [Animation.render] writes them (one domain, so one frame
   after the other, windows of frames sharing what does not move), each against a render
   of its own scene from scratch: the same bytes. Returns the primary rays of each frame
   as rendered there. *)
let frames_as_rendered ?(domains = 1) name text =
  let p = load_anim text in
  let fps, count =
    match Lancer.Program.animation p with
    | Some a -> a
    | None -> Alcotest.fail "not animated"
  in
  let source : Scenes.t =
    {
      file = "anim.rts";
      builtin = false;
      animation = Some (fps, count);
      evaluate =
        (fun ~progress:_ ~cancel:_ ~time ~frame ->
          match Lancer.Program.scene_at p ~time ~frame with
          | Ok sc -> (sc, [])
          | Error _ -> Alcotest.fail "the animated scene does not evaluate");
      inputs = (fun () -> [ "anim.rts" ]);
      names = (fun () -> []);
      text_digest = (fun () -> text);
      input_digest = (fun _ -> "");
    }
  in
  let dir = Filename.concat (tmpdir ()) "frames" in
  let plan =
    Animation.plan ~dir:(Some dir) ~frames:None ~shard:None ~resume:false
      ~overrides:Overrides.none (fun () -> source)
  in
  let primary = Array.make count 0 in
  Animation.render ~domains plan ~on_frame:(fun k st -> primary.(k) <- st.primary);
  Animation.finish plan;
  let fresh = load_anim text in
  for k = 0 to count - 1 do
    let sc =
      match Lancer.Program.scene_at fresh ~time:(Float.of_int k /. fps) ~frame:k with
      | Ok sc -> sc
      | Error _ -> Alcotest.fail "a frame does not evaluate"
    in
    let fb, _ = Render.render sc in
    let expected = Image.to_bytes sc.settings.gamma fb in
    match Image.read_rgb8 (Filename.concat dir (Frameset.frame_name k)) with
    | Error m -> Alcotest.fail m
    | Ok (_, _, bytes) ->
        if not (Bytes.equal expected bytes) then
          Alcotest.failf "%s: frame %d differs from its own render" name k
  done;
  primary

(* A field of still spheres, a mirror, a shiny sphere, a soft light, a spot light, a
   textured floor, fog and a sky, and one sphere moving across: what the moving sphere's
   queries can reach in any frame is rendered in every frame, the rest once a window. *)
let shared_scene =
  {|settings { width: 48, height: 32, samples: 2, depth: 6,
           background: gradient((0.9, 0.8, 0.7), (0.2, 0.3, 0.8)), fog: fog((0.6, 0.6, 0.7), 30) }
animation { fps: 10, frames: 7 }
camera { position: (0, 4, -9), look_at: (0, 0.5, 0), fov: 55 }
light { position: (-3, 6, -4), radius: 0.4, samples: 2 }
light { position: (3, 5, -2), point_at: (1, 0, 1), inner: 10, outer: 30 }
plane { normal: (0, 1, 0), offset: 0, material: material { texture: checker((1, 1, 1), (0.2, 0.2, 0.2), 1) } }
plane { normal: (0, 0, 1), offset: 6, material: material { reflection: 0.6 } }
sphere { center: (2, 0.8, 0), radius: 0.8, material: material { specular: 0.8, shininess: 80, reflection: 0.5 } }
for i in 0 to 9 { for j in 0 to 3 {
  sphere { center: (i - 5, 0.25, j - 1), radius: 0.25, material: material { color: (0.3 + i / 15, 0.5, 0.6) } }
} }
sphere { center: (-4 + 1.2 * time * 10, 1, -1), radius: 0.6,
         material: material { color: (0.9, 0.2, 0.1), reflection: 0.3, specular: 0.5 } }
|}

(* [text] with its first [what] replaced by [by]. *)
let variant_of text what by =
  let n = String.length what in
  let rec at i =
    if i + n > String.length text then Alcotest.failf "no %S in the scene" what
    else if String.sub text i n = what then i
    else at (i + 1)
  in
  let i = at 0 in
  String.sub text 0 i ^ by ^ String.sub text (i + n) (String.length text - i - n)

let frames_share_pixels () =
  (* On one domain the frames of a window one after the other; on two, its first over
     both in tiles, the others in parallel. *)
  List.iter
    (fun domains ->
      let primary =
        frames_as_rendered ~domains
          (Printf.sprintf "a sphere moving, %d domains" domains)
          shared_scene
      in
      (* 48×32 pixels, 2×2 samples: 6144 primary rays where every pixel is rendered. *)
      Alcotest.(check int) "the first frame renders every pixel" 6144 primary.(0);
      Array.iteri
        (fun k n ->
          if k > 0 && not (n > 0 && n < 6144 / 2) then
            Alcotest.failf "frame %d cast %d primary rays: expected under half of 6144" k
              n)
        primary)
    [ 1; 2 ];
  (* Glass among the still spheres and on the moving one: shared as well, the frames
     their own renders to the byte (a shadow ray's crossings multiply in the order of
     their values, whichever structures hold them). *)
  let glass =
    variant_of shared_scene "material: material { color: (0.3 + i / 15, 0.5, 0.6) }"
      "material: material { color: (0.3 + i / 15, 0.5, 0.6), transparency: 0.5, ior: 1.2 \
       }"
  in
  let glass =
    variant_of glass "reflection: 0.3, specular: 0.5 }"
      "transparency: 0.9, ior: 1.5, fresnel: true }"
  in
  let primary = frames_as_rendered "glass spheres, one of them moving" glass in
  Array.iteri
    (fun k n ->
      if k > 0 && not (n > 0 && n < 6144 / 2) then
        Alcotest.failf "glass: frame %d cast %d primary rays: expected under half of 6144"
          k n)
    primary;
  (* What changes more than the moving part: nothing is shared, and the frames are the
     same as their own renders. *)
  let variant = variant_of shared_scene in
  List.iter
    (fun (name, text) ->
      let primary = frames_as_rendered name text in
      Array.iteri
        (fun k n ->
          if n <> 6144 then
            Alcotest.failf "%s: frame %d cast %d primary rays, not 6144" name k n)
        primary)
    [
      ( "a moving light",
        variant "light { position: (-3, 6, -4)" "light { position: (-3 + time, 6, -4)" );
      ( "a moving camera",
        variant "camera { position: (0, 4, -9)" "camera { position: (time, 4, -9)" );
      ( "jittered samples",
        variant "samples: 2, depth: 6" "samples: 2, jitter: true, depth: 6" );
      ( "a moving plane",
        variant "plane { normal: (0, 0, 1), offset: 6"
          "plane { normal: (0, 0, 1), offset: 6 + time" );
    ]

let () =
  Alcotest.run "job"
    [
      ( "plan",
        [
          Alcotest.test_case "frame ranges and shards as typed" `Quick frames_syntax;
          Alcotest.test_case "shards partition the frames" `Quick shards_partition;
          Alcotest.test_case "a Slurm task's shard" `Quick slurm;
          Alcotest.test_case "the time and frame of a still" `Quick still_time;
        ] );
      ( "records",
        [
          Alcotest.test_case "the frames record: journals, view, damage" `Quick
            frames_record;
          Alcotest.test_case "a frame replaced before its record is not this job's" `Quick
            frame_replaced_before_record;
          Alcotest.test_case "a checkpoint comes back bit for bit" `Quick
            checkpoint_roundtrip;
          Alcotest.test_case "a still's checkpoint key follows its inputs' digests" `Quick
            checkpoint_key_follows_inputs;
          Alcotest.test_case "an animation's plan: shards, resume, stale frames" `Quick
            animation_plan;
        ] );
      ( "frames",
        [
          Alcotest.test_case "every frame shares one index of what does not move" `Quick
            frames_share_the_fixed_part;
          Alcotest.test_case "a frame allocates for what moves, not for what does not"
            `Quick frames_cost_what_moves;
          Alcotest.test_case "frames of still and moving pieces in any order" `Quick
            frames_in_pieces;
          Alcotest.test_case "frames share the pixels that nothing moving reaches" `Quick
            frames_share_pixels;
          Alcotest.test_case "glass frames are their stills, bit for bit" `Quick
            glass_frames_are_their_stills;
          Alcotest.test_case "the scenes of several instants of one frame" `Quick
            scenes_of_one_frame;
        ] );
      ( "work",
        [
          Alcotest.test_case "units as planned, pixels as rendered" `Quick
            units_cut_and_render;
        ] );
      ( "scenes",
        [
          Alcotest.test_case "a still compiles its objects as it loads" `Quick
            still_compiles_as_it_loads;
          Alcotest.test_case "a still lets its objects go as they compile" `Quick
            still_lets_objects_go;
          Alcotest.test_case "a scene without its hierarchy" `Quick scene_without_index;
          Alcotest.test_case "moving many primitives" `Quick mover_shares_shift;
        ] );
      ( "options",
        [
          Alcotest.test_case "overrides" `Quick overrides;
          Alcotest.test_case "guarded writes" `Quick guarded_files;
        ] );
    ]
