(* The lancer command as a user runs it: exit codes, messages, files left behind,
   determinism across domain counts, interruption. *)

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"

open Run_lancer

let tmpdir () = tmpdir "lancer-cli"

(* Run lancer with [args] in [dir]; (status, stdout, stderr). *)
let lancer ?(dir = Sys.getcwd ()) args = run ~exe ~dir args

let small_scene =
  {|// A small scene with jitter and a soft shadow.
settings { width: 48, height: 36, samples: 2, jitter: true }
camera { position: (0, 2, -6), look_at: (0, 0.5, 0) }
light { position: (-3, 5, -4), radius: 0.5, samples: 3 }
plane { normal: (0, 1, 0), offset: 0, material: material { texture: checker((1,1,1), (0.2,0.2,0.2), 1) } }
sphere { center: (0, 1, 0), radius: 1, material: material { color: (0.9, 0.2, 0.2), specular: 0.5 } }
sphere { center: (1.5, 0.5, -1), radius: 0.5, material: material { transparency: 0.9, ior: 1.5 } }
|}

let no_backtrace msg e =
  Alcotest.(check bool)
    (msg ^ ": no backtrace\n" ^ e)
    false
    (contains e "Raised at" || contains e "Fatal error")

let anim_scene =
  {|settings { width: 24, height: 18 }
animation { fps: 10, frames: 4 }
camera { position: (0, 1, -5), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0 }
body ball { sphere { center: (0, 2, 0), radius: 0.4 } restitution: 0.8 }
|}

let mtime p = (Unix.stat p).Unix.st_mtime

(* Still parts (a plane, rows of spheres from a macro, a group, a CSG object, spheres
   after the moving ones) among moving ones (a sphere that follows [time], one that
   follows [frame] through a name defined from it, a body): an animation shares the still
   parts between its frames. [glass] makes a still sphere transparent. *)
let mixed_scene ~glass =
  Printf.sprintf
    {|settings { width: 40, height: 30, samples: 2 }
animation { fps: 10, frames: 5 }
camera { position: (0, 3, -8), look_at: (0, 0.5, 0) }
light { position: (-3, 6, -4) }
light { position: (3, 4, -6), radius: 0.3, samples: 2 }
plane { normal: (0, 1, 0), offset: 0, material: material { texture: checker((1,1,1), (0.2,0.2,0.2), 1) } }
let m = material { color: (0.3, 0.6, 0.9), specular: 0.4 }
fn row(z) { for i in 0 to 5 { sphere { center: (i - 2.5, 0.3, z), radius: 0.3, material: m } } }
row(0)
row(1)
group { translate: (0, 0, 2), box { min: (-1, 0, 0), max: (1, 1, 0.5) } sphere { center: (2, 0.5, 0), radius: 0.5 } }
merge { box { min: (-3, 0, -1), max: (-2, 1, 0) } box { min: (-2.8, 0, -0.8), max: (-2.2, 1.4, -0.2) } }
sphere { center: (-2 + time * 4, 1, -1), radius: 0.5, material: material { reflection: 0.5 } }
let lift = frame / 10
sphere { center: (2.5, 0.3 + lift, -1.5), radius: 0.3 }
body ball { sphere { center: (1, 2, -1), radius: 0.4 } restitution: 0.8 }
for i in 0 to 3 { sphere { center: (i - 1.5, 0.2, -2.5), radius: 0.2%s } }
|}
    (if glass then ", material: material { transparency: 0.8, ior: 1.3 }" else "")

let animate_tests =
  [
    Alcotest.test_case
      "every frame of an animation is the still of that frame, byte for byte, though the \
       frames share what does not move"
      `Quick (fun () ->
        let d = tmpdir () in
        List.iter
          (fun glass ->
            write_file (Filename.concat d "m.rts") (mixed_scene ~glass);
            check_status "animate" 0
              (lancer ~dir:d [ "animate"; "m.rts"; "-o"; "out"; "-q"; "--domains"; "1" ]);
            for k = 0 to 4 do
              let still = Printf.sprintf "still_%d.png" k in
              check_status still 0
                (lancer ~dir:d
                   [ "render"; "m.rts"; "--frame"; string_of_int k; "-o"; still; "-q" ]);
              Alcotest.(check bool)
                (Printf.sprintf "frame %d (glass: %b)" k glass)
                true
                (pixels (Filename.concat d (Printf.sprintf "out/frame_%04d.png" k))
                = pixels (Filename.concat d still))
            done;
            (* The frames differ: something moves. *)
            Alcotest.(check bool)
              "frames 1 and 4 differ" false
              (pixels (Filename.concat d "out/frame_0001.png")
              = pixels (Filename.concat d "out/frame_0004.png")))
          [ false; true ]);
    Alcotest.test_case
      "animate writes every frame and a manifest; --resume renders only what is missing \
       or stale"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "a.rts") anim_scene;
        let frames = List.init 4 (Printf.sprintf "frame_%04d.png") in
        check_status "animate" 0 (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "-q" ]);
        let path f = Filename.concat (Filename.concat d "out") f in
        List.iter
          (fun f -> Alcotest.(check bool) f true (Sys.file_exists (path f)))
          ("lancer-frames.json" :: frames);
        (* The ball falls: frames differ. *)
        Alcotest.(check bool)
          "the ball moves" false
          (pixels (path "frame_0000.png") = pixels (path "frame_0003.png"));
        let before = read_file (path "frame_0001.png") in
        Sys.remove (path "frame_0002.png");
        Unix.sleepf 0.05;
        let t3 = mtime (path "frame_0003.png") in
        let ((_, out, _) as r) =
          lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "--resume" ]
        in
        check_status "resume" 0 r;
        Alcotest.(check bool)
          ("says what it skips: " ^ out)
          true
          (contains out "3 frames already rendered, 1 to go");
        Alcotest.(check bool)
          ("and why it renders frame 2 again: " ^ out)
          true
          (contains out "rendering 1 frame again (2): their files are missing");
        Alcotest.(check bool)
          "frame 2 is back" true
          (Sys.file_exists (path "frame_0002.png"));
        Alcotest.(check (float 0.)) "frame 3 untouched" t3 (mtime (path "frame_0003.png"));
        Alcotest.(check bool)
          "same bytes" true
          (before = read_file (path "frame_0001.png"));
        (* A change in an included file makes every frame stale too. *)
        write_file (Filename.concat d "col.rts") "let c = (0.9, 0.1, 0.1)\n";
        write_file (Filename.concat d "b.rts")
          ("include \"col.rts\"\n" ^ anim_scene
         ^ "sphere { center: (1, 1, 0), radius: 0.3, material: material { color: c } }\n"
          );
        check_status "with include" 0
          (lancer ~dir:d [ "animate"; "b.rts"; "-o"; "outb"; "-q" ]);
        write_file (Filename.concat d "col.rts") "let c = (0.1, 0.9, 0.1)\n";
        let ((_, out, _) as r) =
          lancer ~dir:d [ "animate"; "b.rts"; "-o"; "outb"; "--resume" ]
        in
        check_status "include changed" 0 r;
        Alcotest.(check bool)
          ("stale after the include changed: " ^ out)
          true
          (contains out "wrote 4 frames");
        Alcotest.(check bool)
          ("says why: " ^ out) true
          (contains out
             "rendering 4 frames again (0..3): the scene (or a file it includes) has \
              changed");
        (* Another size makes every frame stale. *)
        let ((_, out, _) as r) =
          lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "--resume"; "--width"; "20" ]
        in
        check_status "stale" 0 r;
        Alcotest.(check bool)
          ("re-renders all: " ^ out) true
          (contains out "wrote 4 frames");
        Alcotest.(check bool)
          ("and says why: " ^ out) true
          (contains out
             "rendering 4 frames again (0..3): --width was not given, is now 20");
        (* One frame is one frame. *)
        let ((_, out, _) as r) =
          lancer ~dir:d [ "animate"; "a.rts"; "-o"; "one"; "--frames"; "1..1" ]
        in
        check_status "one frame" 0 r;
        Alcotest.(check bool) ("singular: " ^ out) true (contains out "wrote 1 frame to");
        let ((_, out, _) as r) =
          lancer ~dir:d
            [ "animate"; "a.rts"; "-o"; "one"; "--frames"; "1..2"; "--resume" ]
        in
        check_status "one frame resumed" 0 r;
        Alcotest.(check bool)
          ("singular: " ^ out) true
          (contains out "resuming: 1 frame already rendered, 1 to go"));
    Alcotest.test_case
      "animate writes the same frames on 1 domain (in tiles) and on 2 (whole frames in \
       parallel)"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "a.rts") anim_scene;
        check_status "1 domain" 0
          (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "one"; "-q"; "--domains"; "1" ]);
        check_status "2 domains" 0
          (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "two"; "-q"; "--domains"; "2" ]);
        List.iter
          (fun f ->
            Alcotest.(check bool)
              f true
              (read_file (Filename.concat d ("one/" ^ f))
              = read_file (Filename.concat d ("two/" ^ f))))
          [
            "frame_0000.png";
            "frame_0001.png";
            "frame_0002.png";
            "frame_0003.png";
            "lancer-frames.json";
          ]);
    Alcotest.test_case
      "animate --frames renders a range; bad ranges and stills are refused" `Quick
      (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "a.rts") anim_scene;
        write_file (Filename.concat d "s.rts") small_scene;
        check_status "range" 0
          (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "--frames"; "1..2"; "-q" ]);
        (* Not every frame is done: the record is the journal, no merged view yet. *)
        Alcotest.(check (list string))
          "frames 1 and 2"
          [ "frame_0001.png"; "frame_0002.png"; "lancer-frames.d" ]
          (List.sort compare (Array.to_list (Sys.readdir (Filename.concat d "out"))));
        let ((_, _, e) as r) =
          lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "--frames"; "2..9" ]
        in
        check_status "past the end" 1 r;
        Alcotest.(check bool) e true (contains e "the animation has frames 0..3");
        let ((_, _, e) as r) = lancer ~dir:d [ "animate"; "s.rts"; "-o"; "out2" ] in
        check_status "a still" 1 r;
        Alcotest.(check bool) e true (contains e "no animation block"));
    Alcotest.test_case "animate --video is checked before any frame is rendered" `Quick
      (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "a.rts") anim_scene;
        let ((_, _, e) as r) =
          lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "--video"; "no/a.gif" ]
        in
        check_status "missing directory" 1 r;
        Alcotest.(check bool) e true (contains e "directory no does not exist");
        let ((_, _, e) as r) =
          lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "--video"; "a.avi" ]
        in
        check_status "unknown format" 1 r;
        Alcotest.(check bool) e true (contains e ".mp4 or a .gif");
        (* Without ffmpeg on PATH (a PATH of an empty directory), before any frame. *)
        let empty = Filename.concat d "empty" in
        Unix.mkdir empty 0o755;
        let ((_, _, e) as r) =
          run
            ~prefix:(Printf.sprintf "PATH=%s" (Filename.quote empty))
            ~exe ~dir:d
            [ "animate"; "a.rts"; "-o"; "out"; "--video"; "a.gif" ]
        in
        check_status "no ffmpeg" 1 r;
        Alcotest.(check bool)
          e true
          (contains e "--video a.gif needs ffmpeg, which is not installed");
        Alcotest.(check bool)
          "nothing rendered" false
          (Sys.file_exists (Filename.concat d "out")));
    Alcotest.test_case
      "an interrupted animate keeps its finished frames and says how to resume" `Slow
      (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "a.rts")
          "settings { width: 400, height: 300, samples: 4 }\n\
           animation { fps: 10, frames: 400 }\n\
           camera { position: (0, 1, -5), look_at: (0, 1, 0) }\n\
           light { position: (-3, 5, -4) }\n\
           sphere { center: (0, 1, 0), radius: 1, material: material { reflection: 0.5 } }\n";
        let err = Filename.concat d "err" in
        let fd = Unix.openfile err [ Unix.O_WRONLY; Unix.O_CREAT ] 0o644 in
        let pid =
          Unix.create_process exe
            [|
              exe;
              "animate";
              Filename.concat d "a.rts";
              "-o";
              Filename.concat d "out";
              "-q";
            |]
            Unix.stdin Unix.stdout fd
        in
        let rec wait_frame n =
          if n > 0 && not (Sys.file_exists (Filename.concat d "out/frame_0001.png")) then (
            Unix.sleepf 0.05;
            wait_frame (n - 1))
        in
        wait_frame 400;
        Unix.kill pid Sys.sigint;
        let _, st = Unix.waitpid [] pid in
        Unix.close fd;
        Alcotest.(check bool) "exit 130" true (st = Unix.WEXITED 130);
        let e = read_file err in
        Alcotest.(check bool)
          e true
          (contains e "frames written so far are kept" && contains e "--resume");
        let kept =
          List.filter
            (fun f -> Filename.check_suffix f ".png")
            (Array.to_list (Sys.readdir (Filename.concat d "out")))
        in
        Alcotest.(check bool) "frames kept" true (kept <> []);
        let journals = Sys.readdir (Filename.concat d "out/lancer-frames.d") in
        let recorded =
          String.concat ""
            (Array.to_list
               (Array.map
                  (fun j -> read_file (Filename.concat d ("out/lancer-frames.d/" ^ j)))
                  journals))
        in
        List.iter
          (fun f -> Alcotest.(check bool) (f ^ " recorded") true (contains recorded f))
          kept;
        Alcotest.(check bool)
          "no temporary file" false
          (Array.exists
             (fun f -> contains f ".tmp")
             (Sys.readdir (Filename.concat d "out"))));
    Alcotest.test_case
      "animate --video: a GIF with ffmpeg; without it a clear message before any frame"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "a.rts") anim_scene;
        if Sys.command "command -v ffmpeg >/dev/null 2>&1" = 0 then (
          check_status "video" 0
            (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "-q"; "--video"; "a.gif" ]);
          let gif = read_file (Filename.concat d "a.gif") in
          Alcotest.(check string) "a GIF file" "GIF8" (String.sub gif 0 4);
          (* An odd height (18 + 1) still makes an MP4. *)
          check_status "mp4" 0
            (lancer ~dir:d
               [
                 "animate";
                 "a.rts";
                 "-o";
                 "out2";
                 "-q";
                 "--height";
                 "19";
                 "--video";
                 "a.mp4";
               ]);
          Alcotest.(check bool)
            "an MP4 file" true
            (contains (read_file (Filename.concat d "a.mp4")) "ftyp");
          Alcotest.(check bool)
            "no temporary left" false
            (Array.exists (fun f -> contains f ".tmp") (Sys.readdir d)))
        else
          let ((_, _, e) as r) =
            lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; "-q"; "--video"; "a.gif" ]
          in
          check_status "no ffmpeg" 1 r;
          Alcotest.(check bool) e true (contains e "needs ffmpeg, which is not installed");
          Alcotest.(check bool)
            "no frame rendered for nothing" false
            (Sys.file_exists (Filename.concat d "out/frame_0000.png"));
          Alcotest.(check bool)
            "no video" false
            (Sys.file_exists (Filename.concat d "a.gif")));
    Alcotest.test_case
      "frames written from two domains never lose the error message that follows them"
      `Quick (fun () ->
        (* Frames in parallel (2 domains, 8 frames) write PNGs at the same time; stderr must
           still carry the message about the failed ffmpeg, every time. The ffmpeg on PATH
           is a script that fails. *)
        let d = tmpdir () in
        let bin = Filename.concat d "bin" in
        Unix.mkdir bin 0o755;
        write_file (Filename.concat bin "ffmpeg") "#!/bin/sh\nexit 1\n";
        Unix.chmod (Filename.concat bin "ffmpeg") 0o755;
        write_file (Filename.concat d "a.rts")
          "settings { width: 16, height: 12 }\n\
           animation { fps: 10, frames: 8 }\n\
           camera { position: (0, 1, -5), look_at: (0, 1, 0) }\n\
           light { position: (-3, 5, -4) }\n\
           sphere { center: (0, 1, 0), radius: 1 }\n";
        for i = 1 to 6 do
          let ((_, _, e) as r) =
            run
              ~prefix:("PATH=" ^ Filename.quote bin)
              ~exe ~dir:d
              [
                "animate";
                "a.rts";
                "-o";
                Printf.sprintf "fr%d" i;
                "--domains";
                "2";
                "-q";
                "--video";
                "x.gif";
              ]
          in
          check_status (Printf.sprintf "run %d" i) 1 r;
          Alcotest.(check bool)
            (Printf.sprintf "run %d says why: %S" i e)
            true
            (contains e "ffmpeg failed to make x.gif")
        done);
  ]

(* A flat grid of [k]×[k] vertices as OBJ text, two triangles a cell, then [pad] bytes of
   comment lines (which change nothing of the mesh). *)
let grid_obj k pad =
  let b = Buffer.create (48 * k * k) in
  for i = 0 to k - 1 do
    for j = 0 to k - 1 do
      Printf.bprintf b "v %d 0 %d\n" i j
    done
  done;
  for i = 0 to k - 2 do
    for j = 0 to k - 2 do
      let a = (i * k) + j + 1 in
      Printf.bprintf b "f %d %d %d\nf %d %d %d\n" a (a + 1) (a + k) (a + 1)
        (a + k + 1)
        (a + k)
    done
  done;
  let line = String.make 79 '#' ^ "\n" in
  for _ = 1 to pad / 80 do
    Buffer.add_string b line
  done;
  Buffer.contents b

(* The largest heap of [lancer args] in [dir], in bytes (the runtime's statistics at exit). *)
let top_heap_bytes ~dir args =
  let ((_, _, err) as r) = run ~prefix:"OCAMLRUNPARAM=v=0x400" ~exe ~dir args in
  check_status "render" 0 r;
  match
    List.find_map
      (fun l -> Scanf.sscanf_opt l "top_heap_words: %d" Fun.id)
      (String.split_on_char '\n' err)
  with
  | Some w -> w * (Sys.word_size / 8)
  | None -> Alcotest.failf "no heap statistics in\n%s" err

let tests =
  [
    Alcotest.test_case
      "a large mesh file's text is let go before the mesh's hierarchy is built" `Slow
      (fun () ->
        (* The same mesh from a file 16 MiB longer (comments): its hierarchy needs more
           than its text, so the text held at the build would raise the peak by as
           much; let go, the peak is the build's, the same. *)
        let d = tmpdir () and pad = 16 * 1024 * 1024 in
        write_file (Filename.concat d "plain.obj") (grid_obj 560 0);
        write_file (Filename.concat d "padded.obj") (grid_obj 560 pad);
        let peak name =
          write_file (Filename.concat d "m.rts")
            (Printf.sprintf
               {|settings { width: 8, height: 8 }
camera { position: (280, 400, -200), look_at: (280, 0, 280) }
light { position: (0, 500, 0) }
mesh { file: "%s" }
|}
               name);
          top_heap_bytes ~dir:d
            [ "render"; "m.rts"; "-o"; "m.png"; "-q"; "--domains"; "1" ]
        in
        let plain = peak "plain.obj" and padded = peak "padded.obj" in
        List.iter
          (fun f -> Sys.remove (Filename.concat d f))
          [ "plain.obj"; "padded.obj" ];
        Alcotest.(check bool)
          (Printf.sprintf "the largest heap: %d MiB, %d MiB with the padded file"
             (plain lsr 20) (padded lsr 20))
          true
          (padded - plain < pad / 2));
    Alcotest.test_case "render with no scene writes the built-in showcase" `Slow
      (fun () ->
        let d = tmpdir () in
        check_status "exit" 0
          (lancer ~dir:d [ "render"; "--width"; "64"; "--height"; "48" ]);
        Alcotest.(check bool)
          "showcase.png" true
          (Sys.file_exists (Filename.concat d "showcase.png")));
    Alcotest.test_case "a missing scene file is one line, exit 1, and no output" `Quick
      (fun () ->
        let d = tmpdir () in
        let ((_, _, e) as r) = lancer ~dir:d [ "render"; "nope.rts"; "-o"; "x.png" ] in
        check_status "exit" 1 r;
        Alcotest.(check string) "message" "lancer: nope.rts: no such file\n" e;
        Alcotest.(check (array string)) "nothing written" [||] (Sys.readdir d));
    Alcotest.test_case "an output in a missing directory fails before rendering" `Quick
      (fun () ->
        let d = tmpdir () in
        let ((_, _, e) as r) = lancer ~dir:d [ "render"; "-o"; "no/such/dir/x.png" ] in
        check_status "exit" 1 r;
        no_backtrace "missing dir" e;
        Alcotest.(check bool) "mentions the directory" true (contains e "does not exist"));
    Alcotest.test_case "an output path that is a directory is refused" `Quick (fun () ->
        let d = tmpdir () in
        Unix.mkdir (Filename.concat d "out.png") 0o755;
        check_status "exit" 1 (lancer ~dir:d [ "render"; "-o"; "out.png" ]));
    Alcotest.test_case "an unsupported output format is refused" `Quick (fun () ->
        let d = tmpdir () in
        let ((_, _, e) as r) = lancer ~dir:d [ "render"; "-o"; "out.jpg" ] in
        check_status "exit" 1 r;
        Alcotest.(check bool)
          "says which formats" true
          (contains e ".png, .ppm, .exr, .hdr or .pfm"));
    Alcotest.test_case "a bad scene prints file:line:col and exits 1" `Quick (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "bad.rts")
          "sphere { center: (0,0,0), radius: -1 }\n";
        let ((_, _, e) as r) = lancer ~dir:d [ "render"; "bad.rts" ] in
        check_status "exit" 1 r;
        no_backtrace "bad scene" e;
        Alcotest.(check bool) ("located: " ^ e) true (contains e "bad.rts:1:");
        Alcotest.(check bool)
          "no image" false
          (Sys.file_exists (Filename.concat d "bad.png")));
    Alcotest.test_case
      "1, 2, 3 and 4 domains write identical bytes (jitter, soft shadows)" `Slow
      (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts") small_scene;
        let files =
          List.map
            (fun n ->
              let o = Printf.sprintf "d%d.png" n in
              check_status "exit" 0
                (lancer ~dir:d
                   [ "render"; "s.rts"; "-o"; o; "--domains"; string_of_int n; "-q" ]);
              read_file (Filename.concat d o))
            [ 1; 2; 3; 4 ]
        in
        List.iteri
          (fun i f ->
            Alcotest.(check bool)
              (Printf.sprintf "%d domains" (i + 1))
              true
              (f = List.hd files))
          files);
    Alcotest.test_case "--stats writes JSON with ray counts and features" `Quick
      (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts") small_scene;
        check_status "exit" 0
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.ppm"; "--stats"; "st.json"; "-q" ]);
        let j = Yojson.Safe.from_file (Filename.concat d "st.json") in
        let open Yojson.Safe.Util in
        Alcotest.(check int)
          "primary rays"
          (48 * 36 * 4)
          (j |> member "rays" |> member "primary" |> to_int);
        Alcotest.(check bool)
          "soft shadows used" true
          (j |> member "features" |> member "soft_shadows" |> to_bool);
        Alcotest.(check bool)
          "reflection skipped" false
          (j |> member "features" |> member "reflection" |> to_bool));
    Alcotest.test_case "options override the scene's settings" `Quick (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts") small_scene;
        check_status "exit" 0
          (lancer ~dir:d
             [ "render"; "s.rts"; "-o"; "s.ppm"; "--width"; "20"; "--height"; "10"; "-q" ]);
        match Lancer.Image.read_rgb8 (Filename.concat d "s.ppm") with
        | Ok (w, h, _) -> Alcotest.(check (pair int int)) "size" (20, 10) (w, h)
        | Error m -> Alcotest.fail m);
    Alcotest.test_case "Ctrl-C during a render leaves no output file" `Slow (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts") small_scene;
        let pid =
          Unix.create_process exe
            [|
              exe;
              "render";
              Filename.concat d "s.rts";
              "-o";
              Filename.concat d "big.png";
              "--width";
              "4000";
              "--height";
              "3000";
              "--samples";
              "3";
              "-q";
            |]
            Unix.stdin Unix.stdout Unix.stderr
        in
        Unix.sleepf 1.0;
        Unix.kill pid Sys.sigint;
        (* The render stops within a tile per domain, not after the whole image. *)
        let rec wait n =
          match Unix.waitpid [ Unix.WNOHANG ] pid with
          | 0, _ when n > 0 ->
              Unix.sleepf 0.1;
              wait (n - 1)
          | 0, _ ->
              Unix.kill pid Sys.sigkill;
              ignore (Unix.waitpid [] pid);
              Alcotest.fail "still rendering 20 s after Ctrl-C"
          | _, st -> st
        in
        let st = wait 200 in
        Alcotest.(check bool) "interrupted" true (st = Unix.WEXITED 130);
        Alcotest.(check (list string))
          "no file, no temporary" [ "s.rts" ]
          (Array.to_list (Sys.readdir d)));
    Alcotest.test_case "check --json lists every object with its fields" `Quick (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts") small_scene;
        let ((_, out, _) as r) = lancer ~dir:d [ "check"; "s.rts"; "--json" ] in
        check_status "exit" 0 r;
        let j = Yojson.Safe.from_string out in
        let open Yojson.Safe.Util in
        Alcotest.(check int)
          "3 objects" 3
          (List.length (j |> member "objects" |> to_list)));
    Alcotest.test_case
      "diff exits 0 on identical images and 1 with a diff image otherwise" `Quick
      (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts") small_scene;
        check_status "a" 0 (lancer ~dir:d [ "render"; "s.rts"; "-o"; "a.png"; "-q" ]);
        check_status "b" 0
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "b.png"; "-q"; "--samples"; "1" ]);
        check_status "same" 0 (lancer ~dir:d [ "diff"; "a.png"; "a.png" ]);
        check_status "different" 1
          (lancer ~dir:d [ "diff"; "a.png"; "b.png"; "-o"; "d.png" ]);
        Alcotest.(check bool)
          "diff image" true
          (Sys.file_exists (Filename.concat d "d.png")));
    Alcotest.test_case
      "golden: missing, --update, same, and different with actual and diff images" `Quick
      (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts") small_scene;
        write_file (Filename.concat d "t.rts")
          (small_scene ^ "sphere { center: (-1.5, 0.5, -1), radius: 0.5 }\n");
        let ((_, _, e) as r) = lancer ~dir:d [ "golden"; "s.rts"; "g.png" ] in
        check_status "no golden yet" 1 r;
        Alcotest.(check bool) e true (contains e "--update");
        check_status "update" 0 (lancer ~dir:d [ "golden"; "s.rts"; "g.png"; "--update" ]);
        Alcotest.(check bool)
          "the update removed the earlier render" false
          (Sys.file_exists (Filename.concat d "g.actual.png"));
        check_status "same" 0 (lancer ~dir:d [ "golden"; "s.rts"; "g.png" ]);
        let ((_, out, _) as r) = lancer ~dir:d [ "golden"; "t.rts"; "g.png" ] in
        check_status "different" 1 r;
        Alcotest.(check bool)
          out true
          (contains out "differs from g.png" && contains out "g.diff.png");
        Alcotest.(check bool)
          "actual and diff written" true
          (Sys.file_exists (Filename.concat d "g.actual.png")
          && Sys.file_exists (Filename.concat d "g.diff.png"));
        check_status "same again" 0 (lancer ~dir:d [ "golden"; "s.rts"; "g.png" ]);
        Alcotest.(check bool)
          "a pass removes them" false
          (Sys.file_exists (Filename.concat d "g.actual.png")
          || Sys.file_exists (Filename.concat d "g.diff.png")));
    Alcotest.test_case "a physics simulation that gives up is a warning, not silence"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "z.rts")
          "animation { fps: 1, frames: 200 }\n\
           physics { gravity: (0, 0, 0) }\n\
           plane { normal: (0, 1, 0), offset: 0 }\n\
           plane { normal: (0, 1, 0), offset: 1.01 }\n\
           body b { sphere { center: (0, 0.505, 0), radius: 0.5 } velocity: (0, 10, 0), \
           restitution: 1 }\n";
        let ((_, _, e) as r) = lancer ~dir:d [ "check"; "z.rts" ] in
        check_status "check" 0 r;
        Alcotest.(check bool)
          e true
          (contains e
             "warning: the physics simulation stopped handling collisions after 100000 \
              events"));
    Alcotest.test_case "--stats in a missing directory is refused before rendering" `Quick
      (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts") small_scene;
        let ((_, _, e) as r) =
          lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.png"; "--stats"; "no/s.json" ]
        in
        check_status "refused" 1 r;
        Alcotest.(check bool) e true (contains e "directory no does not exist");
        Alcotest.(check (list string))
          "no image" [ "s.rts" ]
          (Array.to_list (Sys.readdir d)));
    Alcotest.test_case "a mistyped option is a user error: exit 1" `Quick (fun () ->
        let ((st, _, e) as r) = lancer [ "render"; "--width"; "abc" ] in
        ignore st;
        check_status "exit" 1 r;
        Alcotest.(check bool) e true (contains e "expected an integer"));
    Alcotest.test_case
      "progress: a line with rays per second on a terminal, nothing otherwise" `Quick
      (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts") small_scene;
        let render =
          [ "render"; "s.rts"; "-o"; "a.png"; "--width"; "200"; "--height"; "150" ]
        in
        let ((_, _, e) as r) = lancer ~dir:d render in
        check_status "render" 0 r;
        Alcotest.(check string) "stderr is not a terminal, a short render: silent" "" e;
        (* Not on a terminal, a line every few seconds: every unit at an interval of 0. *)
        let ((_, _, e) as r) =
          run ~prefix:"LANCER_PROGRESS_INTERVAL=0" ~exe ~dir:d
            (render @ [ "--domains"; "1" ])
        in
        check_status "render, lines" 0 r;
        Alcotest.(check bool)
          ("a line per tile, with the time left\n" ^ e)
          true
          (contains e "tiles 1/35 (  3%)"
          && contains e "tiles 35/35 (100%)"
          && contains e "left "
          && not (contains e "\r"));
        write_file (Filename.concat d "a.rts") anim_scene;
        let ((_, _, e) as r) =
          run ~prefix:"LANCER_PROGRESS_INTERVAL=0" ~exe ~dir:d
            [ "animate"; "a.rts"; "-o"; "frames"; "--domains"; "1" ]
        in
        check_status "animate, lines" 0 r;
        Alcotest.(check bool)
          ("a line per frame\n" ^ e) true
          (contains e "frames 1/4 ( 25%)" && contains e "frames 4/4 (100%)");
        let ((_, _, e) as r) = lancer ~dir:d (render @ [ "--progress" ]) in
        check_status "render --progress" 0 r;
        Alcotest.(check bool)
          ("--progress: lines for a log\n" ^ e)
          true
          (contains e "tiles 35/35 (100%)"
          && contains e "M rays/s"
          && not (contains e "\r"));
        if Sys.command "command -v script >/dev/null 2>&1" = 0 then (
          let out = Filename.concat d "tty.out" in
          let cmd =
            Printf.sprintf "cd %s && script -qec %s /dev/null > %s 2>&1"
              (Filename.quote d)
              (Filename.quote
                 (Printf.sprintf "%s render s.rts -o b.png --width 200 --height 150"
                    (Filename.quote exe)))
              (Filename.quote out)
          in
          Alcotest.(check int) "render on a terminal" 0 (Sys.command cmd);
          let text = read_file out in
          Alcotest.(check bool)
            text true
            (contains text "tiles " && contains text "M rays/s" && contains text "left ")));
    Alcotest.test_case "--version and --help work" `Quick (fun () ->
        let ((_, out, _) as r) = lancer [ "--version" ] in
        check_status "version" 0 r;
        Alcotest.(check string)
          "the version of dune-project" (Lancer.Version.v ^ "\n") out;
        let ((_, out, _) as r) = lancer [ "render"; "--help=plain" ] in
        check_status "help" 0 r;
        Alcotest.(check bool) "examples" true (contains out "EXAMPLES"));
  ]

let () = Alcotest.run "cli" [ ("lancer", tests); ("animate", animate_tests) ]
