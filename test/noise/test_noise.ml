(* The noise estimate of lancer render's --stats and summary line, against the RMSE that
   lancer diff measures between the render and a reference of many samples. *)

open Run_lancer

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"

(* A floor and two spheres at 64×48 under [light], seen through [camera]'s extra fields,
   with [settings]' extra fields. *)
let scene ~settings ~camera ~light =
  Printf.sprintf
    {|settings { width: 64, height: 48%s }
camera { position: (0, 2, -5), look_at: (0, 0.5, 0), fov: 50%s }
light { position: (-2, 4, -2)%s }
plane { normal: (0, 1, 0), offset: 0, material: material { color: (0.8, 0.8, 0.8) } }
sphere { center: (0, 0.7, 0), radius: 0.7, material: material { color: (0.9, 0.3, 0.2) } }
sphere { center: (1.5, 0.4, 2), radius: 0.4,
         material: material { color: (0.2, 0.3, 0.9), reflection: 0.5 } }
|}
    settings camera light

let dir = lazy (tmpdir "lancer-noise")

(* Renders [text] as NAME.png with --stats: the summary line and the stats' "noise". *)
let render ?(domains = 1) name text =
  let d = Lazy.force dir in
  write_file (Filename.concat d (name ^ ".rts")) text;
  let stats = name ^ ".json" in
  let ((_, out, err) as r) =
    run ~exe ~dir:d
      [
        "render";
        name ^ ".rts";
        "-o";
        name ^ ".png";
        "--domains";
        string_of_int domains;
        "--stats";
        stats;
      ]
  in
  check_status ("render " ^ name) 0 r;
  let json = Yojson.Safe.from_file (Filename.concat d stats) in
  let noise =
    match Yojson.Safe.Util.member "noise" json with
    | `Float e -> Some e
    | `Int e -> Some (Float.of_int e)
    | `Null -> None
    | j -> Alcotest.failf "noise: %s" (Yojson.Safe.to_string j)
  in
  (out ^ err, noise)

let rmse a b =
  let d = Lazy.force dir in
  let status, out, err = run ~exe ~dir:d [ "diff"; "--json"; a ^ ".png"; b ^ ".png" ] in
  if status > 1 then Alcotest.failf "diff failed (%d): %s" status err;
  Yojson.Safe.Util.(to_number (member "rmse" (Yojson.Safe.from_string out)))

(* Renders of [scene n] for each [n], their estimates and their RMSE against the render
   [reference]: each estimate present; both fall from each n to the next; and each
   estimate is within a factor [3] of its RMSE (which also counts the reference's own
   error and 8-bit rounding). *)
let converges name scene ns reference =
  let _ = render (name ^ "_ref") (scene reference) in
  let rows =
    List.map
      (fun n ->
        let r = Printf.sprintf "%s_%d" name n in
        let line, e = render r (scene n) in
        match e with
        | None -> Alcotest.failf "%s: no noise estimate in the stats" r
        | Some e ->
            if not (contains line (Printf.sprintf "noise ≈ ")) then
              Alcotest.failf "%s: no noise in the summary line: %s" r line;
            (n, e, rmse (name ^ "_ref") r))
      ns
  in
  let shown =
    String.concat "; "
      (List.map (fun (n, e, m) -> Printf.sprintf "%d: %.3f vs RMSE %.3f" n e m) rows)
  in
  let rec falls = function
    | (_, e1, m1) :: ((_, e2, m2) :: _ as rest) -> e2 < e1 && m2 < m1 && falls rest
    | _ -> true
  in
  Alcotest.(check bool) ("estimate and RMSE fall: " ^ shown) true (falls rows);
  List.iter
    (fun (n, e, m) ->
      if not (e < 3. *. m && m < 3. *. e) then
        Alcotest.failf "%d samples: the estimate is not of the RMSE's size: %s" n shown)
    rows

let soft n =
  scene ~settings:"" ~camera:"" ~light:(Printf.sprintf ", radius: 1, samples: %d" n)

let jittered n =
  scene
    ~settings:(Printf.sprintf ", samples: %d, jitter: true" n)
    ~camera:", aperture: 0.15, focal_distance: 5" ~light:""

let lens n =
  scene ~settings:""
    ~camera:(Printf.sprintf ", aperture: 0.15, focal_distance: 5, lens_samples: %d" n)
    ~light:""

let tests =
  [
    Alcotest.test_case "soft shadows: the estimate falls with the light's samples" `Quick
      (fun () -> converges "soft" soft [ 2; 3; 4; 6 ] 24);
    Alcotest.test_case "jitter and lens: the estimate falls with the camera samples"
      `Quick (fun () -> converges "jitter" jittered [ 2; 3; 4 ] 12);
    Alcotest.test_case "one camera sample: the estimate falls with the lens samples"
      `Quick (fun () -> converges "lens" lens [ 2; 3; 4 ] 12);
    Alcotest.test_case "nothing stochastic: no estimate" `Quick (fun () ->
        let line, e =
          render "still" (scene ~settings:", samples: 2" ~camera:"" ~light:"")
        in
        Alcotest.(check (option (float 0.))) "stats" None e;
        if contains line "noise" then Alcotest.failf "noise in: %s" line;
        (* Jitter with one sample has no halves to compare. *)
        let _, e = render "one" (scene ~settings:", jitter: true" ~camera:"" ~light:"") in
        Alcotest.(check (option (float 0.))) "one jittered sample" None e);
    Alcotest.test_case "the same estimate on one and two domains" `Quick (fun () ->
        let text =
          scene ~settings:", samples: 2, jitter: true"
            ~camera:", aperture: 0.15, focal_distance: 5" ~light:", radius: 1, samples: 3"
        in
        let _, e1 = render ~domains:1 "d1" text and _, e2 = render ~domains:2 "d2" text in
        match (e1, e2) with
        | Some a, Some b -> Alcotest.(check (float 0.)) "noise" a b
        | _ -> Alcotest.fail "no estimate");
  ]

let () = Alcotest.run "noise estimate" [ ("lancer render", tests) ]
