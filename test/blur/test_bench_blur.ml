(* Motion blur from the command line: lancer bench quality measures it (a "shutter
   samples" row per number of instants, whose error against the reference falls as they
   grow; a scene with its shutter closed has no such row), and lancer check shows the
   shutter. *)

open Run_lancer

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"

let scene shutter =
  Printf.sprintf
    {|settings { width: 32, height: 24 }
animation { fps: 4, frames: 2 }
camera { position: (0, 1, -5), look_at: (0, 0.6, 0), fov: 45%s }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0, material: material { color: (0.8, 0.8, 0.8) } }
sphere { center: (-1.5 + 8 * time, 0.5, 0), radius: 0.5, material: material { color: (0.9, 0.2, 0.2) } }
|}
    shutter

let in_dir shutter =
  let d = tmpdir "lancer-bench-blur" in
  write_file (Filename.concat d "blur.rts") (scene shutter);
  d

let rows shutter =
  let d = in_dir shutter in
  quality_rows ~exe ~dir:d "blur.rts" "shutter samples"

let tests =
  [
    Alcotest.test_case "the shutter-sample rows converge towards the reference" `Quick
      (fun () ->
        let r = rows ", shutter: (0, 1)" in
        Alcotest.(check (list string))
          "values" [ "1"; "2"; "4"; "8"; "16" ] (List.map fst r);
        let e = List.map snd r in
        let shown = String.concat ", " (List.map (Printf.sprintf "%.3f") e) in
        match e with
        | [ e1; e2; e4; _; e16 ] ->
            Alcotest.(check bool)
              ("RMSE falls: " ^ shown) true
              (e1 > e2 && e2 > e4 && e16 < e4 && e16 < e1 /. 2.)
        | _ -> Alcotest.fail shown);
    Alcotest.test_case "a closed shutter has no shutter-sample rows" `Quick (fun () ->
        Alcotest.(check int) "rows" 0 (List.length (rows "")));
    Alcotest.test_case "lancer check shows the shutter" `Quick (fun () ->
        let d = in_dir ", shutter: (-0.5, 0.5), shutter_samples: 6" in
        let st, out, err = run ~exe ~dir:d [ "check"; "blur.rts" ] in
        if st <> 0 then Alcotest.failf "check failed (%d): %s" st err;
        let line =
          "camera: perspective, fov 45°, motion blur (shutter -0.5 to 0.5 frames, 6 \
           instants)"
        in
        if not (List.mem line (String.split_on_char '\n' out)) then
          Alcotest.failf "no %S in:\n%s" line out);
  ]

let () = Alcotest.run "motion blur from the command line" [ ("bench and check", tests) ]
