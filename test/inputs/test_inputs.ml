(* What a run reads and what it records of it: no frame written over a file some frame
   reads, records that say what was written and what was decoded, runs with other
   options into one directory. *)

open Lancer
open Lancer_job
open Run_lancer

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"
let lancer ?prefix ~dir args = run ?prefix ~exe ~dir args
let spawn ~dir args = spawn ~exe ~dir args
let path d f = Filename.concat d f
let frame k = Printf.sprintf "frame_%04d.png" k

let write_ppm p (r, g, b) =
  write_file p
    ("P6\n2 2\n255\n"
    ^ String.concat ""
        (List.init 4 (fun _ -> String.init 3 (fun i -> Char.chr [| r; g; b |].(i)))))

let md5 p = Digest.to_hex (Digest.file p)

(* ---- No frame replaces a file a later frame reads ---- *)

(* From frame 2 on, a sphere wears the image [texture]: a file the first frame's
   evaluation never reads. *)
let later_texture texture =
  Printf.sprintf
    {|settings { width: 16, height: 12 }
animation { fps: 10, frames: 4 }
camera { position: (0, 1, -5), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
sphere { center: (0, 1, 0), radius: 1, material: material { color: (0.9, 0.2, 0.2) } }
if frame >= 2 { sphere { center: (1, 1, 0), radius: 0.5, material: material { texture: image("%s", 1) } } }
|}
    texture

let later_frame_texture_is_kept () =
  let d = tmpdir "lancer-inputs" in
  Unix.mkdir (path d "fr") 0o755;
  (* The user's texture, which happens to be where frame 0 would go. *)
  let tex = path d "fr/frame_0000.png" in
  (match lancer ~dir:d [ "render"; "--width"; "4"; "--height"; "4"; "-o"; tex; "-q" ] with
  | 0, _, _ -> ()
  | _, _, e -> Alcotest.failf "could not make the texture: %s" e);
  let before = md5 tex in
  write_file (path d "a.rts") (later_texture "fr/frame_0000.png");
  let r = lancer ~dir:d [ "animate"; "a.rts"; "-o"; "fr"; "-q" ] in
  check_status "refused" 1 r;
  says "says why" r "refusing to write a frame to fr/frame_0000.png";
  says "names the file" r "the scene names that file";
  Alcotest.(check string) "the texture is untouched" before (md5 tex);
  Alcotest.(check bool)
    "no frame was written" false
    (Sys.file_exists (path d "fr/frame_0001.png"))

(* A name in code that never runs (a macro nobody calls, a branch never taken) is still a
   name the scene may read. *)
let names_in_code_that_never_runs () =
  let d = tmpdir "lancer-inputs" in
  write_file (path d "a.rts")
    {|settings { width: 8, height: 6 }
animation { fps: 10, frames: 2 }
light { position: (-3, 5, -4) }
sphere { center: (0, 0, 0), radius: 1 }
fn dressed(c) { sphere { center: c, radius: 1, material: material { texture: image("out/frame_0001.png", 1) } } }
if frame > 100 { dressed((0, 0, 0)) }
|};
  let r = lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "-q" ] in
  check_status "refused" 1 r;
  says "says why" r "refusing to write a frame to out/frame_0001.png";
  Alcotest.(check bool)
    "nothing written" false
    (Sys.file_exists (path d "out/frame_0000.png"))

(* ---- A texture replaced while the scene is made ---- *)

(* Six frames; a sphere wears tex.ppm from frame 0 on. *)
let textured =
  {|settings { width: 16, height: 12 }
animation { fps: 10, frames: 3 }
camera { position: (0, 1, -5), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
sphere { center: (0, 1, 0), radius: 1, material: material { texture: image("tex.ppm", 1) } }
|}

(* The program of [a.rts] in [d], its texture swapped for another colour the moment its
   bytes are read (before anything is decoded or digested), once. *)
let load_swapping d =
  let swapped = ref false in
  let after_read p =
    if (not !swapped) && Filename.basename p = "tex.ppm" then (
      swapped := true;
      write_ppm p (30, 30, 200))
  in
  match Program.load_file ~after_read (path d "a.rts") with
  | Ok p -> p
  | Error _ -> Alcotest.fail "the scene does not load"

let plan ?(resume = false) d load =
  Animation.plan
    ~dir:(Some (path d "fr"))
    ~frames:None ~shard:None ~resume ~overrides:Overrides.none
    (fun () -> Program.as_scenes ~builtin:false (load ()))

(* What a frame's record says of its texture is what the frame was made of: the bytes
   decoded, not the file as it was a moment later. A run resumed with the new texture
   renders every frame again. *)
let replaced_texture_frames () =
  let d = tmpdir "lancer-inputs" in
  write_file (path d "a.rts") textured;
  write_ppm (path d "tex.ppm") (200, 30, 30);
  let old_md5 = md5 (path d "tex.ppm") in
  let p = plan d (fun () -> load_swapping d) in
  Animation.render ~domains:1 p ~on_frame:(fun _ _ -> ());
  Animation.finish p;
  Alcotest.(check bool)
    "the file was replaced during the run" false
    (String.equal old_md5 (md5 (path d "tex.ppm")));
  let journal = path (path d "fr") Frameset.journal_dir in
  let records =
    String.concat ""
      (List.filter_map
         (fun n ->
           if Filename.check_suffix n ".jsonl" then Some (read_file (path journal n))
           else None)
         (Array.to_list (Sys.readdir journal)))
  in
  Alcotest.(check bool)
    (Printf.sprintf "the record holds the digest of the bytes decoded:\n%s" records)
    true (contains records old_md5);
  let load () =
    match Program.load_file (path d "a.rts") with
    | Ok p -> p
    | Error _ -> Alcotest.fail "the scene does not load"
  in
  Alcotest.(check (list int))
    "resumed with the new texture: every frame again" [ 0; 1; 2 ]
    (plan ~resume:true d load).todo

(* A still's checkpoint key names the texture it was rendered with, whatever the file
   became a moment later. *)
let replaced_texture_checkpoint () =
  let d = tmpdir "lancer-inputs" in
  write_file (path d "a.rts") textured;
  write_ppm (path d "tex.ppm") (200, 30, 30);
  let key prog =
    let src = Program.as_scenes ~builtin:false prog in
    let _, files = Scenes.scene src Overrides.none ~time:0. ~frame:0 in
    Checkpoint.key src Overrides.none ~time:0. ~frame:0 ~files
  in
  let plain () =
    match Program.load_file (path d "a.rts") with
    | Ok p -> p
    | Error _ -> Alcotest.fail "the scene does not load"
  in
  let with_old = key (plain ()) in
  let swapped = key (load_swapping d) in
  Alcotest.(check string) "the key of the texture decoded" with_old swapped;
  Alcotest.(check bool)
    "and not of the one now on disk" false
    (String.equal swapped (key (plain ())))

(* ---- Runs with other options into one directory ---- *)

let many_frames =
  {|settings { width: 8, height: 6 }
animation { fps: 10, frames: 40 }
camera { position: (0, 1, -5), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
sphere { center: (sin(time), 1, 0), radius: 1, material: material { color: (0.9, 0.2, 0.2) } }
|}

(* Two runs with other samples at once into one directory replace each other's frames;
   whatever the interleaving, a resumed run with the first one's options keeps only the
   frames those options made, and ends with exactly the frames of a run alone. *)
let other_options_at_once () =
  let d = tmpdir "lancer-inputs" in
  write_file (path d "c.rts") many_frames;
  check_status "the reference" 0 (lancer ~dir:d [ "animate"; "c.rts"; "-o"; "ref"; "-q" ]);
  for round = 1 to 8 do
    let out = Printf.sprintf "fr%d" round in
    let a = spawn ~dir:d [ "animate"; "c.rts"; "-o"; out; "-q"; "--domains"; "1" ] in
    let b =
      spawn ~dir:d
        [ "animate"; "c.rts"; "-o"; out; "-q"; "--domains"; "1"; "--samples"; "2" ]
    in
    Alcotest.(check int) "first run" 0 (wait_status a);
    Alcotest.(check int) "second run" 0 (wait_status b);
    check_status "resumed" 0
      (lancer ~dir:d [ "animate"; "c.rts"; "-o"; out; "-q"; "--resume" ]);
    for k = 0 to 39 do
      if
        not
          (String.equal
             (read_file (path (path d "ref") (frame k)))
             (read_file (path (path d out) (frame k))))
      then Alcotest.failf "round %d: frame %d is not the resumed options' frame" round k
    done;
    Alcotest.(check string)
      "the merged record"
      (read_file (path (path d "ref") Frameset.view_name))
      (read_file (path (path d out) Frameset.view_name))
  done

let () =
  Alcotest.run "inputs"
    [
      ( "frames never replace what a frame reads",
        [
          Alcotest.test_case "a texture a later frame reads is refused as an output"
            `Quick later_frame_texture_is_kept;
          Alcotest.test_case "a name in code that never runs is protected too" `Quick
            names_in_code_that_never_runs;
        ] );
      ( "records say what was used",
        [
          Alcotest.test_case "frames record the texture they decoded" `Quick
            replaced_texture_frames;
          Alcotest.test_case "a checkpoint's key names the texture decoded" `Quick
            replaced_texture_checkpoint;
          Alcotest.test_case "runs with other options at once, then resumed" `Quick
            other_options_at_once;
        ] );
    ]
