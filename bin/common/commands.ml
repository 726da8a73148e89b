(* The lancer command line: argument parsing and one library call per command. *)
open Lancer
open Lancer_job
open Cmdliner

let resumed_interrupt = Report.resumed_interrupt

(* What rendering an image allocates beside the scene, at most, per pixel: the
   framebuffer's three floats, as many for its encoding, an alpha channel, the samples'
   bytes and a compressed copy. *)
let image_bytes (sc : Scene.t) = 64 * sc.settings.width * sc.settings.height

let render_cmd stop (o : Cli.opts) ~resume (enc : Cli.encoding) =
  let cancel = Report.on_interrupt stop in
  let out = Cli.default_output o in
  Cli.check_output ?format:enc.format out;
  Cli.check_stats_name o.stats;
  Option.iter Cli.check_writable o.stats;
  let domains = Cli.domains o in
  let (sc, files, src, time, frame), build =
    Cli.build o (fun say ->
        say
          (Printf.sprintf "reading and checking %s"
             (Option.value o.scene ~default:"the showcase"));
        (* Only a checkpoint's key needs the digests of the files the scene reads. *)
        let prog = Cli.load ~progress:say ~digests:resume o.scene in
        (* One scene of it: a still's description may go as it is compiled. *)
        Program.single_scene prog;
        let src = Cli.scene_source o prog in
        let time, frame = Cli.time_of o src in
        say "evaluating the scene and building its acceleration structure";
        let sc, files = Cli.scene_with_files ~progress:say o src ~time ~frame in
        (* Evaluating a large scene leaves garbage (the evaluator's values, the objects
           compiled): it is given back before the framebuffer is allocated, so that peak
           memory is the scene plus the image, unless the heap as it is and the image's
           buffers fit in the most the heap has already been (compacting a million
           objects takes a tenth of the build). *)
        let g = Gc.quick_stat () in
        let bytes w = w * (Sys.word_size / 8) in
        if bytes g.heap_words + image_bytes sc > bytes g.top_heap_words then Gc.compact ();
        (sc, files, src, time, frame))
  in
  Cli.guard_render o src ~out;
  Cli.warn_long_render o sc;
  Cli.check_encoding enc ~out sc;
  if resume && Cli.is_stdout out then
    Cli.user
      "--resume keeps its checkpoint beside the output file: it cannot be combined with \
       -o - (standard output)";
  if resume && (enc.alpha || enc.region <> None) then
    Cli.user
      "--resume keeps a checkpoint of the whole image: it cannot be combined with \
       --alpha or --region";
  let region = enc.region in
  let progress =
    Cli.progress o ~label:"tiles" ~total:(Array.length (Render.tiles ?region sc))
  in
  let alpha =
    if enc.alpha then Some (Float.Array.make (sc.settings.width * sc.settings.height) 0.)
    else None
  in
  (* Before the clock starts: the checkpoint's key reads the files' digests. *)
  let checkpoint =
    if resume then Some (Cli.checkpoint o src ~out ~time ~frame ~files sc) else None
  in
  let t0 = Unix.gettimeofday () in
  let fb, st =
    Still.render ~cancel ?checkpoint ?region ?alpha ~domains
      ~on_tile:(fun d rays -> Progress.update ~rays progress d)
      sc
  in
  let wall = Unix.gettimeofday () -. t0 in
  Progress.finish progress;
  Cli.writing o out (fun () -> Cli.write_image ~cancel ~encoding:enc ?alpha out sc fb);
  Option.iter Checkpoint.remove checkpoint;
  Cli.warn_bad_samples st;
  Option.iter
    (fun p ->
      Cli.write_json ~cancel p (Cli.stats_json o sc ~build ~wall ~domains ~ranks:1 st))
    o.stats;
  if not o.quiet then
    let size =
      match enc.region with
      | Some r when enc.crop -> Some (r.x1 - r.x0, r.y1 - r.y0)
      | _ -> None
    in
    let line =
      Cli.summary ?size
        ~out:(if Cli.is_stdout out then "the image to standard output" else out)
        sc ~build ~render:wall
        ~workers:(Printf.sprintf "%d domains" domains)
        st
    in
    (* With -o -, standard output is the image's alone. *)
    if Cli.is_stdout out then prerr_endline line else print_endline line

(* "12..20, 30": frame numbers (ascending) as runs. *)
let runs ks =
  let rec go acc = function
    | [] -> List.rev acc
    | k :: rest -> (
        match acc with
        | (a, b) :: acc' when k = b + 1 -> go ((a, k) :: acc') rest
        | _ -> go ((k, k) :: acc) rest)
  in
  String.concat ", "
    (List.map
       (fun (a, b) -> if a = b then string_of_int a else Printf.sprintf "%d..%d" a b)
       (go [] ks))

(* The frames [--frames] names: "all", A..B or K, within the animation (a still has
   frame 0 only). *)
let check_frames prog spec =
  let fps, count =
    match Program.animation prog with Some (fps, n) -> (fps, n) | None -> (24., 1)
  in
  let first, last =
    if String.equal spec "all" then (0, count - 1)
    else
      match Animate.frames_of_string spec with
      | Ok r -> r
      | Error _ -> Cli.user "--frames expects all, A..B or K (got %S)" spec
  in
  if first < 0 || first > last then
    Cli.user "--frames %s: the first frame must be at least 0 and at most the last" spec;
  if last >= count then
    if Program.animation prog = None then
      Cli.user "--frames %s: the scene is a still (frame 0 only)" spec
    else Cli.user "--frames %s: the animation has frames 0..%d" spec (count - 1);
  (fps, first, last)

let check_cmd stop scene json time frames =
  ignore (Report.on_interrupt stop);
  let o = { (Cli.default_opts ()) with scene = Some scene; time } in
  let prog = Cli.load o.scene in
  match frames with
  | None -> (
      let time, frame = Cli.time_of o (Cli.scene_source o prog) in
      (* Check reads the scene's objects, features and estimates, and traces no ray: no
         acceleration structure. Its summary needs one scene and not the description's
         objects, which may go as they are compiled; the JSON lists them. *)
      if not json then Program.single_scene prog;
      match Program.scene_at ~index:false prog ~time ~frame with
      | Error errors -> raise (Job_error.Scene { errors; note = "" })
      | Ok sc ->
          if json then print_endline (Yojson.Safe.pretty_to_string (Program.to_json prog sc))
          else (
            print_string (Program.summary prog sc);
            print_string (Cli.cost_report sc)))
  | Some _ when time <> None -> Cli.user "give either --time or --frames, not both"
  | Some _ when json ->
      Cli.user "--json prints one frame: choose it with --time, not --frames"
  | Some spec ->
      let fps, first, last = check_frames prog spec in
      (* Every frame is evaluated; the errors of the first that fails are shown, and the
         others that fail are listed. *)
      let first_scene = ref None and failed = ref [] and first_errors = ref [] in
      for k = first to last do
        match Program.scene_at ~index:false prog ~time:(Float.of_int k /. fps) ~frame:k with
        | Ok sc -> if Option.is_none !first_scene then first_scene := Some sc
        | Error errs ->
            if !failed = [] then first_errors := errs;
            failed := k :: !failed
      done;
      let n = last - first + 1 in
      (match List.rev !failed with
      | [] -> ()
      | ks ->
          raise
            (Job_error.Scene
               {
                 errors = !first_errors;
                 note =
                   Printf.sprintf "%d of the %d frames checked (%d..%d) fail: %s"
                     (List.length ks) n first last (runs ks);
               }));
      (match !first_scene with
      | Some sc -> print_string (Program.summary prog sc)
      | None -> ());
      Printf.printf "frames checked: %d..%d (%d frame%s), every one evaluates\n" first
        last n
        (if n = 1 then "" else "s")

(* The bounds of --tolerance and --max-share, shared by diff and golden. *)
let check_tolerance tolerance share =
  if tolerance < 0 || tolerance > 255 then
    Cli.user "--tolerance must be between 0 and 255 (got %d)" tolerance;
  if not (share >= 0. && share <= 1.) then
    Cli.user "--max-share must be between 0 and 1 (got %g)" share

(* One word for the outcome, before the figures. *)
let verdict ~tolerance ~share (c : Compare.t) =
  if c.max_diff = 0 then "same"
  else if Compare.within ~max_diff:tolerance ~max_share:share c then "within tolerance"
  else "differ"

let diff_cmd a b out tolerance share =
  check_tolerance tolerance share;
  Option.iter
    (fun p ->
      Cli.guard_writes
        ~reads:[ (a, "an image this diff compares"); (b, "an image this diff compares") ]
        [ (p, "the diff image") ])
    out;
  let read p =
    match Image.read_rgb8 p with Ok i -> i | Error m -> raise (Cli.User_error m)
  in
  let ((wa, ha, _) as ia) = read a and ((wb, hb, _) as ib) = read b in
  if (wa, ha) <> (wb, hb) then
    Cli.user "%s is %d×%d but %s is %d×%d: only images of the same size can be compared" a
      wa ha b wb hb;
  match Compare.compare ~threshold:tolerance ia ib with
  | Error m -> raise (Cli.User_error m)
  | Ok c ->
      Format.printf "%s: %a@." (verdict ~tolerance ~share c) Compare.pp c;
      Option.iter
        (fun p ->
          let w, h, _ = ia in
          match
            Image.write_rgb8 p w h (Compare.diff_image ~threshold:tolerance ia ib)
          with
          | Ok () -> Printf.printf "diff image: %s\n" p
          | Error m -> raise (Cli.User_error m))
        out;
      if not (Compare.within ~max_diff:tolerance ~max_share:share c) then exit 1

(* Render a scene and hold it against a golden PNG, as lancer-alcotest does in a test. *)
let golden_cmd stop (o : Cli.opts) golden tolerance share update =
  let cancel = Report.on_interrupt stop in
  check_tolerance tolerance share;
  let src = Cli.scene_source o (Cli.load o.scene) in
  let time, frame = Cli.time_of o src in
  let sc = Cli.scene_at o src ~time ~frame in
  (* A golden of another size can never match: say so before rendering, and how to fix it. *)
  (if (not update) && Sys.file_exists golden then
     match Image.read_rgb8 golden with
     | Ok (gw, gh, _) when (gw, gh) <> (sc.settings.width, sc.settings.height) ->
         Cli.user
           "the golden %s is %d×%d but the render would be %d×%d: render at the golden's \
            size with --width %d --height %d, or remake the golden with --update"
           golden gw gh sc.settings.width sc.settings.height gw gh
     | _ -> ());
  let sibling suffix = Filename.remove_extension golden ^ suffix in
  Cli.guard_writes
    ~reads:
      (if update then Cli.reads src else (golden, "the golden image") :: Cli.reads src)
    (if update then [ (golden, "the golden image") ]
     else
       [
         (sibling ".actual.png", "the actual image");
         (sibling ".diff.png", "the diff image");
       ]);
  let progress = Cli.progress o ~label:"tiles" ~total:(Array.length (Render.tiles sc)) in
  let fb, _ =
    Render.with_pool ~cancel (Cli.domains o) (fun pool ->
        Render.render ~cancel ?pool
          ~on_tile:(fun d _ rays -> Progress.update ~rays progress d)
          sc)
  in
  Progress.finish progress;
  let actual = (fb.width, fb.height, Image.to_bytes sc.settings.gamma fb) in
  match Compare.golden ~tolerance ~max_share:share ~update ~golden actual with
  | Error m -> Cli.user "%s" m
  | Ok (Compare.Updated g) -> if not o.quiet then Printf.printf "golden written: %s\n" g
  | Ok (Compare.Missing { actual }) ->
      Cli.user
        "%s does not exist; the render is in %s (run again with --update to make it the \
         golden)"
        golden actual
  | Ok (Compare.Same c) ->
      if not o.quiet then
        Format.printf "%s %s: %a@."
          (if c.max_diff = 0 then "same as" else "within tolerance of")
          golden Compare.pp c
  | Ok (Compare.Different { figures; actual; diff }) ->
      Format.printf "differs from %s: %a@.actual: %s@.diff: %s@." golden Compare.pp
        figures actual diff;
      exit 1

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
        "  lancer render big.rts -o big.png --resume    # again after an interruption: \
         continues";
    ]
  in
  Cmd.v
    (Cmd.info "render" ~doc ~man ~exits)
    Term.(
      const (fun o resume e ->
          Report.run
            ?interrupted:(if resume then Some resumed_interrupt else None)
            (fun stop -> render_cmd stop o ~resume e))
      $ Cli.opts_term $ Cli.resume_still $ Cli.encoding_term)

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
    ]
  in
  Cmd.v
    (Cmd.info "animate" ~doc ~man ~exits)
    Term.(
      const (fun o a ->
          Report.run ~interrupted:Animate.interrupted (fun stop -> Animate.run stop o a))
      $ Cli.(term Animate)
      $ Animate.options_term)

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
      `S Manpage.s_examples;
      `Pre "  lancer check scenes/showcase.rts";
      `Pre "  lancer check anim.rts --json --time 1.5";
      `Pre "  lancer check scenes/bounce.rts --frames all";
      `Pre "  generate-scene | lancer check -";
    ]
  in
  Cmd.v
    (Cmd.info "check" ~doc ~man ~exits)
    Term.(
      const (fun s j t f -> wrap (fun stop -> check_cmd stop s j t f))
      $ scene $ json $ time $ frames)

let diff =
  let doc = "compare two images; exit status 1 when they differ beyond the tolerance" in
  let a = Arg.(required & pos 0 (some file) None & info [] ~docv:"A.png") in
  let b = Arg.(required & pos 1 (some file) None & info [] ~docv:"B.png") in
  let out =
    Arg.(
      value
      & opt (some string) None
      & info [ "o"; "output" ] ~docv:"DIFF.png" ~doc:"Write a picture of the differences.")
  in
  let tol =
    Arg.(
      value & opt int 1
      & info [ "tolerance" ] ~docv:"N"
          ~doc:"Largest per-channel difference (0–255) that still counts as equal.")
  in
  let share =
    Arg.(
      value & opt float 0.
      & info [ "max-share" ] ~docv:"F"
          ~doc:"Share of pixels (0–1) allowed to exceed the tolerance.")
  in
  let man =
    [
      `S Manpage.s_examples;
      `Pre "  lancer diff expected.png actual.png -o diff.png --tolerance 2";
    ]
  in
  Cmd.v
    (Cmd.info "diff" ~doc ~man ~exits)
    Term.(
      const (fun a b o t s -> wrap (fun _ -> diff_cmd a b o t s))
      $ a $ b $ out $ tol $ share)

let golden =
  let doc =
    "render a scene and compare it with a golden image; exit status 1 when they differ"
  in
  let golden = Arg.(required & pos 1 (some string) None & info [] ~docv:"GOLDEN.png") in
  let tol =
    Arg.(
      value & opt int 1
      & info [ "tolerance" ] ~docv:"N"
          ~doc:"Largest per-channel difference (0–255) that still counts as equal.")
  in
  let share =
    Arg.(
      value & opt float 0.
      & info [ "max-share" ] ~docv:"F"
          ~doc:"Share of pixels (0–1) allowed to exceed the tolerance.")
  in
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
         GOLDEN.diff.png (differences in red) are written next to the golden, and the \
         exit status is 1.";
      `S Manpage.s_examples;
      `Pre "  lancer golden scene.rts tests/scene.png --width 160 --height 120";
      `Pre
        "  lancer golden scene.rts tests/scene.png --width 160 --height 120 --update   # \
         (re)make the golden";
    ]
  in
  let term =
    Term.(
      const (fun (o : Cli.opts) g t sh u -> wrap (fun stop -> golden_cmd stop o g t sh u))
      $ Cli.(term Golden)
      $ golden $ tol $ share $ update)
  in
  Cmd.v (Cmd.info "golden" ~doc ~man ~exits) term

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
  in
  let info = Cmd.info "lancer" ~version:Lancer.Version.v ~doc ~man ~exits in
  (* Report.main ends the process: what help, --version or a command printed that
     standard output cannot take is reported there, not at exit. *)
  Report.main (fun () ->
      let code =
        Cmd.eval'
          (Cmd.group info [ render; animate; check; diff; golden; Watch.cmd; Bench.cmd ])
      in
      if code = Cmd.Exit.cli_error then
        Option.iter (Report.say ~program:"lancer") (Cli.negative_value_hint Sys.argv);
      Cli.status_of_eval code)
