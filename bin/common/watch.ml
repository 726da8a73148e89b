(* lancer watch: its options, and the preview (Lancer_preview.Preview). *)
open Lancer
open Cmdliner

let cmd =
  let doc = "show a scene in the browser, re-rendered progressively on every save" in
  let scene =
    Arg.(
      required
      & pos 0 (some string) None
      & info [] ~docv:"SCENE.rts" ~doc:"The scene to show.")
  in
  let port =
    Arg.(
      value & opt int 8123
      & info [ "port"; "p" ] ~docv:"N" ~doc:"The port to listen on; 0 picks a free one.")
  in
  let host =
    Arg.(
      value & opt string "127.0.0.1"
      & info [ "host" ] ~docv:"ADDR"
          ~doc:
            "The address to listen on: one IP address, never a wildcard such as \
             $(b,0.0.0.0), $(b,::) or $(b,::ffff:0.0.0.0). Without \
             $(b,--listen-beyond-loopback) it must be a loopback address \
             ($(b,127.0.0.0/8), $(b,::1), or $(b,::ffff:127.x.y.z)). The server answers \
             only requests addressed to it (their Host header), so a foreign web page \
             cannot reach it by a renamed domain.")
  in
  let beyond_loopback =
    Arg.(
      value & flag
      & info [ "listen-beyond-loopback" ]
          ~doc:
            "Allow a $(b,--host) that is not a loopback address. The preview asks for no \
             password: anyone who can reach that address can watch the scene, its \
             errors, and switch its quality.")
  in
  let any_source_line =
    Arg.(
      value & flag
      & info [ "show-lines-outside" ]
          ~doc:
            "Show the source line of an error in any file. By default, an error in a \
             file outside the scene's directory tree (reached by $(b,..), an absolute \
             path or a symbolic link) is shown as its file, line, column and message \
             only, without the line's text, on the page and in the terminal.")
  in
  let poll =
    Arg.(
      value & flag
      & info [ "poll" ]
          ~doc:
            "Look for changes by polling the files' status twice a second instead of \
             inotify (network file systems).")
  in
  let int_opt names docv doc =
    Arg.(value & opt (some int) None & info names ~docv ~doc)
  in
  let width =
    int_opt [ "width"; "W" ] "W" "Image width in pixels (overrides the scene)."
  in
  let height =
    int_opt [ "height"; "H" ] "H" "Image height in pixels (overrides the scene)."
  in
  let samples = int_opt [ "samples" ] "N" "N×N samples per pixel for the full image." in
  let depth = int_opt [ "depth" ] "D" "Maximum ray depth." in
  let domains = int_opt [ "domains"; "j" ] "N" "Domains (cores) to render with." in
  let quality =
    Arg.(
      value
      & opt (some (enum Quality.all)) None
      & info [ "quality" ] ~docv:"PRESET"
          ~doc:
            "The preset of the full image: $(b,draft), $(b,preview), $(b,final) or \
             $(b,reference) (the page can switch it).")
  in
  let quiet =
    Arg.(
      value & flag
      & info [ "q"; "quiet" ]
          ~doc:"Print only the address and scene errors (not the time each version took).")
  in
  let man =
    [
      `S Manpage.s_description;
      `P
        "Starts a web server on this machine and prints its address. The page shows the \
         scene, first coarse (one sample every 8, 4, then 2 pixels), then at preview \
         quality, then at the chosen quality, each image replacing the last. Saving the \
         scene, or any file it includes or loads, renders it again and cancels the \
         render in progress; a scene error is shown over the last good image until the \
         file is fixed. An animation gets a time slider and play/pause. The page shows \
         what the render cost and can switch the quality preset. It writes no output \
         file (frames are the job of $(b,animate)); the page has a button that saves the \
         current view as a PNG.";
      `P
        "The server listens on one loopback address unless $(b,--listen-beyond-loopback) \
         says otherwise, answers only requests addressed to it and, from a browser, only \
         those of its own page, and bounds what a client may cost: 16 KiB of request \
         headers, 4 KiB of body, 10 seconds to send a complete request (or to take an \
         answer being written), 64 connections at once (past them, the one that has \
         waited longest for its request is closed).";
      `S Manpage.s_examples;
      `Pre "  lancer watch scenes/showcase.rts";
      `Pre "  lancer watch scene.rts --port 9000 --quality final --width 640 --height 480";
    ]
    @ Cli.bugs
  in
  let term =
    Term.(
      const
        (fun
          scene
          port
          host
          beyond_loopback
          any_source_line
          poll
          width
          height
          samples
          depth
          domains
          quality
          quiet
          max_error
        ->
          let o =
            {
              Options.default with
              scene = Some scene;
              width;
              height;
              samples;
              depth;
              domains;
              quality;
              quiet;
            }
          in
          Report.run ~interrupted:"the preview server stopped" (fun stop ->
              ignore (Report.on_interrupt stop);
              Lancer_preview.Preview.run ?max_error o ~host ~port ~poll ~beyond_loopback
                ~any_source_line))
      $ scene $ port $ host $ beyond_loopback $ any_source_line $ poll $ width $ height
      $ samples $ depth $ domains $ quality $ quiet $ Cli.max_error_term)
  in
  Cmd.v (Cmd.info "watch" ~doc ~man ~exits:Cli.exits ~envs:Cli.envs) term
