(* What lancer check (and a render's own report) tells the user: every frame of a range
   checked, with the frames an error happens at; warnings; the cost estimate; build and
   render times apart. *)

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"

open Run_lancer

let lancer ?(dir = Sys.getcwd ()) args = run ~exe ~dir args

let has msg text sub =
  Alcotest.(check bool)
    (Printf.sprintf "%s: %S in\n%s" msg sub text)
    true (contains text sub)

let lacks msg text sub =
  Alcotest.(check bool)
    (Printf.sprintf "%s: no %S in\n%s" msg sub text)
    false (contains text sub)

let scene_dir text =
  let d = tmpdir "lancer-check" in
  write_file (Filename.concat d "s.rts") text;
  d

(* Frame 12 divides by zero; frames 21 and later have a negative radius. *)
let flaky_anim =
  {|settings { width: 16, height: 12 }
animation { fps: 10, frames: 30 }
light { position: (0, 5, -5) }
let r = 1 / (frame - 12)
sphere { center: (0, 0, 0), radius: if frame > 20 then -1 else 1 }
|}

let frame_tests =
  [
    Alcotest.test_case "an error at one frame only names the frame and time" `Quick
      (fun () ->
        let d = scene_dir flaky_anim in
        let ((_, _, e) as r) =
          lancer ~dir:d [ "render"; "s.rts"; "--frame"; "12"; "-o"; "x.png" ]
        in
        check_status "render --frame 12" 1 r;
        has "located" e "s.rts:4:13: division by zero (at frame 12, time 1.2 s)";
        Alcotest.(check bool)
          "no output" false
          (Sys.file_exists (Filename.concat d "x.png")));
    Alcotest.test_case
      "check --frames all evaluates every frame and lists those that fail" `Quick
      (fun () ->
        let d = scene_dir flaky_anim in
        let ((_, _, e) as r) = lancer ~dir:d [ "check"; "s.rts"; "--frames"; "all" ] in
        check_status "check --frames all" 1 r;
        has "first failing frame shown" e "division by zero (at frame 12, time 1.2 s)";
        has "every failing frame listed" e
          "10 of the 30 frames checked (0..29) fail: 12, 21..29";
        (* Frame 0 alone is fine: plain check passes. *)
        check_status "check (frame 0)" 0 (lancer ~dir:d [ "check"; "s.rts" ]));
    Alcotest.test_case "check --frames A..B checks only that range" `Quick (fun () ->
        let d = scene_dir flaky_anim in
        let ((_, out, _) as r) =
          lancer ~dir:d [ "check"; "s.rts"; "--frames"; "0..11" ]
        in
        check_status "frames before the error" 0 r;
        has "says what it checked" out
          "frames checked: 0..11 (12 frames), every one evaluates";
        let ((_, _, e) as r) = lancer ~dir:d [ "check"; "s.rts"; "--frames"; "20..25" ] in
        check_status "a range with failing frames" 1 r;
        has "the radius error, at frame 21" e "(at frame 21, time 2.1 s)";
        has "listed" e "5 of the 6 frames checked (20..25) fail: 21..25");
    Alcotest.test_case "check --frames outside the animation, or a bad range, is refused"
      `Quick (fun () ->
        let d = scene_dir flaky_anim in
        let ((_, _, e) as r) = lancer ~dir:d [ "check"; "s.rts"; "--frames"; "0..40" ] in
        check_status "beyond the end" 1 r;
        has "says the range" e "the animation has frames 0..29";
        check_status "not a range" 1
          (lancer ~dir:d [ "check"; "s.rts"; "--frames"; "some" ]);
        check_status "with --time" 1
          (lancer ~dir:d [ "check"; "s.rts"; "--frames"; "all"; "--time"; "1" ]);
        write_file
          (Filename.concat d "still.rts")
          "sphere { center: (0, 0, 0), radius: 1 }\n";
        let ((_, out, _) as r) =
          lancer ~dir:d [ "check"; "still.rts"; "--frames"; "all" ]
        in
        check_status "a still has frame 0" 0 r;
        has "one frame" out "frames checked: 0..0 (1 frame)");
  ]

let build_scene =
  {|settings { width: 32, height: 24 }
light { position: (0, 5, -5) }
for i in 0 to 499 { sphere { center: (i, 0, 0), radius: 0.5 } }
|}

let time_tests =
  [
    Alcotest.test_case "the summary and --stats give build and render time apart" `Quick
      (fun () ->
        let d = scene_dir build_scene in
        let ((_, out, _) as r) =
          lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.png"; "--stats"; "st.json" ]
        in
        check_status "render" 0 r;
        has "summary" out "s: build ";
        has "summary" out " s, render ";
        let j = Yojson.Safe.from_file (Filename.concat d "st.json") in
        let open Yojson.Safe.Util in
        let f k = j |> member k |> to_number in
        let build = f "build_seconds"
        and render = f "render_seconds"
        and wall = f "wall_seconds" in
        Alcotest.(check bool) "build time is counted" true (build > 0.);
        Alcotest.(check bool) "render time is counted" true (render > 0.);
        Alcotest.(check (float 1e-9)) "wall is build + render" (build +. render) wall);
    Alcotest.test_case
      "the build says what it is doing with --progress, and nothing without" `Quick
      (fun () ->
        let d = scene_dir build_scene in
        let ((_, _, e) as r) =
          lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.png"; "--progress" ]
        in
        check_status "render --progress" 0 r;
        has "loading" e "building: reading and checking s.rts";
        has "evaluating" e
          "building: evaluating the scene and building its acceleration structure";
        let ((_, _, e) as r) = lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.png" ] in
        check_status "render" 0 r;
        Alcotest.(check string) "not a terminal: silent" "" e;
        if Sys.command "command -v script >/dev/null 2>&1" = 0 then (
          let out = Filename.concat d "tty.out" in
          let cmd =
            Printf.sprintf "cd %s && script -qec %s /dev/null > %s 2>&1"
              (Filename.quote d)
              (Filename.quote
                 (Printf.sprintf "%s render s.rts -o b.png" (Filename.quote exe)))
              (Filename.quote out)
          in
          Alcotest.(check int) "render on a terminal" 0 (Sys.command cmd);
          has "on a terminal, redrawn in place" (read_file out)
            "\r\027[Kbuilding: evaluating the scene"));
    Alcotest.test_case
      "a long build counts the objects built so far, then names the acceleration \
       structure; a still is evaluated once"
      `Quick (fun () ->
        let d =
          scene_dir
            "settings { width: 8, height: 8 }\n\
             light { position: (0, 5, 0) }\n\
             for i in 0 to 65535 { sphere { center: (i, 0, 0), radius: 0.4 } }\n"
        in
        let ((_, _, e) as r) =
          lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.png"; "--progress" ]
        in
        check_status "render --progress" 0 r;
        has "checking" e "building: checking the scene: 65536 objects so far";
        (* The render of a still uses the evaluation its load made. *)
        lacks "evaluated once" e "building: evaluating the scene: 65536 objects so far";
        has "acceleration structure" e
          "building: building the acceleration structure over 65536 objects");
  ]

let check_out text =
  let d = scene_dir text in
  let ((_, out, _) as r) = lancer ~dir:d [ "check"; "s.rts" ] in
  check_status "check" 0 r;
  out

let warning_tests =
  [
    Alcotest.test_case "the summary shows jitter and adaptive sampling" `Quick (fun () ->
        let out =
          check_out
            "settings { samples: 2, jitter: true, adaptive: 0.05 }\n\
             light { position: (0, 5, 0) }\n\
             sphere { center: (0, 0, 0), radius: 1 }\n"
        in
        has "jitter" out "jitter on";
        has "adaptive" out "adaptive 0.05: 2×2 samples, 4×4 where they differ by more";
        let out =
          check_out
            "light { position: (0, 5, 0) }\nsphere { center: (0, 0, 0), radius: 1 }\n"
        in
        has "defaults" out "1×1 samples per pixel (jitter off, adaptive off)";
        lacks "a fine scene" out "warning");
    Alcotest.test_case "check warns about an empty file, no objects, no lights" `Quick
      (fun () ->
        let out = check_out "// only a comment\n" in
        has "empty" out "s.rts: warning: the scene is empty (no statements)";
        lacks "empty says it once" out "no objects";
        let out = check_out "light { position: (0, 5, 0) }\n" in
        has "no objects" out "s.rts: warning: the scene has no objects";
        lacks "has a light" out "no lights";
        let out = check_out "sphere { center: (0, 0, 0), radius: 1 }\n" in
        has "no lights" out "s.rts: warning: the scene has no lights";
        lacks "has an object" out "no objects");
    Alcotest.test_case "check warns, at the loop, about a loop that runs zero times"
      `Quick (fun () ->
        let out =
          check_out
            "light { position: (0, 5, 0) }\n\
             sphere { center: (0, 0, 0), radius: 1 }\n\
             for i in 10 to 0 { sphere { center: (i, 0, 0), radius: 1 } }\n"
        in
        has "located" out
          "s.rts:3:1: warning: this loop runs zero times: it counts from 10 to 0 in \
           steps of 1";
        has "how to count down" out "give a negative step";
        has "the line" out "\nfor i in 10 to 0 {";
        let out =
          check_out
            "light { position: (0, 5, 0) }\n\
             sphere { center: (0, 0, 0), radius: 1 }\n\
             for i in 10 to 0 step -1 { }\n"
        in
        lacks "a loop that runs" out "warning");
    Alcotest.test_case
      "colours given as 0–255 are a located warning, in check and before a render, \
       unless a light is dim enough for them"
      `Quick (fun () ->
        let scene intensity =
          Printf.sprintf
            "settings { width: 8, height: 6 }\n\
             light { position: (0, 5, -5), intensity: %s }\n\
             let orange = material { color: (255, 128, 0) }\n\
             sphere { center: (0, 0, 0), radius: 1, material: orange }\n\
             sphere { center: (2, 0, 0), radius: 1, material: orange }\n\
             plane { normal: (0, 1, 0), offset: -1, material: material { texture: \
             checker((1, 1, 1), (0, 0, 1.5), 1) } }\n"
            intensity
        in
        let out = check_out (scene "1") in
        has "located at the first object that has it" out
          "s.rts:4:1: warning: colour (255, 128, 0) has a component above 1 and no light \
           is dim enough to make up for it";
        has "the colour divided by 255" out "divide by 255: (1, 0.502, 0))";
        has "the other objects counted" out "; 1 more object has this colour";
        has "the line and a caret" out "\nsphere { center: (0, 0, 0)";
        has "a texture's colours too" out "s.rts:6:1: warning: colour (0, 0, 1.5)";
        (* A light of intensity 1/255 makes up for 255; 1/2 for 1.5 but not for 255. *)
        lacks "a dim light" (check_out (scene "1 / 255")) "component above 1";
        let out = check_out (scene "0.5") in
        lacks "1.5 under a light of 0.5" out "colour (0, 0, 1.5)";
        has "255 under a light of 0.5" out "colour (255, 128, 0)";
        (* render says it on stderr, before rendering; -q does not. *)
        let d = scene_dir (scene "1") in
        let ((_, _, e) as r) = lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.png" ] in
        check_status "render" 0 r;
        has "render warns" e "s.rts:4:1: warning: colour (255, 128, 0)";
        let ((_, _, e) as r) = lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.png"; "-q" ] in
        check_status "render -q" 0 r;
        Alcotest.(check string) "render -q: no warning" "" e);
    Alcotest.test_case "render repeats check's warnings on stderr before rendering" `Quick
      (fun () ->
        let d = scene_dir "sphere { center: (0, 0, 0), radius: 1 }\n" in
        let ((_, out, e) as r) = lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.png" ] in
        check_status "render" 0 r;
        has "no lights" e "s.rts: warning: the scene has no lights";
        lacks "not on stdout" out "warning";
        let d = scene_dir "// only a comment\n" in
        let ((_, _, e) as r) = lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.png" ] in
        check_status "render an empty scene" 0 r;
        has "empty" e "s.rts: warning: the scene is empty (no statements)");
  ]

(* The row of [name] in check's estimate table, as words. *)
let row out name =
  match
    List.find_opt
      (fun l ->
        match String.split_on_char ' ' (String.trim l) with
        | w :: _ -> w = name
        | [] -> false)
      (String.split_on_char '\n' out)
  with
  | Some l -> List.filter (( <> ) "") (String.split_on_char ' ' (String.trim l))
  | None -> Alcotest.failf "no row %S in\n%s" name out

let cost_tests =
  [
    Alcotest.test_case "check --width and --height: the estimates at that size" `Quick
      (fun () ->
        let d =
          scene_dir
            "settings { width: 100, height: 50 }\n\
             light { position: (0, 5, 0) }\n\
             sphere { center: (0, 0, 0), radius: 1 }\n"
        in
        let ((_, out, _) as r) =
          lancer ~dir:d [ "check"; "s.rts"; "--width"; "200"; "--height"; "100" ]
        in
        check_status "check --width --height" 0 r;
        has "the size" out "image: 200×100";
        Alcotest.(check (list string))
          "as set: four times the primary rays"
          [ "as"; "set"; "20"; "k"; "40"; "k"; "40"; "k"; "(depth"; "5)"; "1" ]
          (row out "as");
        let ((_, out, _) as r) =
          lancer ~dir:d [ "check"; "s.rts"; "--json"; "--width"; "30" ]
        in
        check_status "check --json --width" 0 r;
        has "in the JSON" out "\"width\": 30");
    Alcotest.test_case
      "check estimates the rays of the scene and of each preset, and says it is an \
       estimate"
      `Quick (fun () ->
        (* 100×50 pixels, one point light and one area light of 3×3 samples: 5000 primary
           rays, each with 1 + 9 shadow rays; a mirror to depth 4 bounds it at 4×. *)
        let out =
          check_out
            {|settings { width: 100, height: 50, depth: 4 }
light { position: (0, 5, 0) }
light { position: (2, 5, 0), radius: 0.5, samples: 3 }
sphere { center: (0, 0, 0), radius: 1, material: material { reflection: 0.5 } }
|}
        in
        has "an estimate" out "rays, estimated before rendering";
        Alcotest.(check (list string))
          "as set"
          [ "as"; "set"; "5"; "k"; "55"; "k"; "220"; "k"; "(depth"; "4)"; "1" ]
          (row out "as");
        (* draft: 1 sample, hard shadows (1 + 1 shadow rays), depth 3 *)
        Alcotest.(check (list string))
          "draft"
          [ "draft"; "5"; "k"; "15"; "k"; "45"; "k"; "(depth"; "3)"; "0.273" ]
          (row out "draft");
        (* reference: 8×8 samples, area light at 8×8: 320 k primary, × (1 + 1 + 64) *)
        Alcotest.(check (list string))
          "reference"
          [ "reference"; "320"; "k"; "21.1"; "M"; "338"; "M"; "(depth"; "16)"; "384" ]
          (row out "reference");
        (* final refines adaptively: a range *)
        has "final is a range" (String.concat " " (row out "final")) "20 k–100 k");
    Alcotest.test_case
      "a render estimated above a billion rays says so before it starts; a small one \
       does not"
      `Quick (fun () ->
        let d =
          scene_dir
            "settings { width: 64, height: 64 }\n\
             for i in 0 to 63 { light { position: (i, 10, 0), radius: 1, samples: 64 } }\n"
        in
        let ((_, _, e) as r) = lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.png" ] in
        check_status "render" 0 r;
        has "the note" e "lancer: note: this render is estimated at up to 1.07 G rays";
        let ((_, _, e) as r) = lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.png"; "-q" ] in
        check_status "render -q" 0 r;
        Alcotest.(check string) "quiet" "" e;
        let d = scene_dir build_scene in
        let ((_, _, e) as r) = lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.png" ] in
        check_status "small render" 0 r;
        Alcotest.(check string) "no note" "" e);
  ]

(* Mistakes in code that does not run are found before the scene is evaluated. *)
let static_scene =
  {|settings { width: 16, height: 12 }
light { position: (0, 5, -5) }
sphere { center: (0, 0, 0), radius: 1 }
if false { sphere { center: (0, 0, 0), radiu: 1 } }
fn post(h) { cylinder { base: 0, top: (0, h, 0), radius: 0.1 } }
|}

let remove_dir d =
  Array.iter (fun f -> Sys.remove (Filename.concat d f)) (Sys.readdir d);
  Unix.rmdir d

let static_tests =
  [
    Alcotest.test_case
      "check and render report a mistake in a branch not taken or a macro never called"
      `Quick (fun () ->
        let d = scene_dir static_scene in
        Fun.protect
          ~finally:(fun () -> remove_dir d)
          (fun () ->
            let ((_, _, e) as r) = lancer ~dir:d [ "check"; "s.rts" ] in
            check_status "check" 1 r;
            has "the branch not taken" e
              ("s.rts:4:40: unknown field `radiu` in sphere; did you mean `radius`?\n\
                if false { sphere { center: (0, 0, 0), radiu: 1 } }\n"
             ^ String.make 39 ' ' ^ "^^^^^\n");
            has "the macro never called" e
              "s.rts:5:31: `base` must be a vector (x, y, z), got a number";
            let ((_, _, e) as r) = lancer ~dir:d [ "render"; "s.rts"; "-o"; "s.png" ] in
            check_status "render" 1 r;
            has "render reports it too" e "s.rts:4:40: unknown field `radiu`";
            Alcotest.(check bool)
              "no image" false
              (Sys.file_exists (Filename.concat d "s.png"))));
  ]

(* Which normals each mesh and height field is shaded with. *)
let normals_tests =
  [
    Alcotest.test_case "check says which normals each mesh and height field uses" `Quick
      (fun () ->
        let d =
          scene_dir
            "light { position: (0, 5, -5) }\n\
             mesh { file: \"bare.obj\" }\n\
             mesh { file: \"bare.obj\", smooth: false }\n\
             mesh { file: \"vn.obj\" }\n\
             height_field { file: \"h.ppm\", size: (1, 1, 1), smooth: true }\n"
        in
        let tri = "v 0 0 0\nv 1 0 0\nv 0 0 1\n" in
        write_file (Filename.concat d "bare.obj") (tri ^ "f 1 2 3\n");
        write_file (Filename.concat d "vn.obj") (tri ^ "vn 0 1 0\nf 1//1 2//1 3//1\n");
        write_file (Filename.concat d "h.ppm")
          "P6\n2 2\n255\n\000\000\000\001\001\001\002\002\002\003\003\003";
        let ((_, out, _) as r) = lancer ~dir:d [ "check"; "s.rts" ] in
        check_status "check" 0 r;
        has "computed" out
          "mesh: bare.obj, 1 triangle, normals computed from the faces (split at edges \
           sharper than 60°)";
        has "flat" out "mesh: bare.obj, 1 triangle, flat (smooth: false)";
        has "the file's" out "mesh: vn.obj, 1 triangle, normals from the file";
        has "height field" out
          "height field: h.ppm, 2×2 pixels, normals computed from the cells";
        let ((_, json, _) as r) = lancer ~dir:d [ "check"; "s.rts"; "--json" ] in
        check_status "check --json" 0 r;
        List.iter
          (fun n -> has "json" json (Printf.sprintf "\"normals\": \"%s\"" n))
          [ "computed"; "flat"; "file" ]);
  ]

(* The distinct materials a summary counts: materials that differ in their colour alone
   (as a loop makes them) are distinct; equal ones written apart, and a CSG leaf's equal
   to another object's, are one. *)
let materials_scene =
  {|settings { width: 16, height: 12 }
light { position: (0, 5, -5) }
// 3 colours over one base: 3 materials (their first, black, below again)
for i in 0 to 5 { sphere { center: (i, 0, 0), radius: 0.4,
                           material: material { color: (i % 3 / 3, 0, 0) } } }
// the default material, written out or not: 1 more
sphere { center: (0, 2, 0), radius: 0.4 }
sphere { center: (1, 2, 0), radius: 0.4, material: material { color: (1, 1, 1) } }
// another base, equal twice: 1 more
sphere { center: (2, 2, 0), radius: 0.4, material: material { color: (1, 0, 0), specular: 0.5 } }
sphere { center: (3, 2, 0), radius: 0.4, material: material { color: (1, 0, 0), specular: 0.5 } }
// its colour over the first base: 1 more
sphere { center: (4, 2, 0), radius: 0.4, material: material { color: (1, 0, 0) } }
// black again, its red a negative zero: none more
sphere { center: (5, 2, 0), radius: 0.4, material: material { color: (0 * -1, 0, 0) } }
// 300 colours, each ten times: 300 more (the table doubles as they come)
for k in 0 to 2999 { sphere { center: (k, -5, 0), radius: 0.1,
                              material: material { color: (k % 300 / 300, 0, 1) } } }
// a CSG object: its sphere's material is the loop's first (none more), its box takes
// the object's: 1 more
difference {
  sphere { center: (0, 4, 0), radius: 1, material: material { color: (0, 0, 0) } }
  box { min: (-0.5, 3.5, -2), max: (0.5, 4.5, 2) }
  material: material { color: (0, 1, 0) }
}
|}

(* The plain definition: the records Primitive.materials gives, equal when structurally
   equal. *)
let materials_by_records (sc : Lancer.Scene.t) =
  let seen = ref [] in
  Array.iter
    (fun o ->
      List.iter
        (fun m ->
          if not (List.exists (fun m' -> m' == m || m' = m) !seen) then seen := m :: !seen)
        (Lancer.Primitive.materials o))
    sc.objects;
  List.length !seen

let materials_tests =
  [
    Alcotest.test_case "check counts materials that differ in their colour alone" `Quick
      (fun () ->
        let d = scene_dir materials_scene in
        let ((_, out, _) as r) = lancer ~dir:d [ "check"; "s.rts" ] in
        check_status "check" 0 r;
        has "count" out "materials: 307 distinct");
    Alcotest.test_case "the count is that of the materials' records, scene by scene"
      `Quick (fun () ->
        let files = scene_files "../../scenes" [ "."; "gallery"; "materials" ] in
        let d = scene_dir materials_scene in
        List.iter
          (fun file ->
            match Lancer.Program.load_file file with
            | Error _ -> Alcotest.failf "%s does not load" file
            | Ok p -> (
                match Lancer.Program.scene ~index:false p ~time:0. ~frame:0 with
                | Error _ -> Alcotest.failf "%s does not compile" file
                | Ok sc ->
                    Alcotest.(check int)
                      (file ^ ": distinct materials")
                      (materials_by_records sc)
                      (Lancer.Compile.rendered (Lancer.Program.assets p) sc).r_materials))
          (Filename.concat d "s.rts" :: files);
        Alcotest.(check bool) "scenes read" true (List.length files > 10));
  ]

let () =
  Alcotest.run "check"
    [
      ("frames", frame_tests);
      ("times", time_tests);
      ("warnings", warning_tests);
      ("cost", cost_tests);
      ("static", static_tests);
      ("normals", normals_tests);
      ("materials", materials_tests);
    ]
