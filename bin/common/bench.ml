(* lancer bench: the measurements a user runs, each a call of lancer_measure. *)
open Cmdliner

let exits = Cli.exits

let cmd =
  let doc = "measure speed and the speed/accuracy trade" in
  let json =
    Arg.(value & flag & info [ "json" ] ~doc:"Print JSON instead of a Markdown table.")
  in
  let domains =
    let counts =
      Arg.(
        value
        & opt (list int) [ 1; 2 ]
        & info [ "counts" ] ~docv:"N,N,..." ~doc:"Domain counts to time.")
    in
    let repeat =
      Arg.(
        value & opt int 3
        & info [ "repeat" ] ~docv:"R" ~doc:"Runs per count; the median is reported.")
    in
    let man =
      [
        `S Manpage.s_examples;
        `Pre "  lancer bench domains --width 1920 --height 1080 --counts 1,2,4,8,16";
      ]
      @ Cli.bugs
    in
    Cmd.v
      (Cmd.info "domains"
         ~doc:
           "wall time and speed-up of one render over several domain counts, and on one \
            domain the minor words allocated per ray"
         ~man ~exits)
      Term.(
        const (fun o counts repeat json ->
            Report.run (fun _ -> Lancer_measure.Bench_domains.run o ~counts ~repeat ~json))
        $ Cli.(term Bench_domains)
        $ counts $ repeat $ json)
  in
  let quality =
    let svg =
      Arg.(
        value
        & opt (some string) None
        & info [ "svg" ] ~docv:"FILE" ~doc:"Also draw time against PSNR as an SVG chart.")
    in
    let fresh =
      Arg.(
        value & flag
        & info [ "fresh" ]
            ~doc:
              "Ignore the cache: render the reference and measure every row again (and \
               cache them anew).")
    in
    let man =
      [
        `S Manpage.s_description;
        `P
          "Renders the scene once per value of each quality knob and compares every \
           image with a reference render (the reference preset at 16×16 samples and \
           depth 64). The reference image and the measured rows are cached under \
           \\$XDG_CACHE_HOME/lancer (or ~/.cache/lancer), keyed by the scene text, the \
           size and options, the lancer build and the host, so a second run prints at \
           once; $(b,--fresh) measures again. Before it measures, it says on stderr what \
           it will render, $(b,lancer check)'s estimate of the rays and roughly how long \
           that takes (from a render of the reference at one pixel in k×k), then shows \
           its progress.";
        `S Manpage.s_examples;
        `Pre
          "  lancer bench quality scenes/showcase.rts --width 320 --height 240 --svg \
           trade.svg";
      ]
      @ Cli.bugs
    in
    Cmd.v
      (Cmd.info "quality"
         ~doc:"time, rays and error against a reference for each quality knob" ~man ~exits)
      Term.(
        const (fun o json svg fresh ->
            Report.run (fun _ -> Lancer_measure.Bench_quality.run o ~json ~svg ~fresh))
        $ Cli.(term Bench_quality)
        $ json $ svg $ fresh)
  in
  let animation =
    let scene =
      Arg.(
        value
        & pos 0 string "scenes/bench/field_moving.rts"
        & info [] ~docv:"SCENE" ~doc:"The animated scene (.rts) to time.")
    in
    let repeat =
      Arg.(
        value & opt int 3
        & info [ "repeat" ] ~docv:"R"
            ~doc:"Runs of each command, alternated; the median time is reported.")
    in
    let domains =
      Arg.(
        value
        & opt (some int) None
        & info [ "domains" ] ~docv:"D" ~doc:"Domains of both commands (default: theirs).")
    in
    let man =
      [
        `S Manpage.s_description;
        `P
          "Times $(b,lancer animate SCENE) (every frame of its animation) and $(b,lancer \
           render SCENE) (one still: frame 0), each a whole process from start to exit, \
           and prints their ratio: what the frames after the first cost. What does not \
           change between frames is evaluated, compiled and indexed once per animation.";
        `S Manpage.s_examples;
        `Pre "  lancer bench animation scenes/bench/field_moving.rts --repeat 3";
      ]
      @ Cli.bugs
    in
    Cmd.v
      (Cmd.info "animation"
         ~doc:"wall time of a whole animation against one still of it, and their ratio"
         ~man ~exits)
      Term.(
        const (fun scene repeat domains json ->
            Report.run (fun _ ->
                Lancer_measure.Bench_animation.run ~exe:Sys.executable_name ~scene ~repeat
                  ~domains ~json))
        $ scene $ repeat $ domains $ json)
  in
  Cmd.group
    (Cmd.info "bench" ~doc ~exits ~man:Cli.bugs
       ~envs:
         (Cli.envs
         @ [
             Cmd.Env.info "XDG_CACHE_HOME"
               ~doc:
                 "Where $(b,bench quality) keeps its reference renders \
                  (XDG_CACHE_HOME/lancer, or HOME/.cache/lancer).";
           ]))
    [ domains; quality; animation ]
