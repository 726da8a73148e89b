(* lancer animate --resume and --shard, and lancer render --resume, as a user runs them:
   what is redone after damage or a change, what survives a kill, what runs at once. *)

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"

open Run_lancer

let lancer ?prefix ~dir args = run ?prefix ~exe ~dir args
let spawn ~dir args = spawn ~exe ~dir args
let path d f = Filename.concat d f
let frame k = Printf.sprintf "frame_%04d.png" k
let mtime p = (Unix.stat p).Unix.st_mtime

(* Six frames; from frame 3 on a sphere wears an image texture. *)
let scene ?(color = "(0.9, 0.2, 0.2)") ?(frames = 6) ?(camera = "") () =
  Printf.sprintf
    {|settings { width: 24, height: 18 }
animation { fps: 10, frames: %d }
camera { position: (0, 1, -5), look_at: (0, 1, 0)%s }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0 }
body ball { sphere { center: (0, 2, 0), radius: 0.4, material: material { color: %s } } restitution: 0.8 }
if frame >= 3 { sphere { center: (1, 1, 0), radius: 0.5, material: material { texture: image("tex.ppm", 1) } } }
|}
    frames camera color

let write_ppm p (r, g, b) =
  write_file p
    ("P6\n2 2\n255\n"
    ^ String.concat ""
        (List.init 4 (fun _ -> String.init 3 (fun i -> Char.chr [| r; g; b |].(i)))))

let setup ?color ?frames ?camera () =
  let d = tmpdir "lancer-resume" in
  write_file (path d "a.rts") (scene ?color ?frames ?camera ());
  write_ppm (path d "tex.ppm") (200, 30, 30);
  d

let frames_of d n = List.init n (fun k -> read_file (path d (frame k)))

let rec wait_for ?(tries = 3000) p =
  if tries > 0 && not (p ()) then (
    Unix.sleepf 0.02;
    wait_for ~tries:(tries - 1) p)

let animate_tests =
  [
    Alcotest.test_case
      "--resume redoes exactly the damaged frames and those whose late texture changed"
      `Quick (fun () ->
        let d = setup () in
        check_status "animate" 0 (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "-q" ]);
        let out = path d "out" in
        let good = frames_of out 6 in
        (* Truncated, empty, one byte changed (same size): none of them is done. *)
        let f0 = read_file (path out (frame 0)) in
        write_file (path out (frame 0)) (String.sub f0 0 (String.length f0 / 2));
        write_file (path out (frame 1)) "";
        let f2 = Bytes.of_string (read_file (path out (frame 2))) in
        Bytes.set f2 40 (Char.chr ((Char.code (Bytes.get f2 40) + 1) land 255));
        write_file (path out (frame 2)) (Bytes.to_string f2);
        Unix.sleepf 0.02;
        let untouched = List.map (fun k -> mtime (path out (frame k))) [ 3; 4; 5 ] in
        (* ./a.rts is the scene a.rts. *)
        let r = lancer ~dir:d [ "animate"; "./a.rts"; "-o"; "out"; "--resume" ] in
        check_status "resume" 0 r;
        says "three damaged frames" r "3 frames already rendered, 3 to go";
        Alcotest.(check (list (float 0.)))
          "frames 3..5 untouched" untouched
          (List.map (fun k -> mtime (path out (frame k))) [ 3; 4; 5 ]);
        Alcotest.(check bool) "the same bytes again" true (good = frames_of out 6);
        (* The texture first used at frame 3 changes: frames 3..5 are stale, 0..2 are not. *)
        write_ppm (path d "tex.ppm") (30, 30, 200);
        let early = List.map (fun k -> mtime (path out (frame k))) [ 0; 1; 2 ] in
        let r = lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "--resume" ] in
        check_status "texture changed" 0 r;
        says "the frames that read it" r "3 frames already rendered, 3 to go";
        Alcotest.(check (list (float 0.)))
          "frames 0..2 untouched" early
          (List.map (fun k -> mtime (path out (frame k))) [ 0; 1; 2 ]);
        List.iter
          (fun k ->
            Alcotest.(check bool)
              (frame k ^ " re-rendered")
              false
              (List.nth good k = read_file (path out (frame k))))
          [ 3; 4; 5 ];
        let r = lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "--resume" ] in
        says "then nothing to do" r "6 frames already rendered, 0 to go";
        (* A directory in a frame's place is not a frame. *)
        Sys.remove (path out (frame 4));
        Unix.mkdir (path out (frame 4)) 0o755;
        let ((_, out_, _) as r) =
          lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "--resume" ]
        in
        Alcotest.(check bool)
          ("not kept: " ^ out_) false
          (contains out_ "6 frames already rendered");
        check_status "cannot replace a directory" 1 r;
        says "names it" r (frame 4));
    Alcotest.test_case "--frames without --resume keeps the other frames' records" `Quick
      (fun () ->
        let d = setup () in
        check_status "animate" 0 (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "-q" ]);
        let view = read_file (path d "out/lancer-frames.json") in
        check_status "a range again" 0
          (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "--frames"; "1..2"; "-q" ]);
        says "all six still done"
          (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "--resume" ])
          "6 frames already rendered, 0 to go";
        Alcotest.(check string)
          "the merged view is the same" view
          (read_file (path d "out/lancer-frames.json")));
    Alcotest.test_case
      "four shards at once into one directory make the same frames and manifest as one \
       animate"
      `Quick (fun () ->
        let d = setup ~frames:10 () in
        check_status "one animate" 0
          (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "ref"; "-q" ]);
        let pids =
          List.init 4 (fun k ->
              spawn ~dir:d
                [
                  "animate";
                  "a.rts";
                  "-o";
                  "shards";
                  "-q";
                  "--domains";
                  "1";
                  "--shard";
                  Printf.sprintf "%d/4" k;
                ])
        in
        List.iteri
          (fun k pid ->
            Alcotest.(check int) (Printf.sprintf "shard %d" k) 0 (wait_status pid))
          pids;
        List.iter
          (fun f ->
            Alcotest.(check bool)
              f true
              (read_file (path d ("ref/" ^ f)) = read_file (path d ("shards/" ^ f))))
          ("lancer-frames.json" :: List.init 10 frame);
        says "resume across shards"
          (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "shards"; "--resume" ])
          "10 frames already rendered, 0 to go";
        (* Two whole runs of the same scene at once lose nothing either. *)
        let pids =
          List.init 2 (fun _ ->
              spawn ~dir:d [ "animate"; "a.rts"; "-o"; "twice"; "-q"; "--domains"; "1" ])
        in
        List.iter (fun pid -> Alcotest.(check int) "a whole run" 0 (wait_status pid)) pids;
        Alcotest.(check bool)
          "same manifest" true
          (read_file (path d "ref/lancer-frames.json")
          = read_file (path d "twice/lancer-frames.json")));
    Alcotest.test_case
      "--shard slurm reads the job array's variables; bad shards are refused" `Quick
      (fun () ->
        let d = setup () in
        let env =
          "SLURM_ARRAY_TASK_ID=5 SLURM_ARRAY_TASK_MIN=4 SLURM_ARRAY_TASK_COUNT=2"
        in
        let r =
          lancer ~prefix:env ~dir:d
            [ "animate"; "a.rts"; "-o"; "out"; "--shard"; "slurm" ]
        in
        check_status "task 5 of 4..5" 0 r;
        says "shard 1 of 2" r "shard 1/2";
        Alcotest.(check (list string))
          "frames 1, 3, 5"
          [ frame 1; frame 3; frame 5; "lancer-frames.d" ]
          (List.sort compare (Array.to_list (Sys.readdir (path d "out"))));
        let r =
          lancer
            ~prefix:(env ^ " SLURM_ARRAY_TASK_ID=4")
            ~dir:d
            [ "animate"; "a.rts"; "-o"; "out"; "--shard"; "slurm" ]
        in
        check_status "task 4" 0 r;
        Alcotest.(check bool)
          "complete: the merged view" true
          (Sys.file_exists (path d "out/lancer-frames.json"));
        let r =
          lancer ~prefix:"env -u SLURM_ARRAY_TASK_ID" ~dir:d
            [ "animate"; "a.rts"; "-o"; "out"; "--shard"; "slurm" ]
        in
        check_status "outside a job array" 1 r;
        says "says why" r "SLURM_ARRAY_TASK_ID";
        let r = lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "--shard"; "4/4" ] in
        check_status "4/4" 1 r;
        says "the range" r "between 0 and 3");
    Alcotest.test_case "a shard killed with SIGKILL and resumed loses nothing" `Quick
      (fun () ->
        let d = tmpdir "lancer-resume" in
        write_file (path d "a.rts")
          "settings { width: 128, height: 96, samples: 3 }\n\
           animation { fps: 10, frames: 16 }\n\
           camera { position: (0, 1, -5), look_at: (0, 1, 0) }\n\
           light { position: (-3, 5, -4), radius: 0.5, samples: 4 }\n\
           plane { normal: (0, 1, 0), offset: 0 }\n\
           sphere { center: (sin(time), 1, 0), radius: 1, material: material { \
           reflection: 0.5 } }\n";
        let pid =
          spawn ~dir:d
            [ "animate"; "a.rts"; "-o"; "out"; "-q"; "--domains"; "1"; "--shard"; "0/2" ]
        in
        wait_for (fun () -> Sys.file_exists (path d ("out/" ^ frame 4)));
        Unix.kill pid Sys.sigkill;
        ignore (Unix.waitpid [] pid);
        let kept =
          List.filter
            (fun k -> Sys.file_exists (path d ("out/" ^ frame k)))
            (List.init 16 Fun.id)
        in
        Alcotest.(check bool) "killed before the end" true (List.length kept < 8);
        let r =
          lancer ~dir:d
            [
              "animate";
              "a.rts";
              "-o";
              "out";
              "--shard";
              "0/2";
              "--resume";
              "--domains";
              "1";
            ]
        in
        check_status "resumed" 0 r;
        (* A kill between a frame's rename and its journal line leaves that one frame
           unrecorded: it is rendered again (same bytes). Every other frame is kept. *)
        let n = List.length kept in
        Alcotest.(check bool)
          "keeps what the killed run wrote" true
          (List.exists
             (fun k ->
               let _, out, err = r in
               contains (out ^ err)
                 (Printf.sprintf "resuming: %d frames already rendered" k))
             [ n; n - 1 ]);
        check_status "the other shard" 0
          (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "-q"; "--shard"; "1/2" ]);
        check_status "one animate" 0
          (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "ref"; "-q" ]);
        List.iter
          (fun f ->
            Alcotest.(check bool)
              f true
              (read_file (path d ("ref/" ^ f)) = read_file (path d ("out/" ^ f))))
          ("lancer-frames.json" :: List.init 16 frame));
    Alcotest.test_case
      "two animates of different scenes into one directory: one is refused, nothing is \
       mixed"
      `Quick (fun () ->
        let d = setup ~frames:8 () in
        write_file (path d "b.rts") (scene ~color:"(0.2, 0.2, 0.9)" ~frames:8 ());
        check_status "red alone" 0
          (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "red"; "-q" ]);
        check_status "blue alone" 0
          (lancer ~dir:d [ "animate"; "b.rts"; "-o"; "blue"; "-q" ]);
        let err = path d "err" in
        let both =
          List.map
            (fun s ->
              let fd =
                Unix.openfile err [ Unix.O_WRONLY; Unix.O_CREAT; Unix.O_APPEND ] 0o644
              in
              let cwd = Sys.getcwd () in
              Sys.chdir d;
              let pid =
                Unix.create_process exe
                  [| exe; "animate"; s; "-o"; "mixed"; "-q"; "--domains"; "1" |]
                  Unix.stdin Unix.stdout fd
              in
              Sys.chdir cwd;
              Unix.close fd;
              (s, pid))
            [ "a.rts"; "b.rts" ]
        in
        let statuses = List.map (fun (s, pid) -> (s, wait_status pid)) both in
        let winners = List.filter (fun (_, st) -> st = 0) statuses in
        Alcotest.(check int)
          ("one runs, one is refused\n" ^ read_file err)
          1 (List.length winners);
        Alcotest.(check bool)
          "the refusal says why" true
          (contains (read_file err) "holds the frames of another scene");
        let ref_dir = if fst (List.hd winners) = "a.rts" then "red" else "blue" in
        List.iter
          (fun f ->
            Alcotest.(check bool)
              f true
              (read_file (path d (ref_dir ^ "/" ^ f)) = read_file (path d ("mixed/" ^ f))))
          ("lancer-frames.json" :: List.init 8 frame);
        let loser = if ref_dir = "red" then "b.rts" else "a.rts" in
        let r = lancer ~dir:d [ "animate"; loser; "-o"; "mixed"; "--resume" ] in
        check_status "still refused afterwards" 1 r;
        (* Two scene files of the same name in two folders are two scenes; the same file
           reached from another working directory is the same scene. *)
        Unix.mkdir (path d "other") 0o755;
        write_file (path d "other/a.rts") (scene ~color:"(0.2, 0.9, 0.2)" ~frames:8 ());
        check_status "a.rts into same" 0
          (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "same"; "-q" ]);
        let r = lancer ~dir:d [ "animate"; "other/a.rts"; "-o"; "same"; "-q" ] in
        check_status "other/a.rts refused" 1 r;
        says "says why" r "holds the frames of another scene";
        let r =
          lancer ~dir:(path d "other")
            [ "animate"; "../a.rts"; "-o"; "../same"; "--resume" ]
        in
        check_status "../a.rts from another folder" 0 r;
        says "is the same scene" r "8 frames already rendered, 0 to go";
        (* Nor may another command's output replace the directory's records. *)
        let r =
          lancer ~dir:d
            [ "render"; "a.rts"; "-o"; "z.png"; "--stats"; "same/lancer-frames.json" ]
        in
        check_status "--stats onto the frames record" 1 r;
        says "says why" r "would replace a record";
        let r =
          lancer ~dir:d
            [
              "render";
              "a.rts";
              "-o";
              "z.png";
              "--stats";
              "same/lancer-frames.d/scene.json";
            ]
        in
        check_status "--stats onto the scene record" 1 r;
        Alcotest.(check bool)
          "the record kept" true
          (contains (read_file (path d "same/lancer-frames.d/scene.json")) "a.rts"));
  ]

(* The built-in showcase at 480×360 on one domain: long enough (about a second here) to
   be stopped midway, even when the test is slow to see its first checkpoint. *)
let still =
  [
    "render";
    "--width";
    "480";
    "--height";
    "360";
    "--domains";
    "1";
    "-q";
    "--resume";
    "-o";
  ]

let stopped_midway d out signal =
  let pid = spawn ~dir:d (still @ [ out ]) in
  wait_for (fun () -> Sys.file_exists (path d (out ^ ".checkpoint")));
  Unix.kill pid signal;
  let st = wait_status pid in
  Alcotest.(check bool)
    "stopped before the image was written" false
    (Sys.file_exists (path d out));
  Alcotest.(check bool)
    "the checkpoint is kept" true
    (Sys.file_exists (path d (out ^ ".checkpoint")));
  st

(* With an open shutter every frame is the scenes at its instants: the same bytes
   whoever renders it. *)
let blur_tests =
  [
    Alcotest.test_case
      "a motion-blurred animation: its frames are lancer render's, in shards and resumed \
       too"
      `Quick (fun () ->
        let d = setup ~camera:", shutter: (-0.5, 0.5), shutter_samples: 4" () in
        check_status "animate" 0 (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "ref"; "-q" ]);
        let ref = frames_of (path d "ref") 6 in
        List.iteri
          (fun k _ ->
            check_status "render" 0
              (lancer ~dir:d
                 [
                   "render"; "a.rts"; "--frame"; string_of_int k; "-o"; "still.png"; "-q";
                 ]);
            Alcotest.(check bool)
              (Printf.sprintf "frame %d as a still" k)
              true
              (pixels (path d ("ref/" ^ frame k)) = pixels (path d "still.png")))
          ref;
        check_status "frame 1" 0
          (lancer ~dir:d [ "render"; "a.rts"; "--frame"; "1"; "-o"; "still.png"; "-q" ]);
        write_file (path d "open.rts") (scene ());
        check_status "without the shutter" 0
          (lancer ~dir:d
             [ "render"; "open.rts"; "--frame"; "1"; "-o"; "sharp.png"; "-q" ]);
        Alcotest.(check bool)
          "blurred, not sharp" false
          (pixels (path d "sharp.png") = pixels (path d "still.png"));
        List.iter
          (fun k ->
            check_status "shard" 0
              (lancer ~dir:d
                 [
                   "animate";
                   "a.rts";
                   "-o";
                   "shards";
                   "-q";
                   "--shard";
                   Printf.sprintf "%d/2" k;
                 ]))
          [ 0; 1 ];
        Alcotest.(check bool) "two shards" true (ref = frames_of (path d "shards") 6);
        Sys.remove (path d ("shards/" ^ frame 4));
        let r = lancer ~dir:d [ "animate"; "a.rts"; "-o"; "shards"; "--resume" ] in
        says "resumed" r "5 frames already rendered, 1 to go";
        Alcotest.(check bool) "resumed" true (ref = frames_of (path d "shards") 6));
  ]

let still_tests =
  [
    Alcotest.test_case
      "a still killed or interrupted mid-render and resumed is the same bytes as one \
       uninterrupted"
      `Quick (fun () ->
        let d = tmpdir "lancer-resume" in
        check_status "uninterrupted" 0
          (lancer ~dir:d
             [ "render"; "--width"; "480"; "--height"; "360"; "-q"; "-o"; "ref.png" ]);
        let reference = read_file (path d "ref.png") in
        (* SIGKILL: what the last checkpoint held is kept. *)
        Alcotest.(check int) "killed" (-1) (stopped_midway d "a.png" Sys.sigkill);
        let r = lancer ~dir:d (List.filter (( <> ) "-q") still @ [ "a.png" ]) in
        check_status "resumed" 0 r;
        says "continues" r "tiles already rendered";
        Alcotest.(check bool) "same bytes" true (reference = read_file (path d "a.png"));
        Alcotest.(check bool)
          "the checkpoint is gone" false
          (Sys.file_exists (path d "a.png.checkpoint"));
        (* Ctrl-C: exit 130, and the checkpoint written on the way out. *)
        Alcotest.(check int) "interrupted" 130 (stopped_midway d "b.png" Sys.sigint);
        let ((_, out, _) as r) =
          lancer ~dir:d
            (List.filter (( <> ) "-q") still @ [ "b.png"; "--stats"; "b.json" ])
        in
        check_status "resumed" 0 r;
        says "continues" r "tiles already rendered";
        (* Rays per second count the rays this run cast, not the checkpoint's. *)
        says "this run's rays" r "of them in this run";
        let j = Yojson.Safe.from_file (path d "b.json") in
        let num k = Yojson.Safe.Util.(to_number (member k j)) in
        let total = Yojson.Safe.Util.(to_int (member "total" (member "rays" j))) in
        let resumed = Yojson.Safe.Util.(to_int (member "resumed_rays" j)) in
        Alcotest.(check bool)
          (Printf.sprintf "some rays were the checkpoint's: %d of %d" resumed total)
          true
          (resumed > 0 && resumed < total);
        let expected = Float.of_int (total - resumed) /. num "render_seconds" in
        Alcotest.(check (float (1e-9 *. expected)))
          ("rays per second of this run: " ^ out)
          expected (num "rays_per_second");
        Alcotest.(check bool) "same bytes" true (reference = read_file (path d "b.png"));
        (* A damaged checkpoint, or one of other options, is not used. *)
        ignore (stopped_midway d "c.png" Sys.sigkill);
        let ck = Bytes.of_string (read_file (path d "c.png.checkpoint")) in
        let i = Bytes.length ck / 2 in
        Bytes.set ck i (Char.chr ((Char.code (Bytes.get ck i) + 1) land 255));
        write_file (path d "c.png.checkpoint") (Bytes.to_string ck);
        let ((_, out, _) as r) =
          lancer ~dir:d (List.filter (( <> ) "-q") still @ [ "c.png" ])
        in
        check_status "damaged checkpoint" 0 r;
        Alcotest.(check bool)
          ("starts over: " ^ out) false
          (contains out "already rendered");
        Alcotest.(check bool) "same bytes" true (reference = read_file (path d "c.png"));
        ignore (stopped_midway d "e.png" Sys.sigkill);
        let ((_, out, _) as r) =
          lancer ~dir:d
            [
              "render";
              "--width";
              "200";
              "--height";
              "150";
              "--samples";
              "2";
              "--resume";
              "-o";
              "e.png";
            ]
        in
        check_status "other options" 0 r;
        Alcotest.(check bool)
          ("starts over: " ^ out) false
          (contains out "already rendered"));
  ]

(* A checkpoint of the layout lancer wrote before (version 2: its first line, the MD5 of
   the rest, a marshalled record), crafted so that its bytes unmarshal into a value of
   another shape: a pair of integers where a record of a string, numbers and arrays was
   read. *)
let crafted_checkpoint =
  let body = Marshal.to_string (0, 0) [] in
  "lancer-checkpoint-2\n" ^ Digest.string body ^ body

let crafted_tests =
  [
    Alcotest.test_case
      "a crafted checkpoint of the former marshalled layout is ignored: the render \
       neither crashes nor resumes, and makes the uninterrupted image"
      `Quick (fun () ->
        let d = setup () in
        check_status "uninterrupted" 0
          (lancer ~dir:d [ "render"; "a.rts"; "-o"; "ref.png"; "-q" ]);
        write_file (path d "a.png.checkpoint") crafted_checkpoint;
        let ((_, out, err) as r) =
          lancer ~dir:d [ "render"; "a.rts"; "-o"; "a.png"; "--resume" ]
        in
        check_status "rendered" 0 r;
        Alcotest.(check bool)
          ("starts over: " ^ out) false
          (contains out "already rendered");
        Alcotest.(check string) "nothing on stderr" "" err;
        Alcotest.(check bool)
          "the uninterrupted image" true
          (read_file (path d "ref.png") = read_file (path d "a.png")));
  ]

let () =
  Alcotest.run "resume"
    [
      ("animate", animate_tests);
      ("blur", blur_tests);
      ("render", still_tests);
      ("crafted", crafted_tests);
    ]
