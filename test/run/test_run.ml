(* The commands' pipelines called as library functions: the pixels they write are those
   of the library's own steps (load, evaluate, compile, render, encode; their files add
   the image's record), and what they refuse they refuse before any work. *)
open Lancer

let tmpdir () =
  let d = Filename.temp_dir "lancer-run-test" "" in
  at_exit (fun () -> ignore (Sys.command ("rm -rf " ^ Filename.quote d)));
  d

let write path text = Out_channel.with_open_bin path (fun oc -> output_string oc text)
let read path = In_channel.with_open_bin path In_channel.input_all

(* The samples of a PNG file's contents. *)
let pixels png = Bytes.to_string (Result.get_ok (Png.decode png)).samples

let user_error name f =
  match f () with
  | _ -> Alcotest.failf "%s: expected a user error" name
  | exception Job_error.User _ -> ()

let still_text =
  {|settings { width: 40, height: 36, samples: 2 }
camera { position: (0, 1, -5), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0 }
sphere { center: (0, 1, 0), radius: 1, material: material { color: (0.9, 0.2, 0.2) } }
|}

let anim_text =
  {|settings { width: 24, height: 16 }
animation { fps: 10, frames: 5 }
camera { position: (0, 1, -5), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0 }
sphere { center: (time, 1, 0), radius: 0.5 }
|}

(* The image the library's own steps make of a scene file at a time, written to [out]. *)
let by_steps ?(width = 0) file ~time ~frame out =
  let prog =
    match Program.load_file file with
    | Ok p -> p
    | Error _ -> Alcotest.fail "the scene does not load"
  in
  let sc =
    match Program.scene_at prog ~time ~frame with
    | Ok sc -> sc
    | Error _ -> Alcotest.fail "the scene does not evaluate"
  in
  let sc =
    if width = 0 then sc
    else Overrides.apply { Overrides.none with width = Some width } sc
  in
  let fb, _ = Render.render sc in
  ignore (Files.write_image out sc fb);
  read out

let still () =
  let d = tmpdir () in
  let scene = Filename.concat d "s.rts" and out = Filename.concat d "s.png" in
  write scene still_text;
  let stats = Filename.concat d "s.json" in
  let o =
    {
      Options.default with
      scene = Some scene;
      output = Some out;
      width = Some 30;
      stats = Some stats;
      quiet = true;
      domains = Some 2;
    }
  in
  Still_run.run o ~resume:false Output.default_encoding;
  Alcotest.(check bool)
    "the bytes of load, evaluate, render, encode" true
    (pixels (read out)
    = pixels (by_steps ~width:30 scene ~time:0. ~frame:0 (Filename.concat d "ref.png")));
  let j = Yojson.Safe.from_file stats in
  let open Yojson.Safe.Util in
  Alcotest.(check int) "statistics: the width" 30 (j |> member "width" |> to_int);
  Alcotest.(check int)
    "statistics: one primary ray per sample"
    (30 * 36 * 4)
    (j |> member "rays" |> member "primary" |> to_int);
  (* With a checkpoint, the same bytes, and the checkpoint gone after. *)
  let again = Filename.concat d "again.png" in
  Still_run.run
    { o with output = Some again; stats = None }
    ~resume:true Output.default_encoding;
  Alcotest.(check bool) "resumable: the same bytes" true (read again = read out);
  Alcotest.(check bool)
    "the checkpoint is removed" false
    (Sys.file_exists (again ^ ".checkpoint"));
  user_error "an output over the scene" (fun () ->
      Still_run.run { o with output = Some scene } ~resume:false Output.default_encoding);
  user_error "--stats named like an image" (fun () ->
      Still_run.run { o with stats = Some out } ~resume:false Output.default_encoding)

let built () =
  let d = tmpdir () in
  let scene = Filename.concat d "a.rts" in
  write scene anim_text;
  let b = Still_run.build { Options.default with scene = Some scene; frame = Some 3 } in
  Alcotest.(check (pair (float 1e-12) int)) "frame 3's time" (0.3, 3) (b.time, b.frame);
  Alcotest.(check int) "the scene's width" 24 b.scene.settings.width;
  Alcotest.(check (option (pair (float 0.) int)))
    "the program's animation"
    (Some (10., 5))
    b.source.animation

let frames () =
  let d = tmpdir () in
  let scene = Filename.concat d "a.rts" and dir = Filename.concat d "frames" in
  write scene anim_text;
  let o = { Options.default with scene = Some scene; output = Some dir; quiet = true } in
  Frames_run.run o Frames_run.default_options;
  for k = 0 to 4 do
    let f = Filename.concat dir (Printf.sprintf "frame_%04d.png" k) in
    Alcotest.(check bool)
      (Printf.sprintf "frame %d is that frame's still" k)
      true
      (pixels (read f)
      = pixels
          (by_steps scene
             ~time:(Float.of_int k /. 10.)
             ~frame:k
             (Filename.concat d (Printf.sprintf "ref%d.png" k))))
  done;
  let _, p =
    Frames_run.plan o { Frames_run.default_options with resume = true; frames = None }
  in
  Alcotest.(check int) "resumed: nothing left to do" 0 (List.length p.todo);
  Alcotest.(check int) "resumed: every frame kept" 5 p.resumed

let check () =
  Alcotest.(check string) "runs" "0..2, 5, 7..8" (Check_run.runs [ 0; 1; 2; 5; 7; 8 ]);
  let d = tmpdir () in
  let scene = Filename.concat d "a.rts" in
  write scene anim_text;
  let prog = Scene_file.load (Some scene) in
  Alcotest.(check (triple (float 0.) int int))
    "all the frames" (10., 0, 4) (Check_run.frames prog "all");
  Alcotest.(check (triple (float 0.) int int))
    "a range" (10., 1, 3)
    (Check_run.frames prog "1..3");
  user_error "past the last frame" (fun () -> Check_run.frames prog "2..9")

let compare () =
  let d = tmpdir () in
  let scene = Filename.concat d "s.rts" in
  write scene still_text;
  let golden = Filename.concat d "golden.png" in
  let o = { Options.default with scene = Some scene; quiet = true; width = Some 20 } in
  Alcotest.(check bool)
    "golden written" true
    (Compare_run.golden o ~golden ~tolerance:1 ~share:0. ~update:true);
  Alcotest.(check bool)
    "the same render matches" true
    (Compare_run.golden o ~golden ~tolerance:1 ~share:0. ~update:false);
  Alcotest.(check bool)
    "an image is within tolerance of itself" true
    (Compare_run.diff ~metric:Max ~tolerance:(Some 0.) ~share:0. golden golden);
  Alcotest.(check bool)
    "and of mean FLIP 0" true
    (Compare_run.diff ~metric:Flip ~tolerance:(Some 0.) ~share:0. golden golden);
  user_error "a golden of another size" (fun () ->
      Compare_run.golden { o with width = Some 10 } ~golden ~tolerance:1 ~share:0.
        ~update:false);
  user_error "a tolerance past 255" (fun () -> Compare_run.check_tolerance 256 0.)

let scene_file () =
  let name, text = Scene_file.read None in
  Alcotest.(check string) "the showcase's name" "showcase.rts" name;
  Alcotest.(check bool) "its text" true (text == Scene_file.showcase);
  Alcotest.(check string)
    "its image's name" "showcase.png"
    (Scene_file.default_output Options.default);
  user_error "a missing scene" (fun () -> Scene_file.read (Some "/nonexistent/x.rts"));
  user_error "standard input has no name for the image" (fun () ->
      Scene_file.default_output { Options.default with scene = Some "-" })

(* The progress line's figures: the time left from the share of the work done. *)
let progress_line () =
  let line = Progress.line ~label:"tiles" ~total:4 ~elapsed:10. in
  Alcotest.(check string)
    "a quarter of equal units in 10 s: 30 s left"
    "tiles 1/4 ( 25%)  0.1 tiles/s  elapsed 10s  left 30s" (line ~done_:1 ~rays:0 ());
  Alcotest.(check string)
    "units of unequal cost: the share decides"
    "tiles 1/4 ( 50%)  1.00 M rays/s  elapsed 10s  left 10s"
    (line ~done_:1 ~share:0.5 ~rays:10_000_000 ());
  Alcotest.(check string)
    "nothing done yet: no estimate" "tiles 0/4 (  0%)  0.0 tiles/s  elapsed 10s  left ?"
    (line ~done_:0 ~rays:0 ());
  Alcotest.(check string)
    "minutes and hours" "2m05s 1h03m"
    (Progress.hms 125. ^ " " ^ Progress.hms 3800.)

(* LANCER_PROGRESS_INTERVAL: seconds, or off. *)
let progress_interval () =
  let with_value v =
    Unix.putenv Progress.interval_variable v;
    Progress.interval ~default:5.
  in
  Alcotest.(check (option (float 0.))) "a number of seconds" (Some 0.5) (with_value "0.5");
  Alcotest.(check (option (float 0.))) "off" None (with_value "off");
  Alcotest.(check (option (float 0.)))
    "not a number: the default" (Some 5.) (with_value "x");
  Alcotest.(check (option (float 0.))) "negative: the default" (Some 5.) (with_value "-1")

let () =
  Alcotest.run "run"
    [
      ( "still",
        [
          Alcotest.test_case "lancer render as a function: the bytes of its steps" `Quick
            still;
          Alcotest.test_case "a still's scene, built at a frame" `Quick built;
        ] );
      ( "frames",
        [ Alcotest.test_case "lancer animate as a function, and resumed" `Quick frames ]
      );
      ( "check and compare",
        [
          Alcotest.test_case "frames named and runs written" `Quick check;
          Alcotest.test_case "golden and diff" `Quick compare;
        ] );
      ("scene file", [ Alcotest.test_case "the showcase and errors" `Quick scene_file ]);
      ( "progress",
        [
          Alcotest.test_case "the time left, from the share done" `Quick progress_line;
          Alcotest.test_case "the interval between lines, or off" `Quick progress_interval;
        ] );
    ]
