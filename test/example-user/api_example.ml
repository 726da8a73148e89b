(* The library without the command line: load a scene, render it, write the picture and
   compare it with the golden one. doc/howto/golden-tests.md shows this program. *)
open Lancer

let fail fmt =
  Printf.ksprintf
    (fun m ->
      prerr_endline m;
      exit 1)
    fmt

let () =
  let prog =
    match Program.load_file "ball.rts" with
    | Ok p -> p
    | Error errs ->
        List.iter (Format.eprintf "%a" Diagnostic.pp) errs;
        exit 1
  in
  let scene =
    match Program.scene_at prog ~time:0. ~frame:0 with
    | Ok s -> s
    | Error _ -> fail "no scene"
  in
  let image, stats = Render.with_pool 2 (fun pool -> Render.render ?pool scene) in
  (match Image.save ~gamma:scene.settings.gamma "ball.png" image with
  | Ok () -> ()
  | Error m -> fail "%s" m);
  let rgb = (image.width, image.height, Image.to_bytes scene.settings.gamma image) in
  let golden =
    match Image.read_rgb8 "golden/ball.png" with Ok g -> g | Error m -> fail "%s" m
  in
  match Compare.compare golden rgb with
  | Error m -> fail "%s" m
  | Ok c ->
      Format.printf "%d rays; against the golden: %a@." (Counters.total_rays stats)
        Compare.pp c;
      if not (Compare.within ~max_diff:1 c) then exit 1
