(* The files the lancer command writes, as other programs read them. *)
open Run_lancer

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"
let lancer ?prefix ~dir args = run ?prefix ~exe ~dir args
let tmpdir () = tmpdir "lancer-output"
let ( // ) = Filename.concat

(* The body of a binary PPM lancer wrote (its header is "P6\nW H\nMAX\n"). *)
let ppm_body s =
  let rec nth_newline i k =
    if k = 0 then i else nth_newline (String.index_from s i '\n' + 1) (k - 1)
  in
  let start = nth_newline 0 3 in
  String.sub s start (String.length s - start)

(* What the independent decoder makes of a PNG: (header line, samples). *)
let independent png =
  let out = Filename.temp_file "png" ".raw" in
  let st =
    Sys.command
      (Printf.sprintf "perl png_check.pl %s > %s 2>&1" (Filename.quote png)
         (Filename.quote out))
  in
  let s = read_file out in
  Sys.remove out;
  if st <> 0 then Alcotest.failf "the independent decoder refused %s: %s" png s;
  let nl = String.index s '\n' in
  (String.sub s 0 nl, String.sub s (nl + 1) (String.length s - nl - 1))

let scene =
  {|settings { width: 40, height: 30, samples: 2 }
camera { position: (0, 2, -6), look_at: (0, 0.5, 0) }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0, material: material { texture: checker((1,1,1), (0.2,0.2,0.2), 1) } }
sphere { center: (0, 1, 0), radius: 1, material: material { color: (0.9, 0.2, 0.2), specular: 0.5 } }
|}

(* A gray PNG of w×h samples [v i j] at 8 or 16 bits, through lancer's own writer. *)
let gray_png path depth w h v =
  let b = Bytes.create (w * h * (depth / 8)) in
  for j = 0 to h - 1 do
    for i = 0 to w - 1 do
      let k = (j * w) + i in
      if depth = 8 then Bytes.set_uint8 b k (v i j)
      else Bytes.set_uint16_be b (2 * k) (v i j)
    done
  done;
  Out_channel.with_open_bin path (fun oc ->
      Lancer.Png.encode
        (Lancer.Raster.make ~width:w ~height:h ~channels:1 ~depth b)
        (output_string oc))

let png_tests =
  [
    Alcotest.test_case
      "a rendered PNG is plain, and an independent decoder reads the same pixels as the \
       PPM"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file (d // "s.rts") scene;
        check_status "png" 0 (lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.png"; "-q" ]);
        check_status "ppm" 0 (lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.ppm"; "-q" ]);
        let s = read_file (d // "s.png") in
        Alcotest.(check int) "interlace method 0 (plain)" 0 (Char.code s.[28]);
        let head, samples = independent (d // "s.png") in
        Alcotest.(check string) "40×30 RGB, 8 bits" "40 30 3 8" head;
        Alcotest.(check bool)
          "the same pixels as the PPM" true
          (samples = ppm_body (read_file (d // "s.ppm"))));
    Alcotest.test_case
      "the showcase written plainly is smaller than the interlaced file of the former \
       writer"
      `Quick (fun () ->
        let old = "../../scenes/gallery/showcase.png" in
        match Lancer.Image.read_rgb8 old with
        | Error m -> Alcotest.fail m
        | Ok (w, h, b) -> (
            let d = tmpdir () in
            (match Lancer.Image.write_rgb8 (d // "new.png") w h b with
            | Ok () -> ()
            | Error m -> Alcotest.fail m);
            let before = (Unix.stat old).st_size
            and after = (Unix.stat (d // "new.png")).st_size in
            Alcotest.(check bool)
              (Printf.sprintf "%d bytes, was %d: at least 20%% smaller" after before)
              true
              (after * 10 < before * 8);
            match Lancer.Image.read_rgb8 (d // "new.png") with
            | Ok (_, _, b') -> Alcotest.(check bool) "same pixels" true (Bytes.equal b b')
            | Error m -> Alcotest.fail m));
    Alcotest.test_case "8- and 16-bit gray height maps work as textures and as bump maps"
      `Quick (fun () ->
        let d = tmpdir () in
        gray_png (d // "flat8.png") 8 4 4 (fun _ _ -> 128);
        gray_png (d // "flat16.png") 16 4 4 (fun _ _ -> 40000);
        gray_png (d // "bumps8.png") 8 16 16 (fun i j ->
            if (i / 4) + (j / 4 land 1) = 0 then 255 else 0);
        gray_png (d // "bumps16.png") 16 16 16 (fun i j -> (i * 4000) + (j * 97));
        (* Only the ambient term, at full strength: the pixel is the texture's colour. *)
        let textured file =
          Printf.sprintf
            "settings { width: 8, height: 8, ambient: (1, 1, 1) }\n\
             camera { position: (0, 0, -3), look_at: (0, 0, 0) }\n\
             parallelogram { origin: (-3, -3, 0), edge1: (6, 0, 0), edge2: (0, 6, 0),\n\
             material: material { ambient: 1, diffuse: 0, texture: image(\"%s\", 1) } }\n"
            file
        in
        List.iter
          (fun (file, expect) ->
            write_file (d // "t.rts") (textured file);
            check_status file 0 (lancer ~dir:d [ "render"; "t.rts"; "-o"; "t.ppm"; "-q" ]);
            let px = ppm_body (read_file (d // "t.ppm")) in
            let v = Char.code px.[3 * ((4 * 8) + 4)] in
            Alcotest.(check bool)
              (Printf.sprintf "%s: centre pixel %d, expected %d" file v expect)
              true
              (abs (v - expect) <= 1);
            Alcotest.(check bool)
              "gray" true
              (px.[3 * 36] = px.[(3 * 36) + 1] && px.[(3 * 36) + 1] = px.[(3 * 36) + 2]))
          [ ("flat8.png", 128); ("flat16.png", 40000 * 255 / 65535) ];
        let bumped b =
          Printf.sprintf
            "settings { width: 24, height: 24 }\n\
             camera { position: (0, 0, -3), look_at: (0, 0, 0) }\n\
             light { position: (-2, 3, -4) }\n\
             parallelogram { origin: (-2, -2, 0), edge1: (4, 0, 0), edge2: (0, 4, 0), \
             material: material { specular: 0.5%s } }\n"
            b
        in
        write_file (d // "flat.rts") (bumped "");
        check_status "flat" 0
          (lancer ~dir:d [ "render"; "flat.rts"; "-o"; "flat.ppm"; "-q" ]);
        List.iter
          (fun file ->
            write_file (d // "b.rts")
              (bumped (Printf.sprintf ", bump: image(\"%s\", 2)" file));
            check_status file 0 (lancer ~dir:d [ "render"; "b.rts"; "-o"; "b.ppm"; "-q" ]);
            Alcotest.(check bool)
              (file ^ " changes the shading")
              false
              (read_file (d // "b.ppm") = read_file (d // "flat.ppm")))
          [ "bumps8.png"; "bumps16.png" ]);
    Alcotest.test_case "a corrupt texture is refused at the image(…) that names it" `Quick
      (fun () ->
        let d = tmpdir () in
        gray_png (d // "g.png") 8 4 4 (fun i _ -> i * 60);
        let s = read_file (d // "g.png") in
        write_file (d // "cut.png") (String.sub s 0 (String.length s - 30));
        write_file (d // "t.rts")
          "settings { width: 8, height: 8 }\n\
           sphere { center: (0, 0, 0), radius: 1, material: material { texture: \
           image(\"cut.png\", 1) } }\n";
        let ((_, _, e) as r) = lancer ~dir:d [ "render"; "t.rts"; "-o"; "t.png" ] in
        check_status "refused" 1 r;
        Alcotest.(check bool)
          e true
          (contains e "t.rts:2:" && contains e "cut.png" && contains e "truncated");
        Alcotest.(check bool)
          "no backtrace" false
          (contains e "Raised at" || contains e "internal error"));
  ]

(* ---- writes under a file-size limit ---- *)

(* lancer in [dir] under bash's ulimit -f of [kib] 1024-byte units: (status, stdout,
   stderr). Its output goes to pipes, which the limit does not apply to. *)
let limited ~dir kib args =
  let script =
    Printf.sprintf "cd %s && ulimit -f %d && exec \"$0\" \"$@\"" (Filename.quote dir) kib
  in
  let ic, oc, ec =
    Unix.open_process_args_full "/bin/bash"
      (Array.of_list ("bash" :: "-c" :: script :: exe :: args))
      (Unix.environment ())
  in
  close_out oc;
  let out = In_channel.input_all ic and err = In_channel.input_all ec in
  match Unix.close_process_full (ic, oc, ec) with
  | Unix.WEXITED n -> (n, out, err)
  | _ -> (-1, out, err)

let size p = (Unix.stat p).Unix.st_size

let limit_tests =
  [
    Alcotest.test_case
      "under a file-size limit at every 4096-byte page of the file, the write fails \
       whole and the previous file stays"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file (d // "s.rts") scene;
        let args o =
          [
            "render";
            "s.rts";
            "-o";
            o;
            "--width";
            "200";
            "--height";
            "150";
            "-q";
            "--stats";
            "st.json";
            "--domains";
            "1";
          ]
        in
        check_status "unlimited" 0 (lancer ~dir:d (args "full.png"));
        check_status "unlimited ppm" 0 (lancer ~dir:d (args "full.ppm"));
        List.iter
          (fun out ->
            let len = size (d // ("full" ^ Filename.extension out)) in
            Alcotest.(check bool) "more than one page" true (len > 4096);
            let pages = (len + 4095) / 4096 in
            for k = 0 to pages - 1 do
              write_file (d // out) "the previous image";
              let ((_, _, e) as r) = limited ~dir:d (4 * k) (args out) in
              check_status
                (Printf.sprintf "%s, limit %d bytes (file %d)" out (4096 * k) len)
                1 r;
              Alcotest.(check bool)
                ("says why: " ^ e) true
                (contains e ("cannot write " ^ out) && contains e "File too large");
              Alcotest.(check string)
                "previous file untouched" "the previous image"
                (read_file (d // out));
              Alcotest.(check bool)
                "no temporary file" false
                (Array.exists (fun f -> contains f ".tmp-") (Sys.readdir d))
            done;
            (* At the first page count that holds the whole file, it is written. *)
            check_status "limit large enough" 0 (limited ~dir:d (4 * pages) (args out));
            Alcotest.(check bool)
              "the image" true
              (read_file (d // out) = read_file (d // ("full" ^ Filename.extension out))))
          [ "out.png"; "out.ppm" ]);
    Alcotest.test_case
      "stats JSON and the frames manifest under a file-size limit fail whole" `Quick
      (fun () ->
        let d = tmpdir () in
        write_file (d // "s.rts") scene;
        (* The stats of a scene with a long path are larger than 1 KiB, its 8×8 image is not:
           under a 1 KiB limit the image is written and the stats fail. *)
        let long = String.make 200 'd' in
        let sub = Filename.concat long (Filename.concat long long) in
        ignore (Sys.command (Printf.sprintf "mkdir -p %s" (Filename.quote (d // sub))));
        write_file (d // sub // "s.rts") scene;
        write_file (d // "st.json") "previous stats";
        let ((_, _, e) as r) =
          limited ~dir:d 1
            [
              "render";
              sub // "s.rts";
              "-o";
              "o.ppm";
              "--width";
              "8";
              "--height";
              "8";
              "-q";
              "--stats";
              "st.json";
            ]
        in
        check_status "refused" 1 r;
        Alcotest.(check bool) e true (contains e "cannot write st.json: File too large");
        Alcotest.(check bool)
          "the image was written" true
          (Sys.file_exists (d // "o.ppm"));
        Alcotest.(check string)
          "stats untouched" "previous stats"
          (read_file (d // "st.json"));
        (* Thirty 1×1 frames of about 70 bytes each; the frames record, a line per frame,
           outgrows 1 KiB before the last one: the run fails and says so, and every frame
           under its final name is whole. *)
        write_file (d // "a.rts")
          "settings { width: 1, height: 1 }\n\
           animation { fps: 10, frames: 30 }\n\
           camera { position: (0, 1, -5), look_at: (0, 1, 0) }\n\
           light { position: (-3, 5, -4) }\n\
           sphere { center: (0, 1, 0), radius: 1 }\n";
        let ((_, _, e) as r) =
          limited ~dir:d 1 [ "animate"; "a.rts"; "-o"; "fr"; "-q"; "--domains"; "1" ]
        in
        check_status "animate refused" 1 r;
        Alcotest.(check bool) e true (contains e "File too large");
        let frames =
          List.filter
            (fun f -> Filename.check_suffix f ".png")
            (Array.to_list (Sys.readdir (d // "fr")))
        in
        Alcotest.(check bool) "some frames were written" true (List.length frames > 3);
        List.iter
          (fun f ->
            match Lancer.Image.read_raster (d // "fr" // f) with
            | Ok r ->
                Alcotest.(check (pair int int))
                  (f ^ " is whole") (1, 1) (r.width, r.height)
            | Error m -> Alcotest.failf "%s: %s" f m)
          frames;
        Alcotest.(check bool)
          "no temporary file" false
          (Array.exists (fun f -> contains f ".tmp-") (Sys.readdir (d // "fr"))));
  ]

(* ---- files a run must not write over ---- *)

let brick =
  "settings { width: 8, height: 8 }\n\
   sphere { center: (0, 0, 0), radius: 1, material: material { texture: \
   image(\"brick.png\", 1) } }\n"

let refused ?(status = 1) msg r expect =
  let _, _, e = r in
  check_status msg status r;
  Alcotest.(check bool)
    (Printf.sprintf "%s: the message %S says %S" msg e expect)
    true (contains e expect);
  Alcotest.(check bool)
    "one line, no backtrace" true
    (List.length (String.split_on_char '\n' (String.trim e)) = 1)

let listing d = List.sort compare (Array.to_list (Sys.readdir d))

let refusal_tests =
  [
    Alcotest.test_case
      "render --stats scene.rts (the value forgotten) is refused; the scene stays" `Quick
      (fun () ->
        let d = tmpdir () in
        write_file (d // "scene.rts") scene;
        refused "--stats scene.rts"
          (lancer ~dir:d [ "render"; "--stats"; "scene.rts" ])
          "did --stats take the scene as its value?";
        Alcotest.(check string) "scene untouched" scene (read_file (d // "scene.rts"));
        Alcotest.(check (list string)) "nothing written" [ "scene.rts" ] (listing d));
    Alcotest.test_case
      "a scene whose default output is its own texture is refused; the texture stays"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file (d // "brick.rts") brick;
        gray_png (d // "brick.png") 8 4 4 (fun i j -> (i * 50) + j);
        let before = read_file (d // "brick.png") in
        refused "brick.rts"
          (lancer ~dir:d [ "render"; "brick.rts" ])
          "refusing to write the image to brick.png: that file is an image the scene uses";
        Alcotest.(check bool)
          "texture untouched" true
          (before = read_file (d // "brick.png"));
        (* By another name: ./brick.png, and a symbolic link to it. *)
        Unix.symlink "brick.png" (d // "link.png");
        refused "./brick.png"
          (lancer ~dir:d [ "render"; "brick.rts"; "-o"; "./brick.png" ])
          "refusing to write the image";
        refused "a link to it"
          (lancer ~dir:d [ "render"; "brick.rts"; "-o"; "link.png" ])
          "that file is brick.png (an image the scene uses)";
        Alcotest.(check bool)
          "texture untouched" true
          (before = read_file (d // "brick.png"));
        Alcotest.(check (list string))
          "nothing written"
          [ "brick.png"; "brick.rts"; "link.png" ]
          (listing d);
        (* A frame of an animation that would replace the texture it reads. *)
        Unix.mkdir (d // "fr") 0o755;
        gray_png (d // "fr" // "frame_0001.png") 8 4 4 (fun i _ -> i * 60);
        write_file (d // "a.rts")
          "settings { width: 8, height: 8 }\n\
           animation { fps: 10, frames: 3 }\n\
           sphere { center: (0, 0, 0), radius: 1, material: material { texture: \
           image(\"fr/frame_0001.png\", 1) } }\n";
        refused "animate"
          (lancer ~dir:d [ "animate"; "a.rts"; "-o"; "fr" ])
          "refusing to write a frame to fr/frame_0001.png";
        Alcotest.(check (list string))
          "no frame written" [ "frame_0001.png" ]
          (listing (d // "fr")));
    Alcotest.test_case
      "golden --update over the scene's own texture, and a diff image over the golden, \
       are refused"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file (d // "brick.rts") brick;
        gray_png (d // "brick.png") 8 4 4 (fun i j -> (i * 50) + j);
        let before = read_file (d // "brick.png") in
        refused "golden --update"
          (lancer ~dir:d [ "golden"; "brick.rts"; "brick.png"; "--update" ])
          "refusing to write the golden image to brick.png: that file is an image the \
           scene uses";
        Alcotest.(check bool)
          "texture untouched" true
          (before = read_file (d // "brick.png"));
        (* The golden g.png is read; a texture named g.actual.png would be replaced. *)
        gray_png (d // "g.actual.png") 8 4 4 (fun i _ -> i);
        write_file (d // "g.rts")
          "settings { width: 8, height: 8 }\n\
           sphere { center: (0, 0, 0), radius: 1, material: material { texture: \
           image(\"g.actual.png\", 1) } }\n";
        gray_png (d // "g.png") 8 8 8 (fun _ _ -> 0);
        refused "golden"
          (lancer ~dir:d [ "golden"; "g.rts"; "g.png" ])
          "refusing to write the actual image to g.actual.png");
    Alcotest.test_case "diff a.png b.png -o a.png is refused; its input stays" `Quick
      (fun () ->
        let d = tmpdir () in
        gray_png (d // "a.png") 8 4 4 (fun i _ -> i);
        gray_png (d // "b.png") 8 4 4 (fun _ j -> j);
        let before = read_file (d // "a.png") in
        refused "diff"
          (lancer ~dir:d [ "diff"; "a.png"; "b.png"; "-o"; "a.png" ])
          "refusing to write the diff image to a.png: that file is an image this diff \
           compares";
        Alcotest.(check bool) "input untouched" true (before = read_file (d // "a.png"));
        refused "diff, b"
          (lancer ~dir:d [ "diff"; "a.png"; "b.png"; "-o"; "b.png" ])
          "refusing to write the diff image to b.png");
    Alcotest.test_case "--stats and -o naming one file are refused" `Quick (fun () ->
        let d = tmpdir () in
        write_file (d // "s.rts") scene;
        refused "same name"
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "o.png"; "--stats"; "o.png" ])
          "did --stats take the scene as its value?";
        refused "another name of it"
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "o.ppm"; "--stats"; "./o.ppm" ])
          "did --stats take";
        Alcotest.(check (list string)) "nothing written" [ "s.rts" ] (listing d);
        write_file (d // "o.png") "an image";
        Unix.symlink "o.png" (d // "o.json");
        refused "through a link"
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "o.png"; "--stats"; "o.json" ])
          "the image and the statistics would be the same file, o.png";
        Alcotest.(check string) "untouched" "an image" (read_file (d // "o.png")));
    Alcotest.test_case
      "a read-only (0444) output is refused, by the command and by the library's rename"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file (d // "s.rts") scene;
        write_file (d // "ro.png") "keep me";
        Unix.chmod (d // "ro.png") 0o444;
        refused "render"
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "ro.png" ])
          "cannot write ro.png: the file is read-only";
        write_file (d // "ro.json") "{}";
        Unix.chmod (d // "ro.json") 0o444;
        refused "stats"
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "ok.png"; "--stats"; "ro.json" ])
          "cannot write ro.json: the file is read-only";
        Alcotest.(check bool)
          "refused before rendering" false
          (Sys.file_exists (d // "ok.png"));
        (match
           Lancer.Safe_file.write (d // "ro.png") (fun oc -> output_string oc "new")
         with
        | Ok () -> Alcotest.fail "the rename replaced a read-only file"
        | Error m -> Alcotest.(check bool) m true (contains m "read-only"));
        Alcotest.(check string) "untouched" "keep me" (read_file (d // "ro.png"));
        Alcotest.(check int)
          "still 0444" 0o444
          ((Unix.stat (d // "ro.png")).st_perm land 0o777));
  ]

(* ---- temporary files left by a killed run ---- *)

(* The id of a process that has exited (and been reaped). *)
let dead_pid () =
  let pid = Unix.create_process "true" [| "true" |] Unix.stdin Unix.stdout Unix.stderr in
  ignore (Unix.waitpid [] pid);
  pid

let stale_tests =
  [
    Alcotest.test_case
      "temporary files of dead processes are removed by the next run in that directory, \
       which says so"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file (d // "s.rts") scene;
        let dead = dead_pid () in
        let o = Lancer.Safe_file.owner in
        let stale = Printf.sprintf ".out.png.tmp-%s-%d-123456" o dead
        and stale2 = Printf.sprintf ".other.ppm.tmp-%s-%d-42" o dead in
        (* One of a live process (this test), one of another machine sharing the directory
           (its process id means nothing here), and files that only look alike. *)
        let live = Printf.sprintf ".out.png.tmp-%s-%d-99" o (Unix.getpid ()) in
        let other_host = Printf.sprintf ".out.png.tmp-node17_pid4026531836-%d-5" dead in
        let others =
          [
            other_host;
            "notes.tmp-1-2";
            ".x.tmp-abc-1";
            ".y.tmp-1";
            "out.png.tmp-1-1";
            ".z.tmp-1-2";
          ]
        in
        List.iter
          (fun f -> write_file (d // f) "partial")
          (stale :: stale2 :: live :: others);
        let ((_, _, e) as r) =
          lancer ~dir:d [ "render"; "s.rts"; "-o"; "out.png"; "-q" ]
        in
        check_status "render" 0 r;
        List.iter
          (fun f ->
            Alcotest.(check bool) (f ^ " removed") false (Sys.file_exists (d // f));
            Alcotest.(check bool)
              (Printf.sprintf "%S names %s and its process" e f)
              true
              (contains e ("removed ./" ^ f)
              && contains e
                   (Printf.sprintf "left by process %d, which is no longer running" dead)
              ))
          [ stale; stale2 ];
        List.iter
          (fun f -> Alcotest.(check bool) (f ^ " kept") true (Sys.file_exists (d // f)))
          (live :: others);
        Alcotest.(check bool) "the image" true (Sys.file_exists (d // "out.png"));
        (* Frames directories too: the first frame written sweeps it. *)
        Unix.mkdir (d // "fr") 0o755;
        let stale3 = Printf.sprintf ".frame_0000.png.tmp-%s-%d-7" o dead in
        write_file (d // "fr" // stale3) "partial";
        write_file (d // "a.rts")
          "settings { width: 8, height: 6 }\n\
           animation { fps: 10, frames: 2 }\n\
           camera { position: (0, 1, -5), look_at: (0, 1, 0) }\n\
           light { position: (-3, 5, -4) }\n\
           sphere { center: (0, 1, 0), radius: 1 }\n";
        let ((_, _, e) as r) = lancer ~dir:d [ "animate"; "a.rts"; "-o"; "fr"; "-q" ] in
        check_status "animate" 0 r;
        Alcotest.(check bool) e true (contains e stale3);
        Alcotest.(check (list string))
          "only frames and the frames record"
          [ "frame_0000.png"; "frame_0001.png"; "lancer-frames.d"; "lancer-frames.json" ]
          (listing (d // "fr")));
  ]

(* ---- 16 bits, alpha and regions ---- *)

let sphere_on_background =
  {|settings { width: 32, height: 24, samples: 4, background: (0.1, 0.2, 0.3) }
camera { position: (0, 0, -5), look_at: (0, 0, 0), fov: 40 }
light { position: (-3, 5, -4) }
sphere { center: (0, 0, 0), radius: 1, material: material { color: (0.9, 0.3, 0.2), specular: 0.4 } }
|}

let be16 s k = (Char.code s.[2 * k] lsl 8) lor Char.code s.[(2 * k) + 1]

let output_tests =
  [
    Alcotest.test_case
      "--bits 16: a 16-bit PNG an independent decoder reads as the 16-bit PPM, on the \
       8-bit curve"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file (d // "s.rts") scene;
        check_status "png" 0
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "s16.png"; "--bits"; "16"; "-q" ]);
        check_status "ppm" 0
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "s16.ppm"; "--bits"; "16"; "-q" ]);
        check_status "8 bits" 0
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "s8.ppm"; "-q" ]);
        let ppm = read_file (d // "s16.ppm") in
        Alcotest.(check bool) "PPM maximum value 65535" true (contains ppm "\n65535\n");
        let head, samples = independent (d // "s16.png") in
        Alcotest.(check string) "40×30 RGB, 16 bits" "40 30 3 16" head;
        Alcotest.(check bool) "the same samples as the PPM" true (samples = ppm_body ppm);
        (* The same curve: each 16-bit value within half an 8-bit step of 257 × the 8-bit byte. *)
        let p8 = ppm_body (read_file (d // "s8.ppm")) in
        String.iteri
          (fun k c ->
            let v16 = be16 samples k and v8 = Char.code c in
            if abs (v16 - (257 * v8)) > 129 then
              Alcotest.failf "sample %d: 16-bit %d against 8-bit %d" k v16 v8)
          p8;
        (* Read back by lancer: the samples of the PNG. *)
        match Lancer.Image.read_raster (d // "s16.png") with
        | Ok r ->
            Alcotest.(check bool)
              "round trip" true
              (r.depth = 16 && Bytes.to_string r.samples = samples)
        | Error m -> Alcotest.fail m);
    Alcotest.test_case
      "--alpha: 0 on the background, 1 on the sphere, the covered share at its edge; \
       colours unchanged"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file (d // "s.rts") sphere_on_background;
        check_status "alpha" 0
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "a.png"; "--alpha"; "-q" ]);
        check_status "alpha, 1 domain" 0
          (lancer ~dir:d
             [ "render"; "s.rts"; "-o"; "a1.png"; "--alpha"; "-q"; "--domains"; "1" ]);
        check_status "alpha, 3 domains" 0
          (lancer ~dir:d
             [ "render"; "s.rts"; "-o"; "a3.png"; "--alpha"; "-q"; "--domains"; "3" ]);
        check_status "plain" 0 (lancer ~dir:d [ "render"; "s.rts"; "-o"; "p.ppm"; "-q" ]);
        Alcotest.(check bool)
          "bytes independent of the domains" true
          (read_file (d // "a1.png") = read_file (d // "a.png")
          && read_file (d // "a3.png") = read_file (d // "a.png"));
        let head, samples = independent (d // "a.png") in
        Alcotest.(check string) "RGBA, 8 bits" "32 24 4 8" head;
        let rgb = ppm_body (read_file (d // "p.ppm")) in
        let alpha i j = Char.code samples.[(4 * ((j * 32) + i)) + 3] in
        Alcotest.(check int) "corner: background" 0 (alpha 0 0);
        Alcotest.(check int) "centre: the sphere" 255 (alpha 16 12);
        let partial = ref 0 in
        for j = 0 to 23 do
          for i = 0 to 31 do
            let a = alpha i j in
            (* 4×4 samples: a share k/16. *)
            if not (List.exists (fun k -> a = ((255 * k) + 8) / 16) (List.init 17 Fun.id))
            then Alcotest.failf "alpha %d at %d,%d is no k/16" a i j;
            if a > 0 && a < 255 then incr partial;
            for c = 0 to 2 do
              if samples.[(4 * ((j * 32) + i)) + c] <> rgb.[(3 * ((j * 32) + i)) + c] then
                Alcotest.failf "colour differs at %d,%d" i j
            done
          done
        done;
        Alcotest.(check bool)
          (Printf.sprintf "%d edge pixels partly covered" !partial)
          true (!partial > 10);
        let ((_, _, e) as r) =
          lancer ~dir:d [ "render"; "s.rts"; "-o"; "a.ppm"; "--alpha" ]
        in
        check_status "PPM refused" 1 r;
        Alcotest.(check bool) e true (contains e "--alpha needs a PNG or EXR output"));
    Alcotest.test_case
      "--region renders the same pixels as a whole render, the background elsewhere; \
       --crop writes just them"
      `Quick (fun () ->
        let d = tmpdir () in
        let rest = String.sub scene 11 (String.length scene - 11) in
        assert (String.sub scene 0 11 = "settings { ");
        write_file (d // "s.rts")
          ("settings { background: (0.2, 0.4, 0.6), jitter: true, " ^ rest);
        check_status "whole" 0 (lancer ~dir:d [ "render"; "s.rts"; "-o"; "w.ppm"; "-q" ]);
        List.iter
          (fun domains ->
            check_status "region" 0
              (lancer ~dir:d
                 [
                   "render";
                   "s.rts";
                   "-o";
                   "r.ppm";
                   "--region";
                   "7,5,33,21";
                   "-q";
                   "--domains";
                   domains;
                 ]);
            check_status "crop" 0
              (lancer ~dir:d
                 [
                   "render";
                   "s.rts";
                   "-o";
                   "c.ppm";
                   "--region";
                   "7,5,33,21";
                   "--crop";
                   "-q";
                   "--domains";
                   domains;
                 ]);
            let w = ppm_body (read_file (d // "w.ppm"))
            and r = ppm_body (read_file (d // "r.ppm"))
            and c = read_file (d // "c.ppm") in
            Alcotest.(check bool) "the crop is 26×16" true (contains c "P6\n26 16\n255\n");
            let c = ppm_body c in
            for j = 0 to 29 do
              for i = 0 to 39 do
                let px s k = String.sub s (3 * k) 3 in
                let inside = i >= 7 && i < 33 && j >= 5 && j < 21 in
                if inside then (
                  if px r ((j * 40) + i) <> px w ((j * 40) + i) then
                    Alcotest.failf "region pixel %d,%d differs (%s domains)" i j domains;
                  if px c (((j - 5) * 26) + (i - 7)) <> px w ((j * 40) + i) then
                    Alcotest.failf "crop pixel %d,%d differs" i j)
                else if
                  (* The background (0.2, 0.4, 0.6) encoded: 124, 170, 203. *)
                  px r ((j * 40) + i) <> "\124\170\203"
                then
                  Alcotest.failf
                    "pixel %d,%d outside the region is not the background (%S)" i j
                    (px r ((j * 40) + i))
              done
            done)
          [ "1"; "2" ];
        List.iter
          (fun (args, expect) ->
            let ((_, _, e) as r) =
              lancer ~dir:d ([ "render"; "s.rts"; "-o"; "x.ppm" ] @ args)
            in
            check_status (String.concat " " args) 1 r;
            Alcotest.(check bool) e true (contains e expect))
          [
            ([ "--region"; "0,0,41,10" ], "is not inside the 40×30 image");
            ([ "--region"; "5,5,5,10" ], "0 <= x0 < x1 <= 40");
            ([ "--region"; "1,2,3" ], "four integers");
            ([ "--crop" ], "--crop needs --region");
          ]);
  ]

(* ---- standard output ---- *)

let stdout_tests =
  [
    Alcotest.test_case
      "-o - writes the PNG (or with --format ppm the PPM) to stdout and nothing else \
       there"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file (d // "s.rts") scene;
        check_status "file png" 0
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "f.png"; "-q" ]);
        check_status "file ppm" 0
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "f.ppm"; "-q" ]);
        let ((_, out, e) as r) =
          lancer ~dir:d [ "render"; "s.rts"; "-o"; "-"; "--stats"; "st.json" ]
        in
        check_status "stdout png" 0 r;
        Alcotest.(check bool)
          "stdout holds the PNG file's bytes, and only them" true
          (out = read_file (d // "f.png"));
        Alcotest.(check bool)
          ("the summary went to stderr: " ^ e)
          true
          (contains e "wrote the image to standard output (40×30");
        Alcotest.(check bool) "stats written" true (Sys.file_exists (d // "st.json"));
        let ((_, out, _) as r) =
          lancer ~dir:d [ "render"; "s.rts"; "-o"; "-"; "--format"; "ppm"; "-q" ]
        in
        check_status "stdout ppm" 0 r;
        Alcotest.(check bool) "the PPM file's bytes" true (out = read_file (d // "f.ppm"));
        let ((_, out, _) as r) =
          lancer ~dir:d [ "render"; "s.rts"; "-o"; "-"; "--bits"; "16"; "--alpha"; "-q" ]
        in
        check_status "stdout 16-bit RGBA" 0 r;
        write_file (d // "o16.png") out;
        let head, _ = independent (d // "o16.png") in
        Alcotest.(check string) "16-bit RGBA" "40 30 4 16" head;
        Alcotest.(check (list string))
          "no file named -"
          [ "f.png"; "f.ppm"; "o16.png"; "s.rts"; "st.json" ]
          (listing d));
    Alcotest.test_case
      "-o - into a closed pipe is an error with a message, not a silent death" `Quick
      (fun () ->
        let d = tmpdir () in
        write_file (d // "s.rts") scene;
        let script =
          Printf.sprintf
            "cd %s && %s render s.rts -o - --format ppm --width 600 --height 400 -q \
             2>err | head -c 10 >/dev/null; echo ${PIPESTATUS[0]}"
            (Filename.quote d) (Filename.quote exe)
        in
        let ic = Unix.open_process_args_in "/bin/bash" [| "bash"; "-c"; script |] in
        let status = String.trim (In_channel.input_all ic) in
        ignore (Unix.close_process_in ic);
        let e = read_file (d // "err") in
        Alcotest.(check string) ("exit 1: " ^ e) "1" status;
        Alcotest.(check bool)
          e true
          (contains e "cannot write the image to standard output: Broken pipe"));
    Alcotest.test_case
      "--stats - writes the statistics to stdout, the summary to stderr, and no file \
       named -"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file (d // "s.rts") scene;
        let ((_, out, e) as r) =
          lancer ~dir:d [ "render"; "s.rts"; "-o"; "f.ppm"; "--stats"; "-" ]
        in
        check_status "--stats -" 0 r;
        (match Yojson.Safe.from_string out with
        | `Assoc fields ->
            Alcotest.(check bool)
              "the statistics' fields" true
              (List.mem_assoc "wall_seconds" fields && List.mem_assoc "rays" fields)
        | _ -> Alcotest.failf "not a JSON object: %s" out
        | exception Yojson.Json_error m ->
            Alcotest.failf "stdout is not the statistics alone (%s): %s" m out);
        Alcotest.(check bool)
          ("the summary went to stderr: " ^ e)
          true
          (contains e "wrote f.ppm (40×30");
        Alcotest.(check (list string)) "no file named -" [ "f.ppm"; "s.rts" ] (listing d);
        (* The error budget's choice is a line for the user too. *)
        let ((_, out, e) as r) =
          lancer ~dir:d
            [ "render"; "s.rts"; "-o"; "f.ppm"; "--max-error"; "0.05"; "--stats"; "-" ]
        in
        check_status "--max-error with --stats -" 0 r;
        (match Yojson.Safe.from_string out with
        | `Assoc _ -> ()
        | _ -> Alcotest.failf "not a JSON object: %s" out
        | exception Yojson.Json_error m ->
            Alcotest.failf "stdout is not the statistics alone (%s): %s" m out);
        Alcotest.(check bool)
          ("the choice went to stderr: " ^ e)
          true (contains e "max error 0.05"));
    Alcotest.test_case
      "--format that contradicts the file's extension, and --stats - with -o -, are \
       refused"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file (d // "s.rts") scene;
        List.iter
          (fun (args, expect) ->
            let ((_, out, e) as r) = lancer ~dir:d ([ "render"; "s.rts" ] @ args) in
            check_status (String.concat " " args) 1 r;
            Alcotest.(check string) "nothing on stdout" "" out;
            Alcotest.(check bool) e true (contains e expect))
          [
            ([ "-o"; "x.png"; "--format"; "ppm" ], "--format is for -o -");
            ( [ "-o"; "-"; "--format"; "ppm"; "--alpha" ],
              "--alpha needs a PNG or EXR output" );
            ([ "-o"; "-"; "--stats"; "-" ], "would both write to standard output");
            ( [ "-o"; "-"; "--resume" ],
              "--resume keeps its checkpoint beside the output file" );
          ];
        Alcotest.(check (list string)) "nothing written" [ "s.rts" ] (listing d));
  ]

let () =
  Alcotest.run "output"
    [
      ("png", png_tests);
      ("limits", limit_tests);
      ("refusals", refusal_tests);
      ("stale", stale_tests);
      ("bits, alpha, region", output_tests);
      ("stdout", stdout_tests);
    ]
