(* The lancer command line: argument parsing and one library call per command. *)
open Lancer
open Cmdliner

let exits = Cli.exits
let wrap f = Report.run f

let render =
  let doc = "render a scene to a PNG or PPM image" in
  let man =
    [
      `S Manpage.s_examples;
      `Pre
        "  lancer render                                # the built-in showcase, to \
         showcase.png";
      `Pre "  lancer render scenes/glass.rts -o glass.png --quality final";
      `Pre
        "  lancer render scene.rts --width 1920 --height 1080 --domains 8 --stats \
         stats.json";
      `Pre "  lancer render anim.rts --frame 12 -o frame12.ppm";
      `Pre
        "  lancer render scene.rts -o s.png --aov object,depth  # also s.object.png, \
         s.objects.json, s.depth.pfm";
      `Pre
        "  lancer render big.rts -o big.png --resume    # again after an interruption: \
         continues";
      `Pre
        "  lancer render scene.rts --max-error 0.02     # the cheapest settings within \
         mean FLIP 0.02 of the reference";
    ]
    @ Cli.bugs
  in
  Cmd.v
    (Cmd.info "render" ~doc ~man ~exits ~envs:Cli.envs)
    Term.(
      const (fun o resume e aov max_error ->
          Report.run
            ?interrupted:(if resume then Some Report.resumed_interrupt else None)
            (fun stop ->
              let aov = Option.map Aov_run.parse aov in
              Still_run.run ~cancel:(Report.on_interrupt stop) ?aov ?max_error o ~resume e))
      $ Cli.(term Render)
      $ Cli.resume_still $ Cli.encoding_term $ Cli.aov_term $ Cli.max_error_term)

let animate =
  let doc = "render an animation's frames to DIR/frame_0000.png …" in
  let man =
    [
      `S Manpage.s_examples;
      `Pre "  lancer animate scenes/bounce.rts -o frames/";
      `Pre
        "  lancer animate scenes/bounce.rts -o frames/ --frames 0..23 --resume --video \
         bounce.mp4";
      `Pre
        "  lancer animate scene.rts -o frames/ --shard 2/4 --resume     # frames 2, 6, \
         10, …";
      `Pre
        "  lancer animate scene.rts -o frames/ --shard slurm --resume   # a task of \
         sbatch --array=0-15";
      `Pre
        "  lancer animate scene.rts -o frames/ --max-error 0.02   # one choice of \
         settings for every frame";
    ]
    @ Cli.bugs
  in
  Cmd.v
    (Cmd.info "animate" ~doc ~man ~exits ~envs:(Cli.envs @ Cli.slurm_envs))
    Term.(
      const (fun o a max_error ->
          Report.run ~interrupted:Frames_run.interrupted (fun stop ->
              Frames_run.run ~cancel:(Report.on_interrupt stop) ?max_error o a))
      $ Cli.(term Animate)
      $ Cli.frames_term $ Cli.max_error_term)

let check =
  let doc =
    "parse and evaluate a scene; say what it holds and which renderer features it uses"
  in
  let scene =
    Arg.(
      required
      & pos 0 (some string) None
      & info [] ~docv:"SCENE.rts"
          ~doc:"The scene to check ($(b,-): read it from standard input).")
  in
  let json =
    Arg.(value & flag & info [ "json" ] ~doc:"Print the evaluated scene as JSON.")
  in
  let time =
    Arg.(
      value
      & opt (some float) None
      & info [ "time"; "t" ] ~docv:"SECONDS" ~doc:"Evaluate at this time.")
  in
  let frames =
    Arg.(
      value
      & opt (some string) None
      & info [ "frames" ] ~docv:"A..B"
          ~doc:
            "Evaluate every frame from A to B (inclusive), or $(b,all) of them, instead \
             of one: an error that only some frames have is found, with the frames that \
             have it.")
  in
  let man =
    [
      `S Manpage.s_description;
      `P
        "Prints what the scene holds (sampling, camera, animation, objects by kind, CSG \
         trees, lights, the renderer's features it uses and skips), warnings about what \
         is legal but likely a mistake, and the rays a render will cost, estimated \
         before any is traced, as set and under each quality preset ($(b,--width) and \
         $(b,--height) give them for that size). The warnings (which $(b,lancer render) \
         prints too) name an empty scene, a scene without objects or lights, a loop that \
         runs zero times, and a surface colour with a component m above 1 (as if given \
         as 0–255) unless some light's intensity × its colour's largest component × m is \
         at most 1.";
      `S Manpage.s_examples;
      `Pre "  lancer check scenes/showcase.rts";
      `Pre "  lancer check anim.rts --json --time 1.5";
      `Pre "  lancer check scene.rts --width 3840 --height 2160   # the estimates at 4K";
      `Pre "  lancer check scenes/bounce.rts --frames all";
      `Pre "  generate-scene | lancer check -";
    ]
    @ Cli.bugs
  in
  Cmd.v
    (Cmd.info "check" ~doc ~man ~exits ~envs:Cli.envs)
    Term.(
      const (fun scene json time frames (width, height) ->
          wrap (fun stop ->
              ignore (Report.on_interrupt stop);
              Check_run.run ?width ?height ~scene ~json ~time ~frames ()))
      $ scene $ json $ time $ frames $ Cli.size)

(* The options of diff and golden that say when two images count as equal. *)
let metric_arg =
  Arg.(
    value
    & opt (enum Compare_run.metric_names) Compare_run.Max
    & info [ "metric" ] ~docv:"max|rmse|psnr|flip|ssim"
        ~doc:
          "The figure that decides: $(b,max), the per-channel difference (the default); \
           $(b,rmse), the RMSE (0–255); $(b,psnr), the PSNR (dB); $(b,flip), the mean \
           FLIP (0–1); $(b,ssim), the SSIM.")

let tolerance_arg =
  Arg.(
    value
    & opt (some float) None
    & info [ "tolerance" ] ~docv:"T"
        ~doc:
          "The limit of the metric: the largest per-channel difference (0–255, default \
           1), RMSE or mean FLIP, or the smallest PSNR or SSIM, that still counts as \
           equal. Required with a $(b,--metric) other than $(b,max).")

let share_arg =
  Arg.(
    value & opt float 0.
    & info [ "max-share" ] ~docv:"F"
        ~doc:
          "Share of pixels (0–1) allowed to exceed the per-channel tolerance \
           ($(b,--metric max)).")

let diff =
  let doc = "compare two images; exit status 1 when they differ beyond the tolerance" in
  let a = Arg.(required & pos 0 (some file) None & info [] ~docv:"A.png") in
  let b = Arg.(required & pos 1 (some file) None & info [] ~docv:"B.png") in
  let out =
    Arg.(
      value
      & opt (some string) None
      & info [ "o"; "output" ] ~docv:"MAP.png"
          ~doc:
            "Write FLIP's error map of B against A: grey, black where they agree, white \
             at error 1.")
  in
  let json =
    Arg.(
      value & flag
      & info [ "json" ] ~doc:"Print the verdict and every figure as one JSON object.")
  in
  let man =
    [
      `S Manpage.s_description;
      `P
        "Compares two 8-bit images of the same size and prints the verdict (same, within \
         tolerance or differ) and the figures: the largest per-channel difference, the \
         RMSE, the PSNR, the pixels over the per-channel tolerance, the mean FLIP (the \
         perceptual error of Andersson et al. 2020, for a 3840-pixel monitor 0.7 m wide \
         seen from 0.7 m) and the SSIM (per channel, 11×11 Gaussian window).";
      `S Manpage.s_examples;
      `Pre "  lancer diff expected.png actual.png -o map.png --tolerance 2";
      `Pre "  lancer diff expected.png actual.png --metric flip --tolerance 0.01";
      `Pre "  lancer diff expected.png actual.png --json";
    ]
    @ Cli.bugs
  in
  Cmd.v
    (Cmd.info "diff" ~doc ~man ~exits)
    Term.(
      const (fun a b out metric tolerance share json ->
          wrap (fun _ ->
              if not (Compare_run.diff ?out ~json ~metric ~tolerance ~share a b) then
                Stdlib.exit 1))
      $ a $ b $ out $ metric_arg $ tolerance_arg $ share_arg $ json)

let golden =
  let doc =
    "render a scene and compare it with a golden image; exit status 1 when they differ"
  in
  let golden = Arg.(required & pos 1 (some string) None & info [] ~docv:"GOLDEN.png") in
  let update =
    Arg.(
      value & flag
      & info [ "update" ] ~doc:"Write the render as the golden instead of comparing.")
  in
  let man =
    [
      `S Manpage.s_description;
      `P
        "Renders SCENE.rts with the given options and compares the image with \
         GOLDEN.png. When they differ beyond the tolerance, GOLDEN.actual.png and \
         GOLDEN.diff.png (differences in red; FLIP's error map, in grey, with a \
         $(b,--metric) other than $(b,max)) are written next to the golden, and the exit \
         status is 1.";
      `S Manpage.s_examples;
      `Pre "  lancer golden scene.rts tests/scene.png --width 160 --height 120";
      `Pre
        "  lancer golden scene.rts tests/scene.png --width 160 --height 120 --update   # \
         (re)make the golden";
      `Pre
        "  lancer golden scene.rts tests/scene.png --width 160 --height 120 --metric \
         flip --tolerance 0.01";
    ]
    @ Cli.bugs
  in
  let term =
    Term.(
      const (fun o golden metric tolerance share update ->
          wrap (fun stop ->
              let cancel = Report.on_interrupt stop in
              let tolerance, metric = Compare_run.judge metric tolerance ~share in
              if
                not
                  (Compare_run.golden ~cancel ?metric o ~golden ~tolerance ~share ~update)
              then Stdlib.exit 1))
      $ Cli.(term Golden)
      $ golden $ metric_arg $ tolerance_arg $ share_arg $ update)
  in
  Cmd.v (Cmd.info "golden" ~doc ~man ~exits ~envs:Cli.envs) term

let verify =
  let doc = "check that an image lancer wrote still comes from its scene" in
  let image = Arg.(required & pos 0 (some file) None & info [] ~docv:"IMAGE.png") in
  let blocks =
    let parse = function
      | "all" -> Ok Verify_run.All
      | s -> (
          match int_of_string_opt s with
          | Some k when k >= 1 -> Ok (Verify_run.Count k)
          | _ ->
              Error (`Msg (Printf.sprintf "%S: a number of blocks, at least 1, or all" s))
          )
    in
    let print f = function
      | Verify_run.All -> Format.pp_print_string f "all"
      | Count k -> Format.pp_print_int f k
    in
    Arg.(
      value
      & opt (conv (parse, print)) (Verify_run.Count 8)
      & info [ "tiles" ] ~docv:"K|all"
          ~doc:
            "Render $(docv) blocks of 32×32 pixels again, chosen from the image's \
             own              digest, besides every block edited since it was written; \
             $(b,all) renders              the whole image again.")
  in
  let domains =
    Arg.(
      value
      & opt (some int) None
      & info [ "domains"; "j" ] ~docv:"N" ~doc:"Domains (cores) to render with.")
  in
  let man =
    [
      `S Manpage.s_description;
      `P
        "Every PNG image lancer renders keeps a record of where it came from, in a \
         text          chunk: the lancer version, the scene (a path from the image's \
         directory) and          the digest of its text, the MD5 of every file the scene \
         read, the options that          change pixels, the frame and time, and a digest \
         of each 32×32 block of its          pixels.";
      `P
        "$(b,lancer verify) checks the blocks against their digests, the scene and \
         its          files against theirs, then renders some blocks again and compares \
         them sample          for sample. It prints $(b,reproduced) and exits with 0, or \
         names what is          missing or changed, or the blocks and pixels that \
         differ, and exits with 1.";
      `S Manpage.s_examples;
      `Pre "  lancer verify out/showcase.png";
      `Pre "  lancer verify out/bounce/frame_0042.png --tiles all";
    ]
    @ Cli.bugs
  in
  Cmd.v
    (Cmd.info "verify" ~doc ~man ~exits)
    Term.(
      const (fun image blocks domains ->
          wrap (fun stop ->
              let cancel = Report.on_interrupt stop in
              let domains = Options.domains { Options.default with domains } in
              if not (Verify_run.run ~cancel ~domains ~blocks image) then Stdlib.exit 1))
      $ image $ blocks $ domains)

let main () =
  let doc = "a functional ray tracer for .rts scene scripts" in
  let man =
    [
      `S Manpage.s_description;
      `P
        "lancer renders .rts scene scripts to PNG images and image sequences. Start with \
         $(b,lancer render), which renders the built-in showcase, then $(b,lancer check \
         SCENE.rts) and $(b,lancer render SCENE.rts).";
      `S Manpage.s_examples;
      `Pre "  lancer render";
      `Pre "  lancer render scenes/showcase.rts -o out/showcase.png --quality final";
      `Pre "  lancer check scenes/showcase.rts";
    ]
    @ Cli.bugs
  in
  let info =
    Cmd.info "lancer" ~version:Lancer.Version.v ~doc ~man ~exits
      ~envs:(Cli.envs @ Cli.slurm_envs)
  in
  (* Report.main ends the process: what help, --version or a command printed that
     standard output cannot take is reported there, not at exit. *)
  Report.main (fun () ->
      let code =
        Cmd.eval'
          (Cmd.group info
             [ render; animate; check; diff; golden; verify; Watch.cmd; Bench.cmd ])
      in
      if code = Cmd.Exit.cli_error then
        Option.iter (Report.say ~program:"lancer") (Cli.negative_value_hint Sys.argv);
      Cli.status_of_eval code)
