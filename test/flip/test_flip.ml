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
  List.iter
    (fun (name, flip, ssim) ->
      let a, b = pair name in
      let f = Flip.mean (Flip.error_map a b) in
      Printf.printf "%-18s FLIP %.6f (reference %.6f)  SSIM %s (reference %s)\n" name f
        flip
        (match Ssim.ssim a b with Ok s -> Printf.sprintf "%.6f" s | Error _ -> "-")
        (match ssim with Some s -> Printf.sprintf "%.6f" s | None -> "-");
      if Float.abs (f -. flip) > tolerance then
        Alcotest.failf "%s: mean FLIP %.6f, the reference %.6f" name f flip;
      match (ssim, Ssim.ssim a b) with
      | Some s, Ok s' ->
          if Float.abs (s -. s') > tolerance then
            Alcotest.failf "%s: SSIM %.6f, the reference %.6f" name s' s
      | None, Error _ -> ()
      | None, Ok s' -> Alcotest.failf "%s: SSIM %.6f where the reference has none" name s'
      | Some _, Error m -> Alcotest.failf "%s: %s" name m)
    rows

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

let () =
  Alcotest.run "flip"
    [
      ( "reference",
        [ Alcotest.test_case "FLIP and SSIM agree with the references" `Quick agreement ]
      );
      ("cost", [ Alcotest.test_case "no allocation per pixel" `Quick allocation ]);
    ]
