let user = Job_error.user

type built = {
  program : Program.t;
  source : Scenes.t;
  scene : Scene.t;
  files : string list;
  time : float;
  frame : int;
  seconds : float;
}

let check_outputs ?format (o : Options.t) ~out =
  Output.check_output ?format out;
  let stats = Output.stats_file o in
  Output.check_stats_name stats;
  Option.iter Files.check_writable stats

(* What rendering an image allocates beside the scene, at most, per pixel: the
   framebuffer's three floats, as many for its encoding, an alpha channel, the samples'
   bytes and a compressed copy. *)
let image_bytes (sc : Scene.t) = 64 * sc.settings.width * sc.settings.height

let build ?digests (o : Options.t) =
  let (program, source, scene, files, time, frame), seconds =
    Progress.build o (fun say ->
        say
          (Printf.sprintf "reading and checking %s"
             (Option.value o.scene ~default:"the showcase"));
        (* One scene of it: a still's description may go as it is compiled. *)
        let prog =
          Scene_file.load ~single:(Options.at_start o) ~progress:say ?digests o.scene
        in
        let src = Scene_file.source o prog in
        let time, frame = Options.time_of o src in
        say "evaluating the scene and building its acceleration structure";
        let sc, files =
          Scenes.scene ~progress:say src (Options.overrides o) ~time ~frame
        in
        (* Evaluating a large scene leaves garbage (the evaluator's values, the objects
           compiled): it is given back before the framebuffer is allocated, so that peak
           memory is the scene plus the image, unless the heap as it is and the image's
           buffers fit in the most the heap has already been (compacting a million
           objects takes a tenth of the build), or the image is under a sixteenth of the
           heap, so that it can raise the peak by no more than that: compacting the heap
           of a million coloured spheres for a preview at 64×48 took 0.3 s of its 1.5 s. *)
        let g = Gc.quick_stat () in
        let bytes w = w * (Sys.word_size / 8) in
        let image = image_bytes sc and heap = bytes g.heap_words in
        if image >= heap / 16 && heap + image > bytes g.top_heap_words then Gc.compact ();
        (prog, src, sc, files, time, frame))
  in
  { program; source; scene; files; time; frame; seconds }

(* A line for the user: on standard output, unless the image ([-o -]) or the statistics
   ([--stats -]) go there, then on standard error. *)
let tell (o : Options.t) ~out line =
  if Output.is_stdout out || Output.stats_to_stdout o then prerr_endline line
  else print_endline line

let checkpoint (o : Options.t) (b : built) ~out =
  let key =
    Checkpoint.key b.source (Options.overrides o) ~time:b.time ~frame:b.frame
      ~files:b.files
  in
  let ck = Checkpoint.start ~out ~key b.scene in
  if Checkpoint.resumed ck > 0 && not o.quiet then
    tell o ~out
      (Printf.sprintf "resuming: %d of %d tiles already rendered" (Checkpoint.resumed ck)
         (Checkpoint.tiles ck));
  ck

let record ?max_error (o : Options.t) (b : built) (enc : Output.encoding) ~out =
  Provenance.make ?max_error ~image:out b.source (Options.overrides o)
    ~files:(List.map (fun f -> (f, b.source.input_digest f)) b.files)
    ~time:b.time ~frame:b.frame ~region:enc.region ~crop:enc.crop ~alpha:enc.alpha
    ~bits:(Option.value enc.bits ~default:8)

let finish ?cancel ?(encoding = Output.default_encoding) ?alpha ?record ?(extra = [])
    (o : Options.t) ~out ~checkpoint ~build ~wall ~domains ~ranks ~workers sc fb st =
  Progress.writing o out (fun () ->
      Output.write_image ?cancel ~encoding ?alpha ?record out sc fb);
  Option.iter Checkpoint.remove checkpoint;
  let resumed_rays = Option.fold ~none:0 ~some:Checkpoint.resumed_rays checkpoint in
  Render_report.warn_bad_samples st;
  Option.iter
    (fun p ->
      let j =
        match
          Render_report.stats_json ~resumed_rays o sc ~build ~wall ~domains ~ranks st
        with
        | `Assoc l -> `Assoc (l @ extra)
        | j -> j
      in
      if Output.stats_to_stdout o then Output.write_stats_stdout j
      else Files.write_json ?cancel p j)
    o.stats;
  if not o.quiet then
    let size =
      match encoding.region with
      | Some r when encoding.crop -> Some (r.x1 - r.x0, r.y1 - r.y0)
      | _ -> None
    in
    let stdout = Output.is_stdout out in
    let line =
      Render_report.summary ?size ~resumed_rays
        ~out:(if stdout then "the image to standard output" else out)
        sc ~build ~render:wall ~workers st
    in
    tell o ~out line

(* The images of [--aov] beside [out]: checked before any work, made after the image. *)
let aov_files kinds ~out =
  if kinds <> [] && Output.is_stdout out then
    user "--aov writes its images beside the image file: it cannot be combined with -o -";
  List.concat_map (Aov_run.paths out) kinds

let run ?cancel ?(aov = []) ?max_error (o : Options.t) ~resume (enc : Output.encoding) =
  Option.iter
    (fun m ->
      Budget.check m;
      Budget.check_options o ~resume)
    max_error;
  let out = Scene_file.default_output o in
  check_outputs ?format:enc.format o ~out;
  let aov_paths = aov_files aov ~out in
  let domains = Options.domains o in
  (* The image's record and a checkpoint's key hold the digests of the files the scene
     read: of the bytes it read. An image without a record (PPM, HDR, PFM) rendered
     without --resume needs neither: the files are not digested (a 41 MB mesh's MD5 is
     about a twentieth of its load). *)
  let keeps_record = Image.keeps_record (Output.format_of ?format:enc.format out) in
  let b = build ~digests:(keeps_record || resume) o in
  (* With --max-error, the scene at the settings it chooses, said before the render. *)
  let choice =
    Option.map
      (fun m ->
        let c =
          Budget.choose ?cancel ~domains o b.source b.scene ~time:b.time ~frame:b.frame m
        in
        if not o.quiet then tell o ~out (Budget.text c);
        c)
      max_error
  in
  let sc = match choice with Some c -> c.scene | None -> b.scene in
  Output.guard_render o b.source ~out;
  if aov_paths <> [] then
    Files.guard_writes ~reads:(Scenes.reads b.source)
      ((out, "the image") :: List.map (fun p -> (p, "an --aov image")) aov_paths);
  (* What lancer check warns of, before the render rather than after it. *)
  if not o.quiet then
    List.iter
      (fun w -> Printf.eprintf "%s%!" (Diagnostic.to_string w))
      (Program.warnings b.program sc);
  Render_report.warn_long_render o sc;
  Output.check_encoding enc ~out sc;
  if resume && Output.is_stdout out then
    user
      "--resume keeps its checkpoint beside the output file: it cannot be combined with \
       -o - (standard output)";
  if resume && (enc.alpha || enc.region <> None) then
    user
      "--resume keeps a checkpoint of the whole image: it cannot be combined with \
       --alpha or --region";
  let region = enc.region in
  let progress =
    Progress.for_options o ~label:"tiles" ~total:(Array.length (Render.tiles ?region sc))
  in
  let alpha =
    if enc.alpha then Some (Float.Array.make (sc.settings.width * sc.settings.height) 0.)
    else None
  in
  (* Before the clock starts: the checkpoint's key reads the files' digests. *)
  let checkpoint = if resume then Some (checkpoint o b ~out) else None in
  let t0 = Unix.gettimeofday () in
  let fb, st =
    Still.render ?cancel ?checkpoint ?region ?alpha ~domains
      ~on_tile:(fun d rays -> Progress.update ~rays progress d)
      sc
  in
  let wall = Unix.gettimeofday () -. t0 in
  Progress.finish progress;
  (* With --max-error, the record keeps the settings it chose beside the options. *)
  let record =
    if keeps_record then
      Some (record ?max_error:(Option.map Budget.record choice) o b enc ~out)
    else None
  in
  let extra =
    match choice with Some c -> [ ("max_error", Budget.json c) ] | None -> []
  in
  finish ?cancel ~encoding:enc ?alpha ?record ~extra o ~out ~checkpoint ~build:b.seconds
    ~wall ~domains ~ranks:1
    ~workers:(Printf.sprintf "%d domains" domains)
    sc fb st;
  if aov <> [] then (
    let objects = Aov_run.objects b.program ~time:b.time ~frame:b.frame sc in
    Aov_run.write aov ~out objects (Aov.primary sc);
    if not o.quiet then tell o ~out ("AOV images: " ^ String.concat ", " aov_paths))
