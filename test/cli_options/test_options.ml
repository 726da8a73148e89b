(* Every option a command lists does what it says or is refused: the options each
   command's help lists, and the refusals of those that make no sense there. *)

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"

open Run_lancer

let lancer ?(dir = Sys.getcwd ()) args = run ~exe ~dir args

let has msg s sub =
  Alcotest.(check bool) (Printf.sprintf "%s: %S in\n%s" msg sub s) true (contains s sub)

let lacks msg s sub =
  Alcotest.(check bool)
    (Printf.sprintf "%s: no %S in\n%s" msg sub s)
    false (contains s sub)

let still =
  {|settings { width: 24, height: 18 }
camera { position: (0, 1, -5), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0 }
sphere { center: (0, 1, 0), radius: 0.5 }
|}

let anim =
  {|settings { width: 24, height: 18 }
animation { fps: 10, frames: 4 }
camera { position: (0, 1, -5), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0 }
sphere { center: (0, 1 + time, 0), radius: 0.5 }
|}

(* An image a command wrote in the directory d. *)
let read_image d p =
  match Lancer.Image.read_rgb8 (Filename.concat d p) with
  | Ok i -> i
  | Error m -> Alcotest.fail m

let scenes () =
  let d = tmpdir "lancer-options" in
  write_file (Filename.concat d "s.rts") still;
  write_file (Filename.concat d "a.rts") anim;
  d

(* The long names of the options a command's --help lists. *)
let listed args =
  let _, out, _ = lancer (args @ [ "--help=plain" ]) in
  String.split_on_char '\n' out
  |> List.filter_map (fun line ->
         let t = String.trim line in
         if
           String.length line > 7
           && String.sub line 0 7 = "       "
           && String.length t > 1
           && t.[0] = '-'
         then
           let words = String.split_on_char ' ' t in
           List.find_map
             (fun w ->
               let w =
                 match String.index_opt w '=' with
                 | Some i -> String.sub w 0 i
                 | None -> w
               in
               let w =
                 match String.index_opt w '[' with
                 | Some i -> String.sub w 0 i
                 | None -> w
               in
               let w =
                 if String.ends_with ~suffix:"," w then
                   String.sub w 0 (String.length w - 1)
                 else w
               in
               if String.length w > 2 && String.sub w 0 2 = "--" then Some w else None)
             words
         else None)
  |> List.filter (fun o -> o <> "--help" && o <> "--version")
  |> List.sort_uniq compare

let render_options =
  [
    "--alpha";
    "--aov";
    "--bits";
    "--crop";
    "--depth";
    "--domains";
    "--format";
    "--frame";
    "--height";
    "--max-error";
    "--metric";
    "--output";
    "--progress";
    "--quality";
    "--quiet";
    "--region";
    "--resume";
    "--samples";
    "--stats";
    "--time";
    "--width";
  ]

let help_tests =
  [
    Alcotest.test_case "each command lists the options it acts on, and only those" `Quick
      (fun () ->
        let check args expected =
          Alcotest.(check (list string))
            (String.concat " " args) (List.sort compare expected) (listed args)
        in
        check [ "render" ] render_options;
        check [ "animate" ]
          [
            "--bits";
            "--depth";
            "--domains";
            "--format";
            "--frames";
            "--height";
            "--max-error";
            "--metric";
            "--output";
            "--progress";
            "--quality";
            "--quiet";
            "--resume";
            "--samples";
            "--shard";
            "--video";
            "--width";
          ];
        check [ "golden" ]
          [
            "--depth";
            "--domains";
            "--frame";
            "--height";
            "--max-share";
            "--metric";
            "--progress";
            "--quality";
            "--quiet";
            "--samples";
            "--time";
            "--tolerance";
            "--update";
            "--width";
          ];
        check [ "diff" ]
          [ "--json"; "--max-share"; "--metric"; "--output"; "--tolerance" ];
        check [ "bench"; "domains" ]
          [
            "--counts";
            "--depth";
            "--frame";
            "--height";
            "--json";
            "--quality";
            "--repeat";
            "--samples";
            "--time";
            "--width";
          ];
        check [ "bench"; "quality" ]
          [
            "--depth";
            "--domains";
            "--fresh";
            "--height";
            "--json";
            "--samples";
            "--svg";
            "--width";
          ]);
    Alcotest.test_case "the scene argument and -o say what they are in each command"
      `Quick (fun () ->
        (* The text with its line breaks and indentation as single spaces. *)
        let help args =
          let _, out, _ = lancer (args @ [ "--help=plain" ]) in
          String.concat " "
            (List.filter (( <> ) "")
               (String.split_on_char ' '
                  (String.map (function '\n' -> ' ' | c -> c) out)))
        in
        let r = help [ "render" ] in
        has "render" r "Without one, the built-in showcase is rendered";
        has "render" r "Output image (.png or .ppm)";
        lacks "render -o" r "for animate";
        let a = help [ "animate" ] in
        has "animate" a "SCENE.rts (required)";
        has "animate" a "it needs an animation block";
        has "animate" a "Directory for the frames";
        lacks "animate" a "showcase";
        let g = help [ "golden" ] in
        has "golden" g "SCENE.rts (required)";
        has "golden" g "The scene to render and compare with GOLDEN.png";
        lacks "golden" g "showcase";
        lacks "golden" g "Output image";
        has "render" r "-: read it from standard input";
        has "check" (help [ "check" ]) "-: read it from standard input";
        let b = help [ "bench"; "domains" ] in
        has "bench" b "The scene to measure";
        lacks "bench" b "Output image");
  ]

let refusal_tests =
  [
    Alcotest.test_case "animate refuses --time and --stats instead of ignoring them"
      `Quick (fun () ->
        let d = scenes () in
        List.iter
          (fun (opt, v) ->
            let ((_, _, e) as r) =
              lancer ~dir:d [ "animate"; "a.rts"; "-o"; "out"; opt; v ]
            in
            check_status opt 1 r;
            has opt e (Printf.sprintf "unknown option '%s'" opt))
          [ ("--time", "1"); ("--stats", "st.json") ];
        Alcotest.(check bool)
          "no frames, no statistics" false
          (Sys.file_exists (Filename.concat d "out")
          || Sys.file_exists (Filename.concat d "st.json")));
    Alcotest.test_case "golden refuses -o and --stats, which it never wrote" `Quick
      (fun () ->
        let d = scenes () in
        List.iter
          (fun (opt, v) ->
            let ((_, _, e) as r) =
              lancer ~dir:d [ "golden"; "s.rts"; "g.png"; opt; v; "--update" ]
            in
            check_status opt 1 r;
            has opt e (Printf.sprintf "unknown option '%s'" opt))
          [ ("-o", "x.png"); ("--stats", "st.json") ];
        Alcotest.(check (list string))
          "nothing written" [ "a.rts"; "s.rts" ]
          (List.sort compare (Array.to_list (Sys.readdir d))));
    Alcotest.test_case "golden and animate need a scene: the usage says so" `Quick
      (fun () ->
        let ((_, _, e) as r) = lancer [ "golden" ] in
        check_status "golden" 1 r;
        has "golden" e "SCENE.rts";
        let ((_, _, e) as r) = lancer [ "animate"; "-o"; "out" ] in
        check_status "animate" 1 r;
        has "animate" e "required argument SCENE.rts is missing");
    Alcotest.test_case
      "render --frame K: beyond the animation or on a still it is refused" `Quick
      (fun () ->
        let d = scenes () in
        let ((_, _, e) as r) =
          lancer ~dir:d [ "render"; "a.rts"; "--frame"; "4"; "-o"; "f.png" ]
        in
        check_status "past the end" 1 r;
        has "past the end" e "--frame 4: the animation has frames 0..3";
        let ((_, _, e) as r) =
          lancer ~dir:d [ "render"; "s.rts"; "--frame"; "1"; "-o"; "f.png" ]
        in
        check_status "a still" 1 r;
        has "a still" e "no animation block";
        has "a still" e "--time";
        Alcotest.(check bool)
          "no image" false
          (Sys.file_exists (Filename.concat d "f.png"));
        (* The last frame is frame 3, at time 0.3: the same image as --time 0.3. *)
        check_status "last frame" 0
          (lancer ~dir:d [ "render"; "a.rts"; "--frame"; "3"; "-o"; "f.png"; "-q" ]);
        check_status "its time" 0
          (lancer ~dir:d [ "render"; "a.rts"; "--time"; "0.3"; "-o"; "t.png"; "-q" ]);
        check_status "frame 0" 0
          (lancer ~dir:d [ "render"; "a.rts"; "-o"; "z.png"; "-q" ]);
        let f = read_file (Filename.concat d "f.png") in
        Alcotest.(check bool)
          "frame 3 is at time 0.3" true
          (f = read_file (Filename.concat d "t.png"));
        Alcotest.(check bool)
          "and not at time 0" false
          (f = read_file (Filename.concat d "z.png")));
    Alcotest.test_case
      "golden --quiet prints nothing when it passes; --progress reports tiles" `Quick
      (fun () ->
        let d = scenes () in
        check_status "update" 0 (lancer ~dir:d [ "golden"; "s.rts"; "g.png"; "--update" ]);
        let ((_, out, e) as r) = lancer ~dir:d [ "golden"; "s.rts"; "g.png"; "-q" ] in
        check_status "quiet" 0 r;
        Alcotest.(check string) "quiet: no output" "" (out ^ e);
        let ((_, out, _) as r) = lancer ~dir:d [ "golden"; "s.rts"; "g.png" ] in
        check_status "same" 0 r;
        has "not quiet" out "same as g.png";
        let ((_, _, e) as r) =
          lancer ~dir:d [ "golden"; "s.rts"; "g.png"; "--progress" ]
        in
        check_status "progress" 0 r;
        has "progress" e "tiles 1/1 (100%)";
        (* A difference is reported even with --quiet. *)
        let ((_, out, _) as r) =
          lancer ~dir:d [ "golden"; "a.rts"; "g.png"; "-q"; "--time"; "0.3" ]
        in
        check_status "different" 1 r;
        has "different, quiet" out "differs from g.png");
  ]

let diff_tests =
  [
    Alcotest.test_case
      "diff refuses a tolerance outside 0..255 or its metric's range, a metric without \
       its limit, and a share outside 0..1"
      `Quick (fun () ->
        let d = scenes () in
        check_status "render" 0 (lancer ~dir:d [ "render"; "s.rts"; "-o"; "a.png"; "-q" ]);
        List.iter
          (fun (args, msg) ->
            let ((_, out, e) as r) =
              lancer ~dir:d ([ "diff"; "a.png"; "a.png" ] @ args)
            in
            check_status (String.concat " " args) 1 r;
            has (String.concat " " args) e msg;
            Alcotest.(check string) "no figures" "" out)
          [
            ([ "--tolerance"; "300" ], "--tolerance must be between 0 and 255 (got 300)");
            ([ "--tolerance=-1" ], "--tolerance must be between 0 and 255 (got -1)");
            ([ "--max-share"; "2" ], "--max-share must be between 0 and 1 (got 2)");
            ([ "--max-share"; "nan" ], "--max-share must be between 0 and 1");
            ([ "--max-share=-0.5" ], "--max-share must be between 0 and 1 (got -0.5)");
            ( [ "--metric"; "flip" ],
              "--metric flip needs --tolerance: the largest mean FLIP (0–1)" );
            ([ "--metric"; "ssim" ], "--metric ssim needs --tolerance");
            ( [ "--metric"; "flip"; "--tolerance"; "1.5" ],
              "--tolerance: a mean FLIP limit must be between 0 and 1 (got 1.5)" );
            ( [ "--metric"; "ssim"; "--tolerance"; "2" ],
              "--tolerance: an SSIM limit must be between -1 and 1 (got 2)" );
            ( [ "--metric"; "rmse"; "--tolerance=-1" ],
              "--tolerance: an RMSE limit must be between 0 and 255 (got -1)" );
            ( [ "--tolerance"; "0.5" ],
              "--tolerance must be a whole number between 0 and 255 (got 0.5)" );
            ([ "--metric"; "lpips" ], "invalid value 'lpips'");
          ];
        let ((_, _, e) as r) =
          lancer ~dir:d [ "golden"; "s.rts"; "g.png"; "--update"; "--tolerance"; "256" ]
        in
        check_status "golden" 1 r;
        has "golden" e "--tolerance must be between 0 and 255";
        Alcotest.(check bool)
          "no golden written" false
          (Sys.file_exists (Filename.concat d "g.png")));
    Alcotest.test_case "diff says same, within tolerance or differ before its figures"
      `Quick (fun () ->
        let d = scenes () in
        check_status "a" 0 (lancer ~dir:d [ "render"; "s.rts"; "-o"; "a.png"; "-q" ]);
        check_status "b" 0
          (lancer ~dir:d [ "render"; "a.rts"; "-o"; "b.png"; "-q"; "--time"; "0.3" ]);
        let ((_, out, _) as r) = lancer ~dir:d [ "diff"; "a.png"; "a.png" ] in
        check_status "same" 0 r;
        has "same" out "same: max difference 0/255";
        let ((_, out, _) as r) = lancer ~dir:d [ "diff"; "a.png"; "b.png" ] in
        check_status "differ" 1 r;
        has "differ" out "differ: max difference";
        let ((_, out, _) as r) =
          lancer ~dir:d [ "diff"; "a.png"; "b.png"; "--tolerance"; "255" ]
        in
        check_status "within" 0 r;
        has "within" out "within tolerance: max difference";
        let ((_, out, _) as r) =
          lancer ~dir:d [ "diff"; "a.png"; "b.png"; "--max-share"; "1" ]
        in
        check_status "within a share" 0 r;
        has "within a share" out "within tolerance: ");
    Alcotest.test_case "diff --metric judges by the metric, within its limit" `Quick
      (fun () ->
        let d = scenes () in
        check_status "a" 0 (lancer ~dir:d [ "render"; "s.rts"; "-o"; "a.png"; "-q" ]);
        check_status "b" 0
          (lancer ~dir:d [ "render"; "a.rts"; "-o"; "b.png"; "-q"; "--time"; "0.3" ]);
        let figures m =
          let ((_, out, _) as r) = lancer ~dir:d [ "diff"; "a.png"; "b.png"; "--json" ] in
          check_status "json" 1 r;
          let j = Yojson.Safe.from_string out in
          Yojson.Safe.Util.(j |> member m |> to_number)
        in
        let flip = figures "flip" and ssim = figures "ssim" in
        Alcotest.(check bool) "a FLIP between 0 and 1" true (flip > 0. && flip < 1.);
        Alcotest.(check bool) "an SSIM under 1" true (ssim < 1.);
        let judged metric limit =
          lancer ~dir:d
            [
              "diff";
              "a.png";
              "b.png";
              "--metric";
              metric;
              "--tolerance";
              Printf.sprintf "%.6f" limit;
            ]
        in
        let ((_, out, _) as r) = judged "flip" (flip +. 0.001) in
        check_status "flip within" 0 r;
        has "flip within" out "within tolerance (mean FLIP";
        let ((_, out, _) as r) = judged "flip" (flip -. 0.001) in
        check_status "flip over" 1 r;
        has "flip over" out "differ (mean FLIP";
        check_status "ssim within" 0 (judged "ssim" (ssim -. 0.001));
        let ((_, out, _) as r) = judged "ssim" (ssim +. 0.001) in
        check_status "ssim under" 1 r;
        has "ssim under" out "differ (SSIM";
        check_status "rmse within" 0 (judged "rmse" 255.);
        check_status "psnr under" 1 (judged "psnr" 1000.);
        (* The same images by the per-channel tolerance differ: the metric decided. *)
        check_status "max" 1 (lancer ~dir:d [ "diff"; "a.png"; "b.png" ]);
        let ((_, out, _) as r) = lancer ~dir:d [ "diff"; "a.png"; "a.png"; "--json" ] in
        check_status "same, json" 0 r;
        let j = Yojson.Safe.from_string out in
        let open Yojson.Safe.Util in
        Alcotest.(check string) "verdict" "same" (j |> member "verdict" |> to_string);
        Alcotest.(check (float 0.)) "no FLIP" 0. (j |> member "flip" |> to_number);
        Alcotest.(check (float 0.)) "SSIM 1" 1. (j |> member "ssim" |> to_number);
        Alcotest.(check bool) "PSNR null" true (j |> member "psnr" = `Null));
    Alcotest.test_case "diff --metric ssim needs images of 11×11 pixels or more" `Quick
      (fun () ->
        let d = scenes () in
        (* SSIM needs an 11×11 window. *)
        check_status "tiny" 0
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "t.png"; "-q"; "-W"; "8"; "-H"; "6" ]);
        let ((_, out, e) as r) =
          lancer ~dir:d
            [ "diff"; "t.png"; "t.png"; "--metric"; "ssim"; "--tolerance"; "0.9" ]
        in
        check_status "tiny ssim" 1 r;
        has "tiny ssim" e "SSIM needs images of at least 11×11 pixels (these are 8×6)";
        Alcotest.(check string) "no figures" "" out;
        let ((_, out, _) as r) = lancer ~dir:d [ "diff"; "t.png"; "t.png" ] in
        check_status "tiny, max" 0 r;
        has "tiny, max" out "SSIM undefined (under 11×11 pixels)");
    Alcotest.test_case "golden --metric judges the render by the metric" `Quick (fun () ->
        let d = scenes () in
        check_status "update" 0
          (lancer ~dir:d [ "golden"; "a.rts"; "g.png"; "--update"; "-q" ]);
        let moved args =
          lancer ~dir:d ([ "golden"; "a.rts"; "g.png"; "--time"; "0.05" ] @ args)
        in
        check_status "per channel" 1 (moved []);
        let ((_, out, _) as r) = moved [ "--metric"; "flip"; "--tolerance"; "0.5" ] in
        check_status "flip" 0 r;
        has "flip" out "within tolerance of g.png";
        has "flip" out "; mean FLIP";
        let ((_, out, _) as r) = moved [ "--metric"; "psnr"; "--tolerance"; "99" ] in
        check_status "psnr" 1 r;
        has "psnr" out "; PSNR";
        has "psnr" out "< 99 dB";
        let g = read_image d "g.png" and a = read_image d "g.actual.png" in
        let _, _, m = read_image d "g.diff.png" in
        Alcotest.(check bool)
          "FLIP's map" true
          (Bytes.equal m (Lancer.Compare.flip_image g a));
        let ((_, _, e) as r) = moved [ "--metric"; "ssim" ] in
        check_status "no limit" 1 r;
        has "no limit" e "--metric ssim needs --tolerance");
    Alcotest.test_case "diff -o writes FLIP's error map in grey" `Quick (fun () ->
        let d = scenes () in
        check_status "a" 0 (lancer ~dir:d [ "render"; "s.rts"; "-o"; "a.png"; "-q" ]);
        check_status "b" 0
          (lancer ~dir:d [ "render"; "a.rts"; "-o"; "b.png"; "-q"; "--time"; "0.3" ]);
        let ((_, out, _) as r) =
          lancer ~dir:d [ "diff"; "a.png"; "b.png"; "-o"; "m.png" ]
        in
        check_status "diff" 1 r;
        has "named" out "FLIP error map: m.png";
        let a = read_image d "a.png" and b = read_image d "b.png" in
        let _, _, m = read_image d "m.png" in
        Alcotest.(check bool)
          "the map of Flip" true
          (Bytes.equal m (Lancer.Flip.grey (Lancer.Flip.error_map a b)));
        Alcotest.(check bool) "not black" true (Bytes.exists (fun c -> c <> '\000') m);
        check_status "same" 0 (lancer ~dir:d [ "diff"; "a.png"; "a.png"; "-o"; "z.png" ]);
        let _, _, z = read_image d "z.png" in
        Alcotest.(check bool) "black" true (Bytes.for_all (fun c -> c = '\000') z));
    Alcotest.test_case
      "a golden of another size: which is the golden, and --width/--height" `Quick
      (fun () ->
        let d = scenes () in
        check_status "update" 0
          (lancer ~dir:d
             [ "golden"; "s.rts"; "g.png"; "--update"; "--width"; "16"; "--height"; "12" ]);
        let ((_, _, e) as r) = lancer ~dir:d [ "golden"; "s.rts"; "g.png" ] in
        check_status "size" 1 r;
        has "size" e "the golden g.png is 16×12 but the render would be 24×18";
        has "size" e "--width 16 --height 12";
        Alcotest.(check bool)
          "no actual image" false
          (Sys.file_exists (Filename.concat d "g.actual.png"));
        check_status "at the golden's size" 0
          (lancer ~dir:d
             [ "golden"; "s.rts"; "g.png"; "--width"; "16"; "--height"; "12" ]);
        (* The library says which image is the golden too (lancer-alcotest's message). *)
        match
          Lancer.Compare.golden ~update:false ~golden:(Filename.concat d "g.png")
            (24, 18, Bytes.make (24 * 18 * 3) '\000')
        with
        | Error m -> has "library" m "g.png is 16×12 but the image is 24×18"
        | Ok _ -> Alcotest.fail "a golden of another size passed");
    Alcotest.test_case "diff names the images of different sizes, and one it cannot read"
      `Quick (fun () ->
        let d = scenes () in
        check_status "a" 0 (lancer ~dir:d [ "render"; "s.rts"; "-o"; "a.png"; "-q" ]);
        check_status "b" 0
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "b.png"; "-q"; "--width"; "16" ]);
        let ((_, _, e) as r) = lancer ~dir:d [ "diff"; "a.png"; "b.png" ] in
        check_status "sizes" 1 r;
        has "sizes" e "a.png is 24×18 but b.png is 16×18";
        write_file (Filename.concat d "t.png") "not an image\n";
        let ((_, out, e) as r) =
          lancer ~dir:d
            [ "diff"; "a.png"; "t.png"; "--metric"; "flip"; "--tolerance"; "0.1" ]
        in
        check_status "unreadable" 1 r;
        has "unreadable" e "lancer: t.png: not a PNG file";
        Alcotest.(check string) "no figures" "" out);
    Alcotest.test_case "a negative value after an option gets a hint to write --time=-5"
      `Quick (fun () ->
        let d = scenes () in
        let ((_, _, e) as r) =
          lancer ~dir:d [ "render"; "a.rts"; "--time"; "-5"; "-o"; "n.png" ]
        in
        check_status "--time -5" 1 r;
        has "--time -5" e "--time=-5";
        let ((_, _, e) as r) = lancer ~dir:d [ "check"; "a.rts"; "-t"; "-0.5" ] in
        check_status "-t -0.5" 1 r;
        has "-t -0.5" e "-t-0.5";
        check_status "--time=-5" 0
          (lancer ~dir:d [ "render"; "a.rts"; "--time=-5"; "-o"; "n.png"; "-q" ]);
        let ((_, _, e) as r) = lancer ~dir:d [ "render"; "a.rts"; "--widht"; "5" ] in
        check_status "no negative value" 1 r;
        lacks "no negative value" e "negative");
  ]

(* lancer with [input] on its standard input; (status, stdout, stderr). *)
let lancer_stdin ~dir ~input args =
  let inp = Filename.concat dir ".stdin"
  and out = Filename.concat dir ".out"
  and err = Filename.concat dir ".err" in
  write_file inp input;
  let cmd =
    Printf.sprintf "cd %s && %s %s <%s >%s 2>%s" (Filename.quote dir) (Filename.quote exe)
      (String.concat " " (List.map Filename.quote args))
      (Filename.quote inp) (Filename.quote out) (Filename.quote err)
  in
  let st = Sys.command cmd in
  let r = (st, read_file out, read_file err) in
  List.iter Sys.remove [ inp; out; err ];
  r

let stdin_tests =
  [
    Alcotest.test_case "render - and check - read the scene from standard input" `Quick
      (fun () ->
        let d = scenes () in
        let ((_, out, _) as r) = lancer_stdin ~dir:d ~input:still [ "check"; "-" ] in
        check_status "check -" 0 r;
        has "check -" out "scene: <stdin>";
        has "check -" out "objects: 2";
        check_status "render -" 0
          (lancer_stdin ~dir:d ~input:still [ "render"; "-"; "-o"; "in.png"; "-q" ]);
        check_status "render the file" 0
          (lancer ~dir:d [ "render"; "s.rts"; "-o"; "file.png"; "-q" ]);
        Alcotest.(check bool)
          "the same image" true
          (pixels (Filename.concat d "in.png") = pixels (Filename.concat d "file.png"));
        check_status "animate -" 0
          (lancer_stdin ~dir:d ~input:anim
             [ "animate"; "-"; "-o"; "frames"; "-q"; "--frames"; "3" ]);
        check_status "render --frame 3" 0
          (lancer ~dir:d [ "render"; "a.rts"; "--frame"; "3"; "-o"; "f3.png"; "-q" ]);
        Alcotest.(check bool)
          "frame 3 the same" true
          (pixels (Filename.concat d "frames/frame_0003.png")
          = pixels (Filename.concat d "f3.png")));
    Alcotest.test_case "a scene from standard input needs -o" `Quick (fun () ->
        let d = scenes () in
        let ((_, _, e) as r) = lancer_stdin ~dir:d ~input:still [ "render"; "-" ] in
        check_status "no -o" 1 r;
        has "no -o" e "-o FILE";
        Alcotest.(check bool)
          "no -.png" false
          (Sys.file_exists (Filename.concat d "-.png")));
    Alcotest.test_case
      "errors of a scene on standard input are located in <stdin>, with the line and a \
       caret"
      `Quick (fun () ->
        let d = scenes () in
        let ((_, _, e) as r) =
          lancer_stdin ~dir:d ~input:"sphere { center: (0, 0, 0), radius: -1 }\n"
            [ "check"; "-" ]
        in
        check_status "bad" 1 r;
        has "bad" e "<stdin>:1:";
        has "bad" e "sphere { center: (0, 0, 0), radius: -1 }";
        has "bad" e "^");
    Alcotest.test_case
      "includes of a scene on standard input are found from the current directory" `Quick
      (fun () ->
        let d = scenes () in
        Unix.mkdir (Filename.concat d "inc") 0o755;
        write_file (Filename.concat d "inc/col.rts") "let c = (0.1, 0.9, 0.1)\n";
        write_file (Filename.concat d "inc/bad.rts") "let c = (0.1, 0.9\n";
        let scene inc =
          Printf.sprintf
            "include \"%s\"\n\
             %ssphere { center: (1, 1, 0), radius: 0.3, material: material { color: c } }\n"
            inc still
        in
        check_status "include" 0
          (lancer_stdin ~dir:d ~input:(scene "inc/col.rts")
             [ "render"; "-"; "-o"; "i.png"; "-q" ]);
        write_file (Filename.concat d "i.rts") (scene "inc/col.rts");
        check_status "from a file" 0
          (lancer ~dir:d [ "render"; "i.rts"; "-o"; "j.png"; "-q" ]);
        Alcotest.(check bool)
          "the same image" true
          (pixels (Filename.concat d "i.png") = pixels (Filename.concat d "j.png"));
        let ((_, _, e) as r) =
          lancer_stdin ~dir:d ~input:(scene "inc/bad.rts") [ "check"; "-" ]
        in
        check_status "bad include" 1 r;
        has "bad include" e "inc/bad.rts:";
        let ((_, _, e) as r) =
          lancer_stdin ~dir:d ~input:(scene "nope.rts") [ "check"; "-" ]
        in
        check_status "missing include" 1 r;
        has "missing include" e "<stdin>:1:";
        has "missing include" e "nope.rts");
  ]

let () =
  Alcotest.run "options"
    [
      ("help", help_tests);
      ("refusals", refusal_tests);
      ("diff", diff_tests);
      ("stdin", stdin_tests);
    ]
