(* lancer render --max-error, run as a user runs it, in a fresh directory. *)

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"

open Run_lancer

let lancer ~dir args = run ~exe ~dir args
let ( // ) = Filename.concat

(* Edges to anti-alias, a soft shadow, a mirror: every kind of knob has work to do. *)
let scene =
  {|settings { width: 64, height: 48, background: (0.1, 0.1, 0.2), depth: 4 }
camera { position: (0, 2, -6), look_at: (0, 0.5, 0), fov: 50 }
light { position: (-2, 5, -3), radius: 0.8, samples: 2 }
plane { normal: (0, 1, 0), offset: 0, material: material { texture: checker((0.9, 0.9, 0.9), (0.2, 0.2, 0.2), 2) } }
sphere { center: (-1, 0.7, 0), radius: 0.7, material: material { color: (0.9, 0.2, 0.2) } }
sphere { center: (1, 0.7, 0.5), radius: 0.7, material: material { color: (0.9, 0.9, 0.9), reflection: 0.8 } }
|}

let fresh () =
  let d = tmpdir "lancer-budget" in
  write_file (d // "s.rts") scene;
  d

let render d args = lancer ~dir:d ([ "render"; "s.rts" ] @ args)

let choice d json =
  let j = Yojson.Safe.from_file (d // json) in
  Yojson.Safe.Util.member "max_error" j

let samples c =
  let open Yojson.Safe.Util in
  let v = c |> member "settings" |> member "samples" |> to_string in
  int_of_string (List.hd (String.split_on_char '\xc3' v))

(* A figure of lancer diff --json: "flip", "psnr". *)
let figure d a b key =
  let _, out, _ = lancer ~dir:d [ "diff"; a; b; "--json" ] in
  Yojson.Safe.Util.(Yojson.Safe.from_string out |> member key |> to_number)

let test_tight_takes_more () =
  let d = fresh () in
  let go e name =
    check_status "render" 0
      (render d
         [ "--max-error"; e; "-o"; name ^ ".png"; "--stats"; name ^ ".json"; "-j"; "1" ]);
    choice d (name ^ ".json")
  in
  let loose = go "0.05" "loose" and tight = go "0.005" "tight" in
  let predicted c = Yojson.Safe.Util.(c |> member "predicted_error" |> to_number) in
  Alcotest.(check bool) "tight within its limit" true (predicted tight <= 0.005);
  Alcotest.(check bool) "loose coarser than tight" true (predicted loose > predicted tight);
  Alcotest.(check bool)
    (Printf.sprintf "tight samples %d > loose samples %d" (samples tight) (samples loose))
    true
    (samples tight > samples loose)

let test_within_limit () =
  let d = fresh () in
  let e = 0.02 in
  check_status "reference" 0
    (render d [ "--quality"; "reference"; "-o"; "ref.png"; "-q" ]);
  let r = render d [ "--max-error"; string_of_float e; "-o"; "b.png" ] in
  check_status "budget" 0 r;
  says "what it chose" r "max error 0.02 (mean FLIP): samples";
  says "against the reference" r "against the reference's";
  let f = figure d "ref.png" "b.png" "flip" in
  Alcotest.(check bool) (Printf.sprintf "mean FLIP %g <= %g" f e) true (f <= e);
  (* It chose something cheaper than the reference. *)
  check_status "stats" 0
    (render d [ "--max-error"; "0.02"; "-o"; "c.png"; "--stats"; "c.json"; "-q" ]);
  let c = choice d "c.json" in
  let num k = Yojson.Safe.Util.(c |> member k |> to_number) in
  Alcotest.(check bool)
    "predicted cheaper than the reference" true
    (num "predicted_seconds" < num "reference_predicted_seconds")

let test_domains () =
  let d = fresh () in
  let go j =
    check_status "render" 0
      (render d
         [
           "--max-error"; "0.01"; "-o"; j ^ ".png"; "--stats"; j ^ ".json"; "-q"; "-j"; j;
         ]);
    let c = choice d (j ^ ".json") in
    let open Yojson.Safe.Util in
    ( Yojson.Safe.to_string (c |> member "settings"),
      c |> member "predicted_error" |> to_number,
      c |> member "search_rays" |> to_int )
  in
  let s1, e1, r1 = go "1" and s2, e2, r2 = go "2" in
  Alcotest.(check string) "same settings" s1 s2;
  Alcotest.(check (float 0.)) "same predicted error" e1 e2;
  Alcotest.(check int) "same search rays" r1 r2;
  Alcotest.(check string) "same pixels" (pixels (d // "1.png")) (pixels (d // "2.png"))

(* At 480×360 the search costs at most a fifth of the rays of the render it plans, though
   the reference costs hundreds of times the choice (64 samples, 8×8 shadow rays). *)
let test_search_cost () =
  let d = fresh () in
  let go e name =
    check_status name 0
      (render d
         [
           "--max-error";
           e;
           "-W";
           "480";
           "-H";
           "360";
           "-o";
           name ^ ".png";
           "--stats";
           name ^ ".json";
           "-q";
         ]);
    let open Yojson.Safe.Util in
    let j = Yojson.Safe.from_file (d // (name ^ ".json")) in
    let c = member "max_error" j in
    ( c |> member "search_rays" |> to_int,
      j |> member "rays" |> member "total" |> to_int,
      c |> member "probe_pixels" |> to_int )
  in
  List.iter
    (fun e ->
      let search, rays, probes = go e ("e" ^ e) in
      Alcotest.(check bool)
        (Printf.sprintf "--max-error %s: search %d rays <= a fifth of the render's %d" e
           search rays)
        true
        (5 * search <= rays);
      Alcotest.(check bool)
        (Printf.sprintf "at least 128 probes (%d)" probes)
        true (probes >= 128))
    [ "0.05"; "0.02" ]

(* A scene whose cheapest settings already pass, at 640×480: the first round's 128 probes
   leave room for a second round on more, and the whole search still costs at most a
   fifth of the render's rays. *)
let plain =
  {|settings { width: 640, height: 480, background: (0.1, 0.1, 0.2) }
camera { position: (0, 2, -6), look_at: (0, 0.5, 0), fov: 50 }
light { position: (-2, 5, -3) }
plane { normal: (0, 1, 0), offset: 0, material: material { color: (0.8, 0.8, 0.8) } }
sphere { center: (-1, 0.7, 0), radius: 0.7, material: material { color: (0.9, 0.2, 0.2) } }
sphere { center: (1, 0.7, 0.5), radius: 0.7, material: material { color: (0.2, 0.4, 0.9) } }
|}

let test_second_round () =
  let d = tmpdir "lancer-budget" in
  write_file (d // "p.rts") plain;
  let r =
    lancer ~dir:d
      [ "render"; "p.rts"; "--max-error"; "0.02"; "-o"; "p.png"; "--stats"; "p.json" ]
  in
  check_status "render" 0 r;
  let open Yojson.Safe.Util in
  let j = Yojson.Safe.from_file (d // "p.json") in
  let c = member "max_error" j in
  let search = c |> member "search_rays" |> to_int in
  let rays = j |> member "rays" |> member "total" |> to_int in
  let probes = c |> member "probe_pixels" |> to_int in
  (* The first round's probes: one pixel per 49×49 block, 14×10 of them. *)
  Alcotest.(check bool)
    (Printf.sprintf "a second round on more probes than the first's 140 (%d)" probes)
    true (probes > 140);
  Alcotest.(check bool)
    (Printf.sprintf "search %d rays <= a fifth of the render's %d" search rays)
    true
    (5 * search <= rays)

let test_refusals () =
  let d = fresh () in
  let refused args sub =
    let r = render d args in
    check_status (String.concat " " args) 1 r;
    says (String.concat " " args) r sub;
    let _, _, err = r in
    Alcotest.(check bool) "no exception" false (contains err "Fatal error")
  in
  refused [ "--max-error"; "0" ] "--max-error with --metric flip is a mean FLIP, above 0";
  refused [ "--max-error=-0.1" ] "above 0 and under 1 (got -0.1)";
  refused [ "--max-error"; "1.5" ] "above 0 and under 1 (got 1.5)";
  refused [ "--max-error"; "300"; "--metric"; "rmse" ] "an RMSE, above 0 and at most 255";
  refused [ "--max-error"; "0"; "--metric"; "psnr" ] "a PSNR in dB, above 0";
  refused [ "--max-error"; "0.02"; "--samples"; "4" ] "cannot be combined with --samples";
  refused
    [ "--max-error"; "0.02"; "--quality"; "final" ]
    "cannot be combined with --quality";
  refused [ "--max-error"; "0.02"; "--resume" ] "cannot be combined with --resume";
  Alcotest.(check bool) "no image" false (Sys.file_exists (d // "s.png"))

let test_psnr () =
  let d = fresh () in
  check_status "reference" 0
    (render d [ "--quality"; "reference"; "-o"; "ref.png"; "-q" ]);
  let r = render d [ "--max-error"; "30"; "--metric"; "psnr"; "-o"; "p.png" ] in
  check_status "psnr" 0 r;
  says "in dB" r "max error 30 (PSNR)";
  let p = figure d "ref.png" "p.png" "psnr" in
  Alcotest.(check bool) (Printf.sprintf "PSNR %g >= 30" p) true (p >= 30.)

(* The record of an image written with --max-error keeps what it chose, and lancer verify
   renders those settings; without them, the scene's own settings are another image. *)
let test_verify () =
  let d = fresh () in
  check_status "budget" 0
    (render d [ "--max-error"; "0.005"; "-o"; "v.png"; "--stats"; "v.json"; "-q" ]);
  let bytes = read_file (d // "v.png") in
  let texts = Result.get_ok (Lancer.Png.texts bytes) in
  let record = Yojson.Safe.from_string (List.assoc "lancer" texts) in
  let open Yojson.Safe.Util in
  let kept = record |> member "max_error" in
  Alcotest.(check string) "metric" "flip" (kept |> member "metric" |> to_string);
  Alcotest.(check (float 0.)) "limit" 0.005 (kept |> member "limit" |> to_number);
  Alcotest.(check int)
    "the samples --stats names"
    (samples (choice d "v.json"))
    (kept |> member "settings" |> member "samples" |> to_number |> int_of_float);
  let r = lancer ~dir:d [ "verify"; "v.png"; "--tiles"; "all" ] in
  check_status "verify" 0 r;
  says "reproduced" r "reproduced: 4 of the 4 blocks";
  (* The same pixels under a record without the choice: not the scene's own image. *)
  let without =
    match record with
    | `Assoc l -> `Assoc (List.remove_assoc "max_error" l)
    | _ -> Alcotest.fail "a record that is not an object"
  in
  let rewrite record =
    let texts =
      List.map
        (fun (k, v) -> if k = "lancer" then (k, Yojson.Safe.to_string record) else (k, v))
        texts
    in
    let b = Buffer.create 4096 in
    Lancer.Png.encode ~text:texts
      (Result.get_ok (Lancer.Png.decode bytes))
      (Buffer.add_string b);
    write_file (d // "v.png") (Buffer.contents b);
    lancer ~dir:d [ "verify"; "v.png"; "--tiles"; "all" ]
  in
  let r = rewrite without in
  check_status "verify without the choice" 1 r;
  says "differs" r "not reproduced";
  (* A record is input: a value out of range is refused with a message. *)
  let bad =
    match without with
    | `Assoc l ->
        `Assoc
          (l
          @ [
              ( "max_error",
                `Assoc
                  [
                    ("metric", `String "flip");
                    ("limit", `Float 0.005);
                    ("settings", `Assoc [ ("samples", `Float 0.5) ]);
                  ] );
            ])
    | j -> j
  in
  let r = rewrite bad in
  check_status "verify a bad choice" 1 r;
  says "the value named" r "0.5 is not a value of the setting \"samples\""

(* An animation: one choice for every frame, the same bytes on any number of domains and
   in shards, kept in each frame's record and in the job (a resume with another limit
   renders again). *)
let test_animate () =
  let d = fresh () in
  write_file (d // "a.rts")
    (scene
   ^ {|animation { fps: 4, frames: 4 }
sphere { center: (-2 + time, 1.5, 1), radius: 0.3, material: material { color: (0.2, 0.8, 0.2) } }
|}
    );
  let animate args = lancer ~dir:d ([ "animate"; "a.rts" ] @ args) in
  let r = animate [ "-o"; "f1"; "--max-error"; "0.02"; "-j"; "1" ] in
  check_status "animate" 0 r;
  says "what it chose" r "max error 0.02 (mean FLIP): samples";
  says "which frames" r "; chosen on frame ";
  says "of which" r ", the costliest of frames 0, 1, 3";
  check_status "2 domains" 0
    (animate [ "-o"; "f2"; "--max-error"; "0.02"; "-j"; "2"; "-q" ]);
  List.iter
    (fun s ->
      check_status "a shard" 0
        (animate [ "-o"; "f3"; "--max-error"; "0.02"; "--shard"; s; "-q" ]))
    [ "0/2"; "1/2" ];
  let frame dir k = Run_lancer.pixels (d // dir // Printf.sprintf "frame_%04d.png" k) in
  for k = 0 to 3 do
    Alcotest.(check bool)
      (Printf.sprintf "frame %d the same on 2 domains" k)
      true
      (frame "f1" k = frame "f2" k);
    Alcotest.(check bool)
      (Printf.sprintf "frame %d the same in shards" k)
      true
      (frame "f1" k = frame "f3" k)
  done;
  (* Not the scene's own settings: the frames differ from a plain animate's. *)
  check_status "plain" 0 (animate [ "-o"; "f4"; "-q" ]);
  Alcotest.(check bool)
    "another image than the scene's settings" false
    (frame "f1" 0 = frame "f4" 0);
  (* A part of the range chooses as the whole does. *)
  let r = animate [ "-o"; "f6"; "--max-error"; "0.02"; "--frames"; "0..1" ] in
  check_status "a range" 0 r;
  says "the whole animation's frames" r ", the costliest of frames 0, 1, 3";
  Alcotest.(check bool) "frame 1 as the whole's" true (frame "f1" 1 = frame "f6" 1);
  let r = lancer ~dir:d [ "verify"; "f1/frame_0002.png"; "--tiles"; "all" ] in
  check_status "verify a frame" 0 r;
  says "reproduced" r "reproduced";
  let r = animate [ "-o"; "f1"; "--max-error"; "0.02"; "--resume" ] in
  check_status "resume" 0 r;
  says "nothing to do" r "4 frames already rendered, 0 to go";
  let r = animate [ "-o"; "f1"; "--max-error"; "0.05"; "--resume" ] in
  check_status "resume with another limit" 0 r;
  says "rendered again" r "--max-error was 0.02, is now 0.05";
  let r = animate [ "-o"; "f5"; "--max-error"; "0.02"; "--samples"; "2" ] in
  check_status "with --samples" 1 r;
  says "refused" r "cannot be combined with --samples"

let () =
  Alcotest.run "budget"
    [
      ( "max-error",
        [
          Alcotest.test_case "a tight limit takes more samples" `Quick
            test_tight_takes_more;
          Alcotest.test_case "the image is within the limit" `Quick test_within_limit;
          Alcotest.test_case "the same choice on 1 and 2 domains" `Quick test_domains;
          Alcotest.test_case "PSNR" `Quick test_psnr;
          Alcotest.test_case "the search costs at most a fifth" `Quick test_search_cost;
          Alcotest.test_case "a second round where the render affords it" `Quick
            test_second_round;
          Alcotest.test_case "refusals" `Quick test_refusals;
          Alcotest.test_case "the record keeps the choice; verify renders it" `Quick
            test_verify;
          Alcotest.test_case "animate: one choice for every frame" `Quick test_animate;
        ] );
    ]
