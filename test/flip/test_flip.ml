(* FLIP and SSIM as lancer computes them, against the values of the reference
   implementations in oracle.tsv (NVIDIA's flip-evaluator, scikit-image) for the pairs of
   pairs/: within 0.001 each. oracle.sh remakes the table from those packages. *)

open Lancer

let tolerance = 0.001

let read p =
  match Image.read_rgb8 p with Ok i -> i | Error m -> Alcotest.failf "%s: %s" p m

let pair name =
  ( read (Filename.concat "pairs" (name ^ ".ref.png")),
    read (Filename.concat "pairs" (name ^ ".test.png")) )

(* (pair, flip, ssim if given) of the table, comments skipped. *)
let oracle () =
  In_channel.with_open_text "oracle.tsv" In_channel.input_lines
  |> List.filter (fun l -> l <> "" && l.[0] <> '#')
  |> List.map (fun l ->
         match String.split_on_char '\t' l with
         | [ name; flip; ssim ] ->
             ( name,
               float_of_string flip,
               if ssim = "-" then None else Some (float_of_string ssim) )
         | _ -> Alcotest.failf "oracle.tsv: a line not of three columns: %S" l)

let agreement () =
  let rows = oracle () in
  Alcotest.(check bool) "at least ten pairs" true (List.length rows >= 10);
  let worst_flip = ref 0. and worst_ssim = ref 0. in
  List.iter
    (fun (name, flip, ssim) ->
      let a, b = pair name in
      let f = Flip.mean (Flip.error_map a b) and s = Result.to_option (Ssim.ssim a b) in
      let show = Option.fold ~none:"-" ~some:(Printf.sprintf "%.6f") in
      Printf.printf "%-18s FLIP %.6f (reference %.6f)  SSIM %s (reference %s)\n" name f
        flip (show s) (show ssim);
      worst_flip := Float.max !worst_flip (Float.abs (f -. flip));
      if Float.abs (f -. flip) > tolerance then
        Alcotest.failf "%s: mean FLIP %.6f, the reference %.6f" name f flip;
      match (ssim, s) with
      | Some s, Some s' ->
          worst_ssim := Float.max !worst_ssim (Float.abs (s -. s'));
          if Float.abs (s -. s') > tolerance then
            Alcotest.failf "%s: SSIM %.6f, the reference %.6f" name s' s
      | None, None -> ()
      | None, Some s' ->
          Alcotest.failf "%s: SSIM %.6f where the reference has none" name s'
      | Some _, None -> Alcotest.failf "%s: no SSIM where the reference has one" name)
    rows;
  Printf.printf
    "largest differences: FLIP %.2g, SSIM %.2g (the table's values have 6 decimals)\n"
    !worst_flip !worst_ssim

(* The work per pixel allocates nothing: what is allocated on the minor heap (kernels,
   small planes, results) does not grow with the image. *)
let allocation () =
  let minor_words f =
    let before = Gc.minor_words () in
    ignore (Sys.opaque_identity (f ()));
    Gc.minor_words () -. before
  in
  let image w h = (w, h, Bytes.init (3 * w * h) (fun i -> Char.chr (i * 7919 mod 256))) in
  let other w h =
    (w, h, Bytes.init (3 * w * h) (fun i -> Char.chr (i * 104729 mod 256)))
  in
  let words w h =
    ( minor_words (fun () -> Flip.error_map (image w h) (other w h)),
      minor_words (fun () -> Ssim.ssim (image w h) (other w h)) )
  in
  let f1, s1 = words 32 24 and f2, s2 = words 256 192 in
  Printf.printf "minor words: FLIP %.0f at 32×24, %.0f at 256×192; SSIM %.0f, %.0f\n" f1
    f2 s1 s2;
  Alcotest.(check bool) "FLIP" true (f2 <= f1 +. 100.);
  Alcotest.(check bool) "SSIM" true (s2 <= s1 +. 100.)

let tmpdir () =
  let d = Filename.temp_file "lancer-flip" "" in
  Sys.remove d;
  Unix.mkdir d 0o755;
  d

let contains s sub =
  let n = String.length s and k = String.length sub in
  let rec at i = i + k <= n && (String.sub s i k = sub || at (i + 1)) in
  at 0

let exists d f = Sys.file_exists (Filename.concat d f)

(* A golden judged by a metric passes or fails by it, and its diff image is FLIP's map;
   without one, the per-channel tolerance decides and the diff image is the red one, as
   before. *)
let golden_metric () =
  let golden_image, actual = pair "render_spheres" in
  let flip = Flip.mean (Flip.error_map golden_image actual) in
  let d = tmpdir () in
  let g = Filename.concat d "g.png" in
  let w, h, bytes = golden_image in
  (match Image.write_rgb8 g w h bytes with Ok () -> () | Error m -> Alcotest.fail m);
  let golden ?metric () =
    match Lancer_alcotest.compare_golden ?metric ~golden:g actual with
    | Ok o -> o
    | Error m -> Alcotest.fail m
  in
  let diff_bytes () =
    match Image.read_rgb8 (Filename.concat d "g.diff.png") with
    | Ok (_, _, b) -> b
    | Error m -> Alcotest.fail m
  in
  (match golden () with
  | Different { figures; _ } ->
      Alcotest.(check bool) "no metric judged" true (figures.judged = None);
      Alcotest.(check bool)
        "no FLIP in the message" false
        (contains (Format.asprintf "%a" Compare.pp figures) "FLIP");
      Alcotest.(check bool)
        "the red diff image" true
        (Bytes.equal (diff_bytes ()) (Compare.diff_image golden_image actual))
  | _ -> Alcotest.fail "the render passed a per-channel tolerance of 1");
  (match golden ~metric:(Compare.Flip (flip +. 0.001)) () with
  | Same { judged = Some (Compare.Flip _, v); _ } ->
      Alcotest.(check (float 1e-12)) "the mean FLIP" flip v;
      Alcotest.(check bool) "failure images removed" false (exists d "g.diff.png")
  | _ -> Alcotest.fail "a mean FLIP within the limit failed");
  (match golden ~metric:(Compare.Flip (flip -. 0.001)) () with
  | Different { figures; _ } ->
      let msg = Format.asprintf "%a" Compare.pp figures in
      Alcotest.(check bool)
        ("the metric in " ^ msg) true
        (contains msg (Printf.sprintf "mean FLIP %.4f >" flip));
      Alcotest.(check bool)
        "FLIP's map as the diff image" true
        (Bytes.equal (diff_bytes ()) (Compare.flip_image golden_image actual))
  | _ -> Alcotest.fail "a mean FLIP over the limit passed");
  (match golden ~metric:(Compare.Ssim 0.9) () with
  | Same _ -> ()
  | _ -> Alcotest.fail "SSIM 0.98 failed a limit of 0.9");
  (match golden ~metric:(Compare.Psnr 60.) () with
  | Different _ -> ()
  | _ -> Alcotest.fail "a noisy render passed a PSNR of 60 dB");
  match Compare.golden ~metric:(Compare.Flip 2.) ~update:false ~golden:g actual with
  | Error m ->
      Alcotest.(check string)
        "refused" "a mean FLIP limit must be between 0 and 1 (got 2)" m
  | Ok _ -> Alcotest.fail "a FLIP limit of 2 was taken"

let () =
  Alcotest.run "flip"
    [
      ( "reference",
        [ Alcotest.test_case "FLIP and SSIM agree with the references" `Quick agreement ]
      );
      ("cost", [ Alcotest.test_case "no allocation per pixel" `Quick allocation ]);
      ("golden", [ Alcotest.test_case "a golden judged by a metric" `Quick golden_metric ]);
    ]
