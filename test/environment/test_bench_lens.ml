(* Depth of field from the command line: lancer bench quality measures it (a "lens samples"
   row per n×n, whose error against the reference falls as n grows; a scene without depth
   of field has no such row), and lancer render writes the same bytes on any number of
   domains. *)

open Run_lancer

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"

let scene aperture =
  Printf.sprintf
    {|settings { width: 32, height: 24 }
camera { position: (0, 1, -5), look_at: (0, 0.6, 0), fov: 45, aperture: %g, focal_distance: 5, lens_samples: 2 }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0, material: material { texture: checker((1, 1, 1), (0.1, 0.1, 0.1), 0.4) } }
sphere { center: (-0.8, 0.5, -2), radius: 0.5, material: material { color: (0.9, 0.2, 0.2) } }
sphere { center: (0.8, 0.6, 2), radius: 0.6, material: material { color: (0.2, 0.3, 0.9) } }
|}
    aperture

let rows aperture =
  let d = tmpdir "lancer-bench-lens" in
  write_file (Filename.concat d "dof.rts") (scene aperture);
  quality_rows ~exe ~dir:d "dof.rts" "lens samples"

let tests =
  [
    Alcotest.test_case "the lens-sample rows converge towards the reference" `Quick
      (fun () ->
        let r = rows 0.3 in
        Alcotest.(check (list string))
          "values"
          [ "1×1"; "2×2"; "4×4"; "8×8" ]
          (List.map fst r);
        let e = List.map snd r in
        let shown = String.concat ", " (List.map (Printf.sprintf "%.3f") e) in
        match e with
        | [ e1; e2; e4; e8 ] ->
            Alcotest.(check bool)
              ("RMSE falls: " ^ shown) true
              (e1 > e2 && e2 > e4 && e4 > e8)
        | _ -> Alcotest.fail shown);
    Alcotest.test_case "a pinhole camera has no lens-sample rows" `Quick (fun () ->
        Alcotest.(check int) "rows" 0 (List.length (rows 0.)));
  ]

let render_tests =
  [
    Alcotest.test_case "depth of field writes the same bytes with --domains 1, 2 and 3"
      `Quick (fun () ->
        let d = tmpdir "lancer-dof-domains" in
        write_file (Filename.concat d "dof.rts") (scene 0.3);
        let render n =
          let out = Printf.sprintf "d%d.png" n in
          let st, _, err =
            run ~exe ~dir:d
              [
                "render";
                "dof.rts";
                "-o";
                out;
                "-q";
                "--samples";
                "2";
                "--domains";
                string_of_int n;
              ]
          in
          if st <> 0 then Alcotest.failf "render failed (%d): %s" st err;
          read_file (Filename.concat d out)
        in
        let one = render 1 in
        Alcotest.(check bool) "2 domains" true (one = render 2);
        Alcotest.(check bool) "3 domains" true (one = render 3));
  ]

let () = Alcotest.run "depth of field" [ ("quality", tests); ("render", render_tests) ]
