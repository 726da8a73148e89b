(* What a golden test does for its user beyond the comparison: it refuses to pass on
   inputs dune does not know about, makes the golden directory on the first update,
   clears the images of an old failure, and renders at a time, a frame, a sample count
   or a quality preset. *)

let read_file path = In_channel.with_open_bin path In_channel.input_all

let write_file path s =
  Out_channel.with_open_bin path (fun oc -> Out_channel.output_string oc s)

let contains s sub =
  let n = String.length sub in
  let rec at i = i + n <= String.length s && (String.sub s i n = sub || at (i + 1)) in
  at 0

let rec mkdir_p d =
  if not (Sys.file_exists d) then (
    mkdir_p (Filename.dirname d);
    Sys.mkdir d 0o755)

let temp_dir () =
  let d = Filename.temp_file "lancer_workflow" "" in
  Sys.remove d;
  Sys.mkdir d 0o755;
  d

(* Run [f] with these environment variables and in this directory, then put them back. *)
let within ?cwd env f =
  let saved = List.map (fun (k, _) -> (k, Sys.getenv_opt k)) env
  and here = Sys.getcwd () in
  List.iter (fun (k, v) -> Unix.putenv k v) env;
  Option.iter Sys.chdir cwd;
  Fun.protect f ~finally:(fun () ->
      Sys.chdir here;
      (* An unset variable is put back empty, which both readers treat as unset. *)
      List.iter (fun (k, v) -> Unix.putenv k (Option.value v ~default:"")) saved)

let failure f = match f () with () -> None | exception e -> Some (Printexc.to_string e)

let scene =
  {|include "parts/colour.rts"
settings { width: 32, height: 24 }
camera { position: (0, 1, -5), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0 }
sphere { center: (0, 1, 0), radius: 1, material: material { color: c } }
|}

(* A project laid out as dune lays it out: sources in ROOT/proj, the test run in
   ROOT/_build/default/proj with copies of its dependencies. *)
let test_undeclared_inputs () =
  let root = temp_dir () in
  let src = Filename.concat root "proj"
  and build = Filename.concat root "_build/default/proj" in
  mkdir_p (Filename.concat src "parts");
  mkdir_p build;
  write_file (Filename.concat src "s.rts") scene;
  write_file (Filename.concat src "parts/colour.rts") "let c = (0.9, 0.2, 0.2)\n";
  (* Only the scene is a dependency, as with (deps (glob_files *.rts)). *)
  write_file (Filename.concat build "s.rts") scene;
  let check () = Lancer_alcotest.check ~scene:"s.rts" ~golden:"golden/s.png" () in
  within ~cwd:build [ ("DUNE_SOURCEROOT", root); ("LANCER_UPDATE_GOLDEN", "1") ]
  @@ fun () ->
  (match failure check with
  | None -> Alcotest.fail "passed with an include that is not a dependency"
  | Some m ->
      List.iter
        (fun part ->
          Alcotest.(check bool) (Printf.sprintf "%S in %S" part m) true (contains m part))
        [ "parts/colour.rts"; "not among its dependencies"; "(source_tree parts)" ]);
  Alcotest.(check bool)
    "no golden written" false
    (Sys.file_exists (Filename.concat src "golden/s.png"));
  (* Declared (dune copied it): the first update makes golden/ and the golden. *)
  mkdir_p (Filename.concat build "parts");
  write_file
    (Filename.concat build "parts/colour.rts")
    (read_file (Filename.concat src "parts/colour.rts"));
  check ();
  Alcotest.(check bool)
    "golden/ made, golden written" true
    (Sys.file_exists (Filename.concat src "golden/s.png"));
  Unix.putenv "LANCER_UPDATE_GOLDEN" "0";
  (* The golden must be a dependency too. *)
  (match failure check with
  | None -> Alcotest.fail "passed with a golden that is not a dependency"
  | Some m -> Alcotest.(check bool) m true (contains m "golden/s.png"));
  mkdir_p (Filename.concat build "golden");
  write_file
    (Filename.concat build "golden/s.png")
    (read_file (Filename.concat src "golden/s.png"));
  check ();
  (* A copy that another rule left behind is stale once the file changes. *)
  write_file (Filename.concat src "parts/colour.rts") "let c = (0.2, 0.9, 0.2)\n";
  match failure check with
  | None -> Alcotest.fail "passed on a stale copy of the include"
  | Some m -> Alcotest.(check bool) m true (contains m "parts/colour.rts")

let test_stale_failure_images_removed () =
  let dir = temp_dir () in
  let golden = Filename.concat dir "golden/ball.png" in
  let ball = Lancer_alcotest.source_path "ball.rts" in
  within [ ("LANCER_UPDATE_GOLDEN", "0") ] @@ fun () ->
  (* No golden directory yet: a plain run says how to make the golden. *)
  (match failure (fun () -> Lancer_alcotest.check ~scene:ball ~golden ()) with
  | None -> Alcotest.fail "passed without a golden"
  | Some m -> Alcotest.(check bool) m true (contains m "LANCER_UPDATE_GOLDEN=1"));
  Alcotest.(check bool)
    "the render kept beside the missing golden" true
    (Sys.file_exists (Filename.concat dir "golden/ball.actual.png"));
  Unix.putenv "LANCER_UPDATE_GOLDEN" "1";
  Lancer_alcotest.check ~scene:ball ~golden ();
  Alcotest.(check bool)
    "updated: no actual image left" false
    (Sys.file_exists (Filename.concat dir "golden/ball.actual.png"));
  Unix.putenv "LANCER_UPDATE_GOLDEN" "0";
  (* An earlier failure's images, then a pass. *)
  List.iter
    (fun f -> write_file (Filename.concat dir f) "old")
    [ "golden/ball.actual.png"; "golden/ball.diff.png" ];
  Lancer_alcotest.check ~scene:ball ~golden ();
  Alcotest.(check (list string))
    "only the golden is left" [ "ball.png" ]
    (Array.to_list (Sys.readdir (Filename.concat dir "golden")))

let render ?samples ?quality ?time ?frame name =
  match
    Lancer_alcotest.render_scene ?samples ?quality ?time ?frame
      (Lancer_alcotest.source_path name)
  with
  | Ok (_, _, bytes) -> Bytes.to_string bytes
  | Error m -> Alcotest.failf "%s: %s" name m

let test_time_frame_samples_quality () =
  (* drop.rts runs at 24 fps: frame 12 is time 0.5. *)
  let f12 = render ~frame:12 "drop.rts" in
  Alcotest.(check bool) "~frame:12 is ~time:0.5" true (f12 = render ~time:0.5 "drop.rts");
  Alcotest.(check bool) "and not time 0" false (f12 = render "drop.rts");
  let refused args r =
    match r with
    | Ok _ -> Alcotest.failf "%s was not refused" args
    | Error m -> Alcotest.(check bool) (args ^ ": " ^ m) true (contains m "frame")
  in
  let drop = Lancer_alcotest.source_path "drop.rts"
  and ball = Lancer_alcotest.source_path "ball.rts" in
  refused "~frame:48" (Lancer_alcotest.render_scene ~frame:48 drop);
  refused "~frame on a still" (Lancer_alcotest.render_scene ~frame:1 ball);
  refused "~time and ~frame" (Lancer_alcotest.render_scene ~frame:1 ~time:0.5 drop);
  (* The preset, then ~samples over it, as lancer render --quality --samples does. *)
  let one = render ~samples:1 "ball.rts"
  and reference = render ~quality:Lancer.Quality.Reference "ball.rts" in
  Alcotest.(check bool)
    "~samples:1 differs from the reference preset's 8×8" false (one = reference);
  Alcotest.(check bool)
    "~samples overrides the preset" true
    (one = render ~quality:Lancer.Quality.Reference ~samples:1 "ball.rts");
  Alcotest.(check bool)
    "~samples:2 is another image" false
    (one = render ~samples:2 "ball.rts")

let () =
  Alcotest.run "example: the golden-test workflow"
    [
      ( "workflow",
        [
          Alcotest.test_case "a file the scene reads must be a dependency" `Quick
            test_undeclared_inputs;
          Alcotest.test_case
            "golden/ is made on the first update; an old failure's images go after a pass"
            `Quick test_stale_failure_images_removed;
          Alcotest.test_case "~time, ~frame, ~samples and ~quality" `Quick
            test_time_frame_samples_quality;
        ] );
    ]
