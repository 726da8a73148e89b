(* lancer bench as a user runs it (quality and its cache, domains, animation), and the
   developers' benchmarks of bench/ run small so that they keep working (physics and the
   closed form it measures against, scaling). *)

open Yojson.Safe.Util

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"
let bench_exe = Filename.concat (Sys.getcwd ()) "../../bench/lancer_bench.exe"

let tmpdir () =
  let d =
    Filename.concat
      (Filename.get_temp_dir_name ())
      (Printf.sprintf "lancer-bench-%d-%d" (Unix.getpid ()) (Random.bits ()))
  in
  Unix.mkdir d 0o755;
  at_exit (fun () -> ignore (Sys.command ("rm -rf " ^ Filename.quote d)));
  d

let read_file p = In_channel.with_open_bin p In_channel.input_all
let write_file p s = Out_channel.with_open_bin p (fun oc -> output_string oc s)

(* Run lancer (or [exe]) with [args] (and [env] prepended as NAME=value); (status,
   stdout, stderr). *)
let lancer ?(exe = exe) ?(env = []) args =
  let out = Filename.temp_file "lancer" ".out"
  and err = Filename.temp_file "lancer" ".err" in
  let cmd =
    Printf.sprintf "%s %s %s >%s 2>%s"
      (String.concat " " (List.map (fun (k, v) -> k ^ "=" ^ Filename.quote v) env))
      (Filename.quote exe)
      (String.concat " " (List.map Filename.quote args))
      out err
  in
  let status = Sys.command cmd in
  let o = read_file out and e = read_file err in
  Sys.remove out;
  Sys.remove err;
  (status, o, e)

let json_of ?exe args ?env () =
  let st, o, e = lancer ?exe ?env args in
  Alcotest.(check int) (String.concat " " args ^ ": exit\n" ^ e) 0 st;
  try Yojson.Safe.from_string o
  with Yojson.Json_error m -> Alcotest.failf "not JSON (%s):\n%s" m o

let contains s sub =
  let n = String.length s and m = String.length sub in
  let rec go i = i + m <= n && (String.sub s i m = sub || go (i + 1)) in
  go 0

(* ---- physics ---- *)

let closed_form () =
  (* doc/reference/numerics.md: e = 1 and e = 0.8 impact times, to the 12 digits given
     there. *)
  let close msg a b = Alcotest.(check (float 5e-12)) msg a b in
  close "e = 1, first impact" 0.451523640986 (Lancer_benchmarks.Drop.impact_time 1. 1);
  close "e = 1, impact 4"
    (0.451523640986 +. (3. *. 0.903047281971))
    (Lancer_benchmarks.Drop.impact_time 1. 4);
  List.iteri
    (fun i t ->
      close
        (Printf.sprintf "e = 0.8, impact %d" (i + 1))
        t
        (Lancer_benchmarks.Drop.impact_time 0.8 (i + 1)))
    [ 0.451523640986; 1.173961466563; 1.751911727025; 2.214271935394; 2.584160102090 ];
  (* apex 0.64 m after the first e = 0.8 impact, half-way to the second *)
  let mid =
    0.5
    *. (Lancer_benchmarks.Drop.impact_time 0.8 1
       +. Lancer_benchmarks.Drop.impact_time 0.8 2)
  in
  Alcotest.(check (float 1e-12)) "apex 0.64 m" 0.64 (Lancer_benchmarks.Drop.gap 0.8 mid);
  Alcotest.(check (float 0.))
    "at rest after Zeno's 4.0637 s" 0.
    (Lancer_benchmarks.Drop.gap 0.8 4.07)

let physics_json () =
  let j = json_of ~exe:bench_exe [ "physics"; "--json" ] () in
  let rows = j |> member "rows" |> to_list in
  Alcotest.(check int)
    "2 restitutions × (exact + 2 methods × 3 steps)" 14 (List.length rows);
  let find e m step =
    List.find
      (fun r ->
        r |> member "restitution" |> to_number = e
        && r |> member "method" |> to_string = m
        &&
        match step with
        | None -> r |> member "step" = `Null
        | Some s -> Float.abs ((r |> member "step" |> to_number) -. s) < 1e-12)
      rows
  in
  let err r = r |> member "max_position_error" |> to_number in
  let exact1 = find 1. "exact" None in
  Alcotest.(check bool)
    (Printf.sprintf "exact, e = 1: position error %g < 1e-9" (err exact1))
    true
    (err exact1 < 1e-9);
  Alcotest.(check bool)
    "exact, e = 1: impact times to 1e-9 s" true
    (exact1 |> member "max_impact_time_error" |> to_number < 1e-9);
  Alcotest.(check int)
    "exact, e = 1: the 11 impacts of 10 s" 11
    (exact1 |> member "impacts_compared" |> to_int);
  let exact08 = find 0.8 "exact" None in
  (* the resting rule stops the cascade once a rebound rises under 1e-4 of the 0.1 m radius *)
  Alcotest.(check bool)
    (Printf.sprintf "exact, e = 0.8: position error %g ≤ 1e-5" (err exact08))
    true
    (err exact08 <= 1e-5);
  Alcotest.(check bool)
    "exact, e = 0.8: apexes to 1e-9 m" true
    (exact08 |> member "max_apex_error" |> to_number < 1e-9);
  let v30 = find 1. "verlet" (Some (1. /. 30.)) in
  Alcotest.(check (float 1e-3))
    "Verlet at 1/30 s: first apex 1.068 m (doc/reference/numerics.md)" 1.068
    (v30 |> member "first_apex" |> to_number);
  Alcotest.(check int) "Verlet at 1/30 s: 300 steps" 300 (v30 |> member "steps" |> to_int);
  let v1000 = find 1. "verlet" (Some 0.001)
  and v240 = find 1. "verlet" (Some (1. /. 240.)) in
  Alcotest.(check bool) "a smaller step is more accurate" true (err v1000 < err v240);
  List.iter
    (fun r ->
      Alcotest.(check bool)
        "positive wall time" true
        (r |> member "seconds" |> to_number > 0.))
    rows

(* ---- quality ---- *)

let tiny_scene =
  {|settings { width: 24, height: 18, samples: 1 }
camera { position: (0, 2, -6), look_at: (0, 0.5, 0) }
light { position: (-3, 5, -4), radius: 0.5, samples: 2 }
plane { normal: (0, 1, 0), offset: 0, material: material { texture: checker((1,1,1), (0.2,0.2,0.2), 1) } }
sphere { center: (0, 1, 0), radius: 1, material: material { color: (0.9, 0.2, 0.2), reflection: 0.3 } }
|}

let quality_cache () =
  let d = tmpdir () in
  let scene = Filename.concat d "tiny.rts" and svg = Filename.concat d "trade.svg" in
  write_file scene tiny_scene;
  let env = [ ("XDG_CACHE_HOME", Filename.concat d "cache") ] in
  let args = [ "bench"; "quality"; scene; "--domains"; "1"; "--json" ] in
  let first = json_of args ~env () in
  Alcotest.(check bool) "first run measures" false (first |> member "cached" |> to_bool);
  Alcotest.(check bool)
    "first run renders the reference" false
    (first |> member "reference_cached" |> to_bool);
  let rows = first |> member "rows" |> to_list in
  Alcotest.(check bool)
    "rows for samples, adaptive, depth, light samples, presets" true
    (List.for_all
       (fun k -> List.exists (fun r -> r |> member "knob" |> to_string = k) rows)
       [ "samples"; "adaptive"; "depth"; "light samples"; "preset" ]);
  List.iter
    (fun r ->
      List.iter
        (fun f -> Alcotest.(check bool) ("row has " ^ f) true (r |> member f <> `Null))
        [ "knob"; "value"; "seconds"; "rays"; "rmse"; "psnr"; "share_over_1" ])
    rows;
  let t0 = Unix.gettimeofday () in
  let second = json_of (args @ [ "--svg"; svg ]) ~env () in
  let dt = Unix.gettimeofday () -. t0 in
  Alcotest.(check bool)
    "second run reads the cache" true
    (second |> member "cached" |> to_bool);
  Alcotest.(check string)
    "same rows"
    (Yojson.Safe.to_string (first |> member "rows"))
    (Yojson.Safe.to_string (second |> member "rows"));
  Alcotest.(check bool) (Printf.sprintf "second run quick (%.2f s)" dt) true (dt < 5.);
  let s = read_file svg in
  Alcotest.(check bool) "an SVG chart" true (contains s "<svg" && contains s "</svg>");
  List.iter
    (fun k -> Alcotest.(check bool) ("legend " ^ k) true (contains s (">" ^ k ^ "<")))
    [ "samples"; "depth"; "preset" ];
  let fresh = json_of (args @ [ "--fresh" ]) ~env () in
  Alcotest.(check bool)
    "--fresh measures again" false
    (fresh |> member "cached" |> to_bool);
  Alcotest.(check bool)
    "--fresh renders the reference again" false
    (fresh |> member "reference_cached" |> to_bool);
  (* Markdown: the columns and the cache note *)
  let st, md, e = lancer ~env [ "bench"; "quality"; scene; "--domains"; "1" ] in
  Alcotest.(check int) ("markdown exit\n" ^ e) 0 st;
  Alcotest.(check bool)
    ("header:\n" ^ md) true
    (contains md
       "| knob | value | wall time (s) | M rays | RMSE (0–255) | PSNR dB | pixels off > \
        1/255 |");
  Alcotest.(check bool) "says it read the cache" true (contains md "read from the cache");
  (* Before it measures, what it will render and roughly how long; then its progress (a
     line at every tile with an interval of 0). *)
  let st, _, e =
    lancer
      ~env:(("LANCER_PROGRESS_INTERVAL", "0") :: env)
      [ "bench"; "quality"; scene; "--domains"; "1"; "--fresh" ]
  in
  Alcotest.(check int) ("fresh markdown exit\n" ^ e) 0 st;
  Alcotest.(check bool)
    ("what it renders, first:\n" ^ e)
    true
    (String.starts_with e
       ~prefix:
         (Printf.sprintf
            "bench quality: 25 renders of %s at 24×18 on 1 domain: the reference (16×16 \
             samples, depth 64), then samples 1×1 to 6×6, adaptive 0.2 to 0.02, depth 1 \
             to 64, light samples 1×1 to 8×8, preset draft to reference; about "
            scene)
    && contains e "rays (lancer check's estimate), roughly ");
  Alcotest.(check bool)
    ("its progress:\n" ^ e) true
    (contains e "renders 0/25" && contains e "renders 25/25 (100%)" && contains e "left ");
  (* another size is another measurement *)
  let other = json_of (args @ [ "--width"; "16"; "--height"; "12" ]) ~env () in
  Alcotest.(check bool)
    "other options are not cached" false
    (other |> member "cached" |> to_bool)

(* ---- scaling ---- *)

let scaling_json () =
  let j =
    json_of ~exe:bench_exe
      [
        "scaling";
        "--counts";
        "100,1000";
        "--json";
        "--width";
        "64";
        "--height";
        "48";
        "--base-count";
        "200";
        "--domain-counts";
        "1,2";
        "--sizes";
        "32x24,64x48";
      ]
      ()
  in
  Alcotest.(check string)
    "peak memory per configuration" "configuration"
    (j |> member "peak_memory_per" |> to_string);
  let rows name = j |> member name |> to_list in
  let ints name f = List.map (fun r -> r |> member f |> to_int) (rows name) in
  Alcotest.(check (list int)) "count sweep" [ 100; 1000 ] (ints "counts" "spheres");
  Alcotest.(check (list int)) "count sweep width" [ 64; 64 ] (ints "counts" "width");
  Alcotest.(check (list int)) "domain sweep" [ 1; 2 ] (ints "domains" "domains");
  Alcotest.(check (list int))
    "domain sweep spheres" [ 200; 200 ] (ints "domains" "spheres");
  Alcotest.(check (list int)) "size sweep" [ 32; 64 ] (ints "sizes" "width");
  List.iter
    (fun r ->
      Alcotest.(check bool) "rays" true (r |> member "rays" |> to_int > 0);
      Alcotest.(check bool)
        "render time" true
        (r |> member "render_seconds" |> to_number > 0.);
      Alcotest.(check bool) "rays/s" true (r |> member "rays_per_second" |> to_number > 0.);
      match r |> member "peak_memory_kib" with
      | `Int k -> Alcotest.(check bool) "peak memory" true (k > 0)
      | `Null -> ()
      | _ -> Alcotest.fail "peak memory")
    (rows "counts" @ rows "domains" @ rows "sizes");
  (* one domain renders the same rays as two *)
  Alcotest.(check bool)
    "same rays on 1 and 2 domains" true
    (match ints "domains" "rays" with [ a; b ] -> a = b | _ -> false);
  let only =
    json_of ~exe:bench_exe
      [
        "scaling";
        "--counts";
        "100";
        "--sweeps";
        "counts";
        "--json";
        "--width";
        "16";
        "--height";
        "12";
      ]
      ()
  in
  Alcotest.(check bool)
    "--sweeps counts: no other sweep" true
    (only |> member "domains" = `Null && only |> member "sizes" = `Null)

(* ---- domains ---- *)

(* Minor words per ray, on one domain. With an area light of 8×8 samples nearly every ray is
   a shadow ray, so the figure is what a shadow ray allocates: nothing, the camera rays'
   allocations spread over 65 rays each. *)
let domains_words () =
  let d = tmpdir () in
  let scene = Filename.concat d "soft.rts" in
  write_file scene
    "settings { width: 64, height: 48 }\n\
     camera { position: (0, 2, -6), look_at: (0, 0.7, 0), fov: 60 }\n\
     light { position: (-3, 5, -4), radius: 0.5, samples: 8 }\n\
     plane { normal: (0, 1, 0), offset: 0 }\n\
     sphere { center: (-1.6, 1, 0), radius: 1 }\n\
     sphere { center: (0.6, 0.7, 1), radius: 0.7 }\n";
  let j =
    json_of [ "bench"; "domains"; scene; "--counts"; "1,2"; "--repeat"; "1"; "--json" ] ()
  in
  match j |> member "runs" |> to_list with
  | [ one; two ] ->
      let w = one |> member "minor_words_per_ray" |> to_number in
      if not (w >= 0. && w < 2.) then
        Alcotest.failf "%.2f minor words per ray with soft shadows" w;
      Alcotest.(check bool)
        "no figure for two domains" true
        (two |> member "minor_words_per_ray" = `Null)
  | _ -> Alcotest.fail "two runs"

let scaling_errors () =
  List.iter
    (fun args ->
      let st, _, e = lancer ~exe:bench_exe ("scaling" :: args) in
      Alcotest.(check int) (String.concat " " args ^ "\n" ^ e) 1 st;
      Alcotest.(check bool)
        "one line, no backtrace" true
        (contains e "lancer: " && not (contains e "Raised at")))
    [
      [ "--counts"; "0" ];
      [ "--sizes"; "12by8" ];
      [ "--row"; "10,8x8" ];
      [ "--sweeps"; "colours" ];
    ]

(* The developers' benchmarks are not part of the shipped command. *)
let not_shipped () =
  List.iter
    (fun b ->
      let st, _, e = lancer [ "bench"; b ] in
      Alcotest.(check int) ("lancer bench " ^ b ^ " is not a command\n" ^ e) 1 st)
    [ "physics"; "scaling"; "language"; "materials" ]

let language_json () =
  let j =
    json_of ~exe:bench_exe [ "language"; "--repeat"; "1"; "--grid"; "10"; "--json" ] ()
  in
  let open Yojson.Safe.Util in
  Alcotest.(check int) "objects" 100 (j |> member "objects" |> to_int);
  Alcotest.(check bool)
    "the loop's time" true
    (j |> member "loop_seconds" |> to_number > 0.)

(* Spheres coloured in their loop hold their colour, not a material each: a few words more
   per object than plain ones in the description and in the scene, and their materials
   next to nothing. *)
let materials_json () =
  let words colour =
    let j =
      json_of ~exe:bench_exe
        ([ "materials"; "--grid"; "30"; "--json" ] @ if colour then [ "--colour" ] else [])
        ()
    in
    let open Yojson.Safe.Util in
    Alcotest.(check int) "objects" 900 (j |> member "objects" |> to_int);
    let w k = j |> member k |> to_number in
    ( w "description_words_per_object",
      w "primitive_words_per_object",
      w "material_words_per_object" )
  in
  let d0, p0, _ = words false and d1, p1, m1 = words true in
  let more what a b =
    Alcotest.(check bool)
      (Printf.sprintf "%s: %.1f words an object more than %.1f, at most 6" what b a)
      true
      (b -. a <= 6.)
  in
  more "the description" d0 d1;
  more "the scene's primitives" p0 p1;
  Alcotest.(check bool)
    (Printf.sprintf "the materials: %.2f words an object, under 1" m1)
    true (m1 < 1.)

(* An animation timed against its still: every frame written, both times and their ratio
   reported; a scene that fails is a one-line error. *)
let animation_json () =
  let d = tmpdir () in
  let scene = Filename.concat d "a.rts" in
  write_file scene
    {|settings { width: 16, height: 12 }
animation { fps: 10, frames: 3 }
camera { position: (0, 1, -5), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0 }
for i in 0 to 9 { sphere { center: (i - 4.5, 0.3, 1), radius: 0.3 } }
sphere { center: (time, 1, 0), radius: 0.5 }
|};
  let st, out, e = lancer [ "bench"; "animation"; scene; "--repeat"; "1"; "--json" ] in
  Alcotest.(check int) ("status\n" ^ e) 0 st;
  let j = Yojson.Safe.from_string out in
  Alcotest.(check int) "frames" 3 (j |> member "frames" |> to_int);
  let a = j |> member "animation_s" |> to_number
  and s = j |> member "still_s" |> to_number
  and r = j |> member "ratio" |> to_number in
  Alcotest.(check bool) "positive times" true (a > 0. && s > 0.);
  Alcotest.(check (float 1e-9)) "ratio" (a /. s) r;
  write_file scene "sphere { radius: -1 }\n";
  let st, _, e = lancer [ "bench"; "animation"; scene; "--repeat"; "1" ] in
  Alcotest.(check int) ("a failing scene\n" ^ e) 1 st;
  Alcotest.(check bool)
    ("one line, no backtrace\n" ^ e)
    true
    (contains e "bench animation: lancer animate failed" && not (contains e "Raised at"))

let () =
  Alcotest.run "bench_cli"
    [
      ( "physics",
        [
          Alcotest.test_case "closed form matches doc/reference/numerics.md" `Quick
            closed_form;
          Alcotest.test_case "physics --json" `Quick physics_json;
        ] );
      ( "quality",
        [ Alcotest.test_case "the second run reads the cache" `Quick quality_cache ] );
      ("domains", [ Alcotest.test_case "minor words per ray" `Quick domains_words ]);
      ( "scaling",
        [
          Alcotest.test_case "scaling --json rows" `Quick scaling_json;
          Alcotest.test_case "bad options exit 1" `Quick scaling_errors;
        ] );
      ("animation", [ Alcotest.test_case "animation --json" `Quick animation_json ]);
      ( "bench/",
        [
          Alcotest.test_case "not commands of lancer" `Quick not_shipped;
          Alcotest.test_case "language --json" `Quick language_json;
          Alcotest.test_case "materials --json: a colour each is compact" `Quick
            materials_json;
        ] );
    ]
