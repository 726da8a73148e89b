(* A golden test must fail when the picture changes. This takes ball.rts, turns the ball
   from blue to green in a copy in a temporary directory, and checks it against a copy of the
   blue ball's golden: the check must fail, say why, and write the actual and diff images. *)

let blue = "color: (0.15, 0.35, 0.9)"
let green = "color: (0.2, 0.8, 0.2)"
let read_file path = In_channel.with_open_bin path In_channel.input_all

let write_file path s =
  Out_channel.with_open_bin path (fun oc -> Out_channel.output_string oc s)

let contains s sub =
  let n = String.length sub in
  let rec at i = i + n <= String.length s && (String.sub s i n = sub || at (i + 1)) in
  at 0

let replace_once s ~sub ~by =
  let n = String.length sub in
  let rec find i =
    if i + n > String.length s then None
    else if String.sub s i n = sub then Some i
    else find (i + 1)
  in
  match find 0 with
  | None -> Alcotest.failf "ball.rts no longer contains %S; update this test" sub
  | Some i -> String.sub s 0 i ^ by ^ String.sub s (i + n) (String.length s - i - n)

let with_temp_dir f =
  let d = Filename.temp_file "lancer_example" "" in
  Sys.remove d;
  Sys.mkdir d 0o755;
  let clean () =
    Array.iter (fun n -> Sys.remove (Filename.concat d n)) (Sys.readdir d);
    Sys.rmdir d
  in
  Fun.protect (fun () -> f d) ~finally:clean

let test_green_ball_fails () =
  (* even under LANCER_UPDATE_GOLDEN=1 this compares rather than rewrites *)
  Unix.putenv "LANCER_UPDATE_GOLDEN" "0";
  with_temp_dir @@ fun dir ->
  let scene = Filename.concat dir "ball.rts" in
  write_file scene
    (replace_once
       (read_file (Lancer_alcotest.source_path "ball.rts"))
       ~sub:blue ~by:green);
  (* the golden is copied so that the failure's images land in the temporary directory *)
  let golden = Filename.concat dir "ball.png" in
  write_file golden (read_file (Lancer_alcotest.source_path "golden/ball.png"));
  let message =
    match Lancer_alcotest.check ~scene ~golden () with
    | () -> Alcotest.fail "the green ball passed against the blue ball's golden"
    | exception e -> Printexc.to_string e
  in
  let diff = Filename.concat dir "ball.diff.png"
  and actual = Filename.concat dir "ball.actual.png" in
  List.iter
    (fun part ->
      Alcotest.(check bool)
        (Printf.sprintf "the message %S mentions %S" message part)
        true (contains message part))
    [
      "differs from its golden";
      golden;
      "max difference";
      "pixels";
      "actual image: " ^ actual;
      "diff image:   " ^ diff;
      "LANCER_UPDATE_GOLDEN=1";
      (* the cause: the ball (line 7) holds the most changed pixels *)
      "most changed pixels: ";
    ];
  (let mark = "most changed pixels: " in
   let rec at i =
     if String.sub message i (String.length mark) = mark then i + String.length mark
     else at (i + 1)
   in
   let rest = String.sub message (at 0) (String.length message - at 0) in
   let first =
     List.hd (String.split_on_char ',' (List.hd (String.split_on_char '\n' rest)))
   in
   let ball = " on sphere at " ^ scene ^ ":7" in
   Alcotest.(check bool)
     (Printf.sprintf "%S names the ball first" first)
     true
     (String.ends_with ~suffix:ball first));
  Alcotest.(check bool) "diff image written" true (Sys.file_exists diff);
  Alcotest.(check bool) "actual image written" true (Sys.file_exists actual);
  (* the diff marks the ball: a sizeable share of the pixels, not the whole picture *)
  match (Lancer.Image.read_rgb8 golden, Lancer.Image.read_rgb8 actual) with
  | Ok g, Ok a -> (
      match Lancer.Compare.compare g a with
      | Ok c ->
          Alcotest.(check bool) "some pixels differ" true (c.over_share > 0.02);
          Alcotest.(check bool) "the floor is unchanged" true (c.over_share < 0.5)
      | Error m -> Alcotest.fail m)
  | Error m, _ | _, Error m -> Alcotest.fail m

let test_unchanged_passes () =
  Unix.putenv "LANCER_UPDATE_GOLDEN" "0";
  with_temp_dir @@ fun dir ->
  let golden = Filename.concat dir "ball.png" in
  write_file golden (read_file (Lancer_alcotest.source_path "golden/ball.png"));
  Lancer_alcotest.check ~scene:(Lancer_alcotest.source_path "ball.rts") ~golden ();
  Alcotest.(check bool)
    "no diff image" false
    (Sys.file_exists (Filename.concat dir "ball.diff.png"))

let () =
  Alcotest.run "example: a change is caught"
    [
      ( "golden",
        [
          Alcotest.test_case "the unchanged scene passes" `Quick test_unchanged_passes;
          Alcotest.test_case "a green ball fails against the blue golden" `Quick
            test_green_ball_fails;
        ] );
    ]
