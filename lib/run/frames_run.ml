type options = {
  frames : (int * int) option;
  resume : bool;
  video : string option;
  shard : Plan.shard option;
  format : Image.format;
  bits : int option;
}

let default_options =
  {
    frames = None;
    resume = false;
    video = None;
    shard = None;
    format = Image.Png;
    bits = None;
  }

(* What an animation's frames owe to --max-error, named for the job's digest: a limit
   and its metric (the settings follow from them and the scene). *)
let budget_job = function
  | None -> []
  | Some m ->
      let r = Budget.record_of_limit m in
      [
        ("--max-error", Printf.sprintf "%.12g" r.Provenance.limit); ("--metric", r.metric);
      ]

let plan ?getenv ?max_error (o : Options.t) (a : options) =
  let program = ref None in
  (* The options first, as every command checks them: then the shard and the scene. *)
  ignore (Options.domains o);
  let p =
    Animation.plan ?getenv ~format:a.format ?bits:a.bits ~job:(budget_job max_error)
      ~dir:o.output ~frames:a.frames ~shard:a.shard ~resume:a.resume
      ~overrides:(Options.overrides o) (fun () ->
        let prog = Scene_file.load_source (Scene_file.read o.scene) in
        program := Some prog;
        Scene_file.source o prog)
  in
  if not o.quiet then (
    if p.resumed > 0 then
      Printf.printf "resuming: %s already rendered, %d to go\n%!"
        (Animation.frames_text p.resumed)
        (List.length p.todo);
    List.iter
      (fun (why, ks) ->
        Printf.printf "rendering %s again (%s): %s\n%!"
          (Animation.frames_text (List.length ks))
          (Check_run.runs ks) why)
      p.stale);
  (Option.get !program, p)

let write_frame p k sc fb st =
  Render_report.warn_bad_samples st;
  Animation.write_frame p k sc fb

let make_video (o : Options.t) p out =
  Animation.make_video p out;
  if not o.quiet then Printf.printf "video: %s\n" out

let progress o (p : Animation.plan) =
  Progress.for_options o ~label:"frames" ~total:(List.length p.todo)

let interrupted = "the frames written so far are kept; run again with --resume to finish"

let check_video (a : options) =
  Option.iter (Animation.check_video ~format:a.format ~shard:(a.shard <> None)) a.video

let wrote ?(extra = "") (o : Options.t) (p : Animation.plan) ~t0 =
  if not o.quiet then
    Printf.printf "wrote %s to %s in %.2f s (%s%s)\n%!"
      (Animation.frames_text (List.length p.todo))
      p.dir
      (Unix.gettimeofday () -. t0)
      (Animation.describe_range p) extra

(* --max-error over an animation: the choice of the first, middle and last frames of the
   whole animation (whatever --frames renders) that costs the most rays (the earliest of
   equals), the same for every frame (the settings do not change from one frame to the
   next), every shard and every range: a function of the scene and the limit, as the
   job's digest says. *)
let choose ?cancel ~domains (o : Options.t) (p : Animation.plan) limit =
  let count = match p.source.animation with Some (_, n) -> n | None -> p.last + 1 in
  let frames = List.sort_uniq compare [ 0; (count - 1) / 2; count - 1 ] in
  let choices =
    List.map
      (fun k ->
        let time = Float.of_int k /. p.fps in
        let base, _ = Scenes.scene ?cancel p.source p.overrides ~time ~frame:k in
        (k, Budget.choose ?cancel ~domains o p.source base ~time ~frame:k limit))
      frames
  in
  let k, c =
    List.fold_left
      (fun ((_, b) as best) ((_, c) as kc) ->
        if c.Budget.rays > b.Budget.rays then kc else best)
      (List.hd choices) (List.tl choices)
  in
  if not o.quiet then
    Printf.printf "%s; chosen on frame %d, the costliest of frames %s\n%!" (Budget.text c)
      k
      (String.concat ", " (List.map string_of_int frames));
  Animation.with_settings p (Budget.record c) (fun sc ~time ~frame ->
      Budget.apply ?cancel p.source p.overrides sc ~time ~frame c.values)

let run ?cancel ?max_error (o : Options.t) (a : options) =
  Option.iter
    (fun m ->
      Budget.check m;
      Budget.check_options o ~resume:false)
    max_error;
  check_video a;
  let _, p = plan ?max_error o a in
  let domains = Options.domains o in
  let p =
    match max_error with
    | Some m when p.todo <> [] -> choose ?cancel ~domains o p m
    | _ -> p
  in
  let bar = progress o p in
  let t0 = Unix.gettimeofday () in
  let finished = Atomic.make 0 in
  Animation.render ?cancel ~domains p ~on_frame:(fun _ st ->
      Render_report.warn_bad_samples st;
      Progress.update ~rays:(Counters.total_rays st) bar
        (Atomic.fetch_and_add finished 1 + 1));
  Progress.finish bar;
  Animation.finish p;
  wrote o p ~t0;
  Option.iter (make_video o p) a.video
