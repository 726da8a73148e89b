(* Bad input everywhere, through the lancer command as a user runs it: each case must end
   with exit status 1, a located or one-line message, no backtrace, no libpng chatter, and
   no file left behind (neither the output nor a temporary). What test/cli and scenes/bad
   already cover is not repeated here. *)
module G = Fuzz_gen

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"
let scenes = Filename.concat (Sys.getcwd ()) "../../scenes"

open Run_lancer

let tmpdir () = tmpdir "lancer-robust"
let files d = Sys.readdir d |> Array.to_list |> List.sort compare

(* Run [prefix; lancer args] in [dir] through the shell; (status, stdout, stderr). *)
let lancer ?prefix ~dir args = run ?prefix ~exe ~dir args

let fail_with ?(msg = "") (st, _, e) =
  Alcotest.failf "%sexit %d, stderr:\n%s" (if msg = "" then "" else msg ^ ": ") st e

(* Scene errors start a line with file:line:col; other errors are one line
   "lancer: …". *)
let names e where =
  G.contains e ("lancer: " ^ where)
  || String.length e >= String.length where
     && String.sub e 0 (String.length where) = where
  || G.contains e ("\n" ^ where)

(* Exit 1, a message naming [where] (a file:line:col, a path), no internal error, nothing
   from a C library, and the directory holding exactly [left] afterwards. *)
let refused ?(lines = 1) ~dir ~where ~left r =
  let st, _, e = r in
  if st <> 1 then fail_with ~msg:"expected exit 1" r;
  if not (names e where) then fail_with ~msg:(Printf.sprintf "expected %S" where) r;
  List.iter
    (fun bad ->
      if G.contains e bad then fail_with ~msg:(Printf.sprintf "unexpected %S" bad) r)
    [ "internal error"; "Raised at"; "Fatal error"; "libpng"; "exception" ];
  let n = List.length (String.split_on_char '\n' (String.trim e)) in
  if n > lines then fail_with ~msg:(Printf.sprintf "expected at most %d lines" lines) r;
  Alcotest.(check (list string)) "files left" (List.sort compare left) (files dir)

(* A scene in [dir] that renders [object_text] in an 8×6 image. *)
let scene dir object_text =
  write_file (Filename.concat dir "s.rts")
    ("settings { width: 8, height: 6 }\nlight { position: (0, 5, -5) }\n" ^ object_text
   ^ "\n")

let render ?prefix dir extra =
  lancer ?prefix ~dir ([ "render"; "s.rts"; "-o"; "out.ppm"; "-q" ] @ extra)

let case name f = Alcotest.test_case name `Quick f

(* ---- scene text ---- *)

let scene_tests =
  [
    case "every scene of scenes/, cut short anywhere, loads or gives located errors"
      (fun () ->
        (* Cut at 20 points of each file: exit 0 (a prefix may well be a valid scene) or 1
           with file:line:col; never an internal error. *)
        let d = tmpdir () in
        Sys.readdir scenes |> Array.to_list
        |> List.filter (fun f -> Filename.check_suffix f ".rts")
        |> List.iter (fun f ->
               let text = read_file (Filename.concat scenes f) in
               for k = 1 to 20 do
                 let cut = String.sub text 0 (k * String.length text / 21) in
                 write_file (Filename.concat d f) cut;
                 let ((st, _, e) as r) = lancer ~dir:d [ "check"; f ] in
                 if st = 1 then (
                   if not (names e (f ^ ":")) then
                     fail_with
                       ~msg:
                         (Printf.sprintf "%s cut at %d: unlocated" f (String.length cut))
                       r)
                 else if st <> 0 then
                   fail_with ~msg:(Printf.sprintf "%s cut at %d" f (String.length cut)) r;
                 if G.contains e "internal error" then fail_with ~msg:f r
               done));
    case "a scene in UTF-16, or a PNG given as a scene, is refused as not text" (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "u.rts") "\255\254s\000p\000h\000e\000r\000e\000";
        refused ~dir:d ~where:"u.rts" ~left:[ "u.rts" ]
          (lancer ~dir:d [ "render"; "u.rts"; "-o"; "u.ppm" ]);
        let png = "\137PNG\r\n\026\n\000\000\000\rIHDR" in
        write_file (Filename.concat d "p.rts") png;
        refused ~dir:d ~where:"p.rts" ~left:[ "p.rts"; "u.rts" ]
          (lancer ~dir:d [ "render"; "p.rts"; "-o"; "p.ppm" ]));
    case "a number beyond the doubles is a located error" (fun () ->
        let d = tmpdir () in
        scene d "sphere { center: (0, 0, 0), radius: 1e999 }";
        refused ~lines:4 ~dir:d ~where:"s.rts:3:" ~left:[ "s.rts" ] (render d []));
    case "100 000 nested parentheses and 100 000 nested groups evaluate" (fun () ->
        let d = tmpdir () in
        let n = 100_000 in
        scene d
          ("let x = " ^ String.make n '(' ^ "1" ^ String.make n ')' ^ "\n"
          ^ String.concat "" (List.init n (fun _ -> "group { "))
          ^ "sphere { center: (0, 0, -2 * x), radius: 1 }"
          ^ String.concat "" (List.init n (fun _ -> " }")));
        let ((st, out, _) as r) = lancer ~dir:d [ "check"; "s.rts" ] in
        if st <> 0 then fail_with r;
        Alcotest.(check bool) ("one sphere: " ^ out) true (G.contains out "objects: 1"));
    case "100 000 unclosed parentheses are a located syntax error" (fun () ->
        let d = tmpdir () in
        scene d ("let x = " ^ String.make 100_000 '(' ^ "1");
        let ((st, _, e) as r) = lancer ~dir:d [ "check"; "s.rts" ] in
        if st <> 1 || not (names e "s.rts:") then fail_with r;
        if G.contains e "internal error" then fail_with r);
    case "a scene that includes itself is a located error" (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts") "include \"s.rts\"\n";
        refused ~lines:4 ~dir:d ~where:"s.rts:1:9: include cycle" ~left:[ "s.rts" ]
          (render d []));
    case "an error never shows the lines of a file that is not a scene or a mesh"
      (fun () ->
        (* A scene may name any file: a password file, as an include or as a mesh. *)
        let d = tmpdir () in
        let secret = "root:$6$SECRET-HASH:19000:0:99999:7:::" in
        write_file (Filename.concat d "shadow") (secret ^ "\ndaemon:*:19000\n");
        write_file (Filename.concat d "shadow.obj") (secret ^ "\n");
        List.iter
          (fun (name, text, where) ->
            write_file (Filename.concat d name) text;
            let ((st, out, e) as r) = lancer ~dir:d [ "check"; name ] in
            if st <> 1 || not (names e where) then fail_with r;
            if G.contains (out ^ e) "SECRET" || G.contains (out ^ e) "root" then
              fail_with ~msg:"a line of the file is shown" r)
          [
            ("i.rts", "include \"shadow\"\n", "shadow:1:");
            ("m.rts", "mesh { file: \"shadow\" }\n", "m.rts:1:");
            ("o.rts", "mesh { file: \"shadow.obj\" }\n", "o.rts:1:");
          ]);
    case "an include tree that doubles at each of 30 levels is refused at once" (fun () ->
        (* f0 includes f1 twice, f1 includes f2 twice, …: 2^30 inclusions if expanded. *)
        let d = tmpdir () in
        let depth = 30 in
        for k = 0 to depth - 1 do
          write_file
            (Filename.concat d (Printf.sprintf "f%d.rts" k))
            (Printf.sprintf "include \"f%d.rts\"\ninclude \"f%d.rts\"\n" (k + 1) (k + 1))
        done;
        write_file
          (Filename.concat d (Printf.sprintf "f%d.rts" depth))
          "sphere { center: (0, 0, 0), radius: 1 }\n";
        (* The unbounded expansion ran for minutes and gigabytes: bounded here. *)
        let ((st, _, e) as r) =
          lancer ~prefix:"ulimit -v 2000000; timeout 120" ~dir:d [ "check"; "f0.rts" ]
        in
        if st <> 1 || not (G.contains e "the includes expand to more than 10000 files")
        then fail_with r;
        if not (G.contains e ".rts:1:1: the includes expand") then
          fail_with ~msg:"unlocated" r);
    case "an image 60000×60000 is refused up front with the limit" (fun () ->
        let d = tmpdir () in
        scene d "";
        (* Each side within 1–65536 (larger is refused as the option is read), the whole
           past the pixel limit. *)
        let ((_, _, e) as r) = render d [ "--width"; "60000"; "--height"; "60000" ] in
        refused ~dir:d ~where:"image 60000×60000" ~left:[ "s.rts" ] r;
        Alcotest.(check bool) "names the limit" true (G.contains e "268435456"));
    case "--depth beyond the scene language's 1000 is refused before rendering" (fun () ->
        let d = tmpdir () in
        scene d "";
        let ((_, _, e) as r) = render d [ "--depth"; "10000000" ] in
        refused ~dir:d ~where:"--depth" ~left:[ "s.rts" ] r;
        Alcotest.(check bool) "names the limit" true (G.contains e "1000"));
    case "a scene asking for a 100 000-pixel-wide or a 65536² image is a located error"
      (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts") "settings { width: 100000 }\n";
        refused ~lines:4 ~dir:d ~where:"s.rts:1:19:" ~left:[ "s.rts" ] (render d []);
        write_file (Filename.concat d "s.rts")
          "settings { width: 65536, height: 65536 }\n";
        refused ~lines:4 ~dir:d ~where:"s.rts:1:1: invalid settings: image 65536×65536"
          ~left:[ "s.rts" ] (render d []));
  ]

(* ---- textures and meshes ---- *)

let asset_tests =
  let texture file =
    Printf.sprintf
      "sphere { center: (0, 0, 0), radius: 1, material: material { texture: image(%S, 1) \
       } }"
      file
  in
  let bad_texture name file contents where =
    case name (fun () ->
        let d = tmpdir () in
        scene d (texture file);
        Option.iter (fun c -> write_file (Filename.concat d file) c) contents;
        let left = "s.rts" :: (match contents with Some _ -> [ file ] | None -> []) in
        let ((_, _, e) as r) = render d [] in
        refused ~lines:4 ~dir:d ~where:"s.rts:3:" ~left r;
        Alcotest.(check bool) ("says why: " ^ e) true (G.contains e where))
  in
  let bad_mesh name contents where =
    case name (fun () ->
        let d = tmpdir () in
        scene d "mesh { file: \"m.obj\" }";
        write_file (Filename.concat d "m.obj") contents;
        let ((_, _, e) as r) = render d [] in
        refused ~lines:4 ~dir:d ~where:"s.rts:3:" ~left:[ "m.obj"; "s.rts" ] r;
        Alcotest.(check bool) ("says where in the OBJ: " ^ e) true (G.contains e where))
  in
  let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n" in
  [
    case "a mesh as ASCII, little- and big-endian PLY and as OBJ renders the same bytes"
      (fun () ->
        let d = tmpdir () in
        let m = G.random_ply (Random.State.make [| 7 |]) in
        let files =
          [
            ("a.ply", G.ply_text "ascii" m);
            ("le.ply", G.ply_text "binary_little_endian" m);
            ("be.ply", G.ply_text "binary_big_endian" m);
            ("m.obj", G.obj_of_ply m);
          ]
        in
        let images =
          List.map
            (fun (name, text) ->
              write_file (Filename.concat d name) text;
              write_file (Filename.concat d "s.rts")
                (Printf.sprintf
                   "settings { width: 48, height: 36 }\n\
                    camera { position: (0, 1, -9), look_at: (0, 0, 0) }\n\
                    light { position: (-3, 5, -4) }\n\
                    mesh { file: %S, material: material { texture: checker((1, 1, 1), \
                    (0.2, 0.3, 0.8), 0.5) } }\n"
                   name);
              let ((st, _, _) as r) = render d [] in
              if st <> 0 then fail_with ~msg:name r;
              read_file (Filename.concat d "out.ppm"))
            files
        in
        match images with
        | first :: rest ->
            List.iteri
              (fun k img ->
                Alcotest.(check bool)
                  (fst (List.nth files (k + 1)) ^ " renders as the ASCII PLY")
                  true (String.equal first img))
              rest
        | [] -> ());
    bad_texture "a missing texture image" "x.png" None "no such file";
    bad_texture "a texture that is not a PNG" "x.png" (Some "GIF89a this is not a png")
      "not a PNG file";
    bad_texture "a truncated PNG texture" "x.png"
      (Some (String.sub (G.png_one_pixel ()) 0 40))
      "x.png";
    bad_texture "a PNG texture claiming 30000×30000 pixels" "x.png"
      (Some (G.png_claiming 30000 30000))
      "larger than the limit";
    bad_texture "a truncated PPM texture" "x.ppm" (Some "P6\n4 4\n255\n\000\000")
      "truncated";
    bad_texture "a texture with an unknown extension" "x.jpg" (Some "\255\216\255")
      "lancer reads .png and .ppm images";
    bad_mesh "an OBJ face with an index past the vertices" (tri ^ "f 1 2 4\n") "m.obj:4:";
    bad_mesh "an OBJ face before any vertex" "f 1 2 3\n" "m.obj:1:";
    bad_mesh "an OBJ with a vertex missing a coordinate"
      ("v 0 0\n" ^ tri ^ "f 1 2 3\n")
      "m.obj:1:";
    bad_mesh "an OBJ of garbage" "\xde\xad\xbe\xef garbage\n" "m.obj:1:";
    bad_mesh "a binary file as OBJ" "\127ELF\002\001\001\000\000\000" "not a text file";
    bad_mesh "an OBJ coordinate beyond ±1e150" (tri ^ "v 1e200 0 0\nf 1 2 4\n") "m.obj:4:";
    bad_mesh "an OBJ whose faces all have zero area"
      "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n" "zero area";
    case "a missing OBJ and a directory as OBJ" (fun () ->
        let d = tmpdir () in
        scene d "mesh { file: \"none.obj\" }";
        refused ~lines:4 ~dir:d ~where:"s.rts:3:" ~left:[ "s.rts" ] (render d []);
        Unix.mkdir (Filename.concat d "dir.obj") 0o755;
        scene d "mesh { file: \"dir.obj\" }";
        refused ~lines:4 ~dir:d ~where:"s.rts:3:" ~left:[ "dir.obj"; "s.rts" ]
          (render d []));
  ]

(* ---- outputs ---- *)

let output_tests =
  [
    case
      "a full disk (file size limit) is one line, exit 1, no file and no temporary, for \
       PNG and PPM" (fun () ->
        (* ulimit -f makes write(2) fail with EFBIG once the file reaches 1 KiB, as ENOSPC
           would; SIGXFSZ is ignored so that the failure reaches lancer. *)
        List.iter
          (fun out ->
            let d = tmpdir () in
            scene d "sphere { center: (0, 0, 0), radius: 1 }";
            let r =
              lancer ~prefix:"trap '' XFSZ; ulimit -f 1;" ~dir:d
                [
                  "render"; "s.rts"; "-o"; out; "-q"; "--width"; "300"; "--height"; "200";
                ]
            in
            refused ~dir:d ~where:("cannot write " ^ out) ~left:[ "s.rts" ] r)
          [ "out.ppm"; "out.png" ];
        (* Without the trap the signal's default action would kill lancer mid-write. *)
        let d = tmpdir () in
        scene d "sphere { center: (0, 0, 0), radius: 1 }";
        let r =
          lancer ~prefix:"ulimit -f 1;" ~dir:d
            [
              "render";
              "s.rts";
              "-o";
              "out.ppm";
              "-q";
              "--width";
              "300";
              "--height";
              "200";
            ]
        in
        refused ~dir:d ~where:"cannot write out.ppm" ~left:[ "s.rts" ] r);
    case "a full disk leaves the previous image untouched" (fun () ->
        let d = tmpdir () in
        scene d "sphere { center: (0, 0, 0), radius: 1 }";
        write_file (Filename.concat d "out.ppm") "previous";
        let r =
          lancer ~prefix:"trap '' XFSZ; ulimit -f 1;" ~dir:d
            [
              "render";
              "s.rts";
              "-o";
              "out.ppm";
              "-q";
              "--width";
              "300";
              "--height";
              "200";
            ]
        in
        refused ~dir:d ~where:"cannot write out.ppm" ~left:[ "out.ppm"; "s.rts" ] r;
        Alcotest.(check string)
          "unchanged" "previous"
          (read_file (Filename.concat d "out.ppm")));
    case "an output directory the system refuses (/proc) is one line, exit 1" (fun () ->
        if Sys.file_exists "/proc/self" then (
          let d = tmpdir () in
          scene d "";
          refused ~dir:d ~where:"cannot write /proc/x.ppm" ~left:[ "s.rts" ]
            (lancer ~dir:d [ "render"; "s.rts"; "-o"; "/proc/x.ppm"; "-q" ]);
          refused ~dir:d ~where:"cannot write /proc/x.png" ~left:[ "s.rts" ]
            (lancer ~dir:d [ "render"; "s.rts"; "-o"; "/proc/x.png"; "-q" ])));
    case "statistics to a missing directory are one line naming the directory" (fun () ->
        let d = tmpdir () in
        scene d "";
        let ((_, _, e) as r) = render d [ "--stats"; "no/such/st.json" ] in
        let st, _, _ = r in
        if st <> 1 then fail_with r;
        Alcotest.(check bool)
          ("names the directory, not a temporary: " ^ e)
          true
          (G.contains e "directory no/such does not exist" && not (G.contains e ".tmp")));
    case "statistics to a pipe are written into the pipe, which stays a pipe" (fun () ->
        (* A device or a FIFO (/dev/stdout, /dev/null) cannot be replaced by rename: it is
           written in place. A reader copies the FIFO to a file. *)
        let d = tmpdir () in
        scene d "";
        let fifo = Filename.concat d "st.json" in
        Unix.mkfifo fifo 0o600;
        let r =
          lancer ~prefix:"(timeout 20 cat st.json > copy.json &);" ~dir:d
            [ "render"; "s.rts"; "-o"; "out.ppm"; "-q"; "--stats"; "st.json" ]
        in
        let st, _, _ = r in
        if st <> 0 then fail_with r;
        Alcotest.(check bool) "still a FIFO" true ((Unix.stat fifo).st_kind = Unix.S_FIFO);
        let copy = Filename.concat d "copy.json" in
        let rec wait k =
          if
            k > 0
            && not (Sys.file_exists copy && G.contains (read_file copy) "bad_samples")
          then (
            Unix.sleepf 0.05;
            wait (k - 1))
        in
        wait 100;
        Alcotest.(check bool)
          "the JSON went through the pipe" true
          (G.contains (read_file copy) "\"bad_samples\""));
    case "a NaN-producing scene warns with the pixel and counts bad_samples in --stats"
      (fun () ->
        (* Colour × light colour × intensity overflows: every sample is infinite or NaN. *)
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts")
          "settings { width: 6, height: 4, samples: 2, background: (0, 1, 0) }\n\
           camera { position: (0, 1, 0), look_at: (0, 0, 0), up: (0, 0, 1), fov: 30 }\n\
           light { direction: (0, -1, 0), intensity: 1e150, color: (1e150, 1e150, 1e150) }\n\
           plane { normal: (0, 1, 0), offset: 0, material: material { color: (1e150, \
           1e150, 1e150) } }\n";
        let ((st, _, e) as r) =
          lancer ~dir:d [ "render"; "s.rts"; "-o"; "out.ppm"; "-q"; "--stats"; "st.json" ]
        in
        if st <> 0 then fail_with r;
        Alcotest.(check bool)
          ("warning with a pixel: " ^ e)
          true
          (G.contains e "96 samples were NaN or infinite (first at pixel ");
        let j = Yojson.Safe.from_file (Filename.concat d "st.json") in
        Alcotest.(check int)
          "bad_samples" 96
          Yojson.Safe.Util.(j |> member "bad_samples" |> to_int);
        match Lancer.Image.read_rgb8 (Filename.concat d "out.ppm") with
        | Error m -> Alcotest.fail m
        | Ok (_, _, b) ->
            Alcotest.(check bool)
              "every pixel is the green background" true
              (Bytes.to_string b
              = String.concat "" (List.init 24 (fun _ -> "\000\255\000"))));
  ]

(* ---- interruption (SIGINT is in test/cli) ---- *)

let signal_tests =
  List.map
    (fun (name, signal) ->
      Alcotest.test_case
        (Printf.sprintf "%s during a render: exit 130, no output, no temporary" name)
        `Slow (fun () ->
          let d = tmpdir () in
          write_file (Filename.concat d "s.rts")
            "settings { width: 3000, height: 2000, samples: 4 }\n\
             light { position: (0, 5, -5), radius: 1, samples: 4 }\n\
             sphere { center: (0, 0, 0), radius: 1, material: material { reflection: 0.5 \
             } }\n";
          let pid =
            Unix.create_process exe
              [|
                exe;
                "render";
                Filename.concat d "s.rts";
                "-o";
                Filename.concat d "out.png";
                "-q";
                "--domains";
                "2";
              |]
              Unix.stdin Unix.stdout Unix.stderr
          in
          Unix.sleepf 0.7;
          Unix.kill pid signal;
          let _, st = Unix.waitpid [] pid in
          Alcotest.(check bool) "exit 130" true (st = Unix.WEXITED 130);
          Alcotest.(check (list string)) "no file" [ "s.rts" ] (files d)))
    [ ("SIGTERM", Sys.sigterm) ]

let () =
  Alcotest.run "bad input"
    [
      ("scene", scene_tests);
      ("assets", asset_tests);
      ("outputs", output_tests);
      ("signals", signal_tests);
    ]
