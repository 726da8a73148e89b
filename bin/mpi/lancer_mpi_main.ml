(* lancer-mpi render|animate: lancer's render and animate over Open MPI ranks
   (doc/reference/mpi.md), with the same options and the same bytes. Every rank parses the
   same command line; rank 0 alone reads the scene file and its includes, checks
   everything, reports errors and writes files. It broadcasts the texts it read (or that
   the job is over, when there is an error) before any work starts, so that the other
   ranks read no scene file (one edited meanwhile cannot make an image of two versions)
   and every rank leaves with the same status. Images and meshes are read by each rank;
   each unit comes back with their digests, and rank 0 refuses pixels made of other bytes
   than its own scene. The work itself is Farm's. *)

open Lancer
open Cmdliner
module Cli = Lancer_cli.Cli
module Report = Lancer_cli.Report
module Mpi = Lancer_mpi.Mpi
module Farm = Lancer_mpi.Farm

(* What rank 0 broadcasts once its checks are done. *)
type setup = Go of Program.bundle | Quit

let user = Job_error.user

let ranks_text domains =
  match Mpi.size () with
  | 1 -> Printf.sprintf "1 rank, %d domain%s" domains (if domains = 1 then "" else "s")
  | n ->
      Printf.sprintf "%d ranks × %d domain%s, rank 0 also serving" n domains
        (if domains = 1 then "" else "s")

(* mpirun stops every rank with SIGTERM, on Ctrl-C and when a rank has died: rank 0 cannot
   tell which, and says both. *)
let terminated ~resume =
  "stopped by SIGTERM, which mpirun sends on Ctrl-C and when another rank has died \
   (mpirun says which rank and why); "
  ^ if resume then Report.resumed_interrupt else "no output was written"

(* How rank 0 reports an exception that ends the job, and the status it ends with; with
   --resume the finished tiles are in the checkpoint, and the message says so. *)
let fatal ~resume stop e =
  Report.fail
    ?interrupted:(if resume then Some Report.resumed_interrupt else None)
    ~terminated:(terminated ~resume) stop e

(* The skeleton of both commands. [prepare] runs on rank 0 only and is (the program's
   texts, state); [lead] runs on rank 0 with the pool its own units are rendered over;
   [scene_of prog key] is the scene of a frame on the other ranks, with the files it was
   made of and their digests. *)
let distributed ?(resume = false) (o : Options.t) ~prepare ~lead ~scene_of =
  if Mpi.rank () = 0 then
    Report.run
      ?interrupted:(if resume then Some Report.resumed_interrupt else None)
      ~terminated:(terminated ~resume)
      (fun stop ->
        let cancel = Report.on_interrupt stop in
        let source, state =
          try prepare ()
          with e ->
            ignore (Mpi.bcast Quit ~root:0);
            raise e
        in
        ignore (Mpi.bcast (Go source) ~root:0);
        let domains = Options.domains o in
        try
          Render.with_pool ~cancel domains (fun pool ->
              lead state ~fatal:(fatal ~resume stop) ~cancel ~pool ~domains)
        with Farm.Worker_failed (rank, m) -> user "rank %d: %s" rank m)
  else
    match Mpi.bcast Quit ~root:0 with
    | Quit -> 1
    | Go bundle ->
        (* Rank 0 has loaded the same texts, so errors here are unexpected: they reach
           rank 0 through Farm and are reported there. *)
        let prog = lazy (Scene_file.load_bundle bundle) in
        let domains =
          match o.domains with
          | Some n when n >= 1 -> n
          | _ -> max 1 (Domain.recommended_domain_count ())
        in
        Render.with_pool domains (fun pool ->
            Farm.work ~describe:Job_error.message ~pool ~domains
              ~prepare:(fun () -> ignore (Lazy.force prog))
              (fun key -> scene_of (Lazy.force prog) key));
        0

(* The files a scene was made of, each with its digest: what a unit is checked by. *)
let with_digests (src : Scenes.t) files =
  List.map (fun f -> (f, src.input_digest f)) files

(* ---- render ---- *)

let render_cmd (o : Options.t) ~resume =
  let still ?progress src =
    let time, frame = Options.time_of o src in
    Scenes.scene ?progress src (Options.overrides o) ~time ~frame
  in
  let prepare () =
    let out = Scene_file.default_output o in
    if Output.is_stdout out then
      user
        "lancer-mpi writes its image to a file; -o - (standard output) is for lancer \
         render";
    Still_run.check_outputs o ~out;
    ignore (Options.domains o);
    let text = Scene_file.read o.scene in
    let (program, source, scene, files), seconds =
      Progress.build o (fun say ->
          say "loading and evaluating the scene";
          let prog = Scene_file.load_source ~progress:say text in
          let src = Scene_file.source o prog in
          let sc, files = still ~progress:say src in
          (prog, src, sc, files))
    in
    let time, frame = Options.time_of o source in
    let b = { Still_run.program; source; scene; files; time; frame; seconds } in
    Output.guard_render o source ~out;
    (* With --resume rank 0 keeps the finished tiles in a checkpoint beside the output. *)
    let ck = if resume then Some (Still_run.checkpoint o b ~out) else None in
    (Program.bundle program, (out, b, ck, with_digests source files))
  in
  let lead (out, (b : Still_run.built), ck, inputs) ~fatal ~cancel ~pool ~domains =
    let module Ck = Checkpoint in
    let total =
      match ck with
      | Some ck -> Array.length (Ck.todo ck)
      | None -> Array.length (Render.tiles b.scene)
    in
    let progress = Progress.for_options o ~label:"tiles" ~total in
    let t0 = Unix.gettimeofday () in
    let result = ref None in
    (* An interrupt ends the job through [fatal]: with --resume, the finished tiles are
       written to the checkpoint first, as lancer render does. *)
    let fatal e =
      match (e, ck) with
      | Sys.Break, Some ck -> (
          match Ck.save ck with
          | () -> fatal e
          | exception Job_error.User m ->
              fatal (Job_error.Interrupted ("the finished tiles could not be kept: " ^ m))
          )
      | _ -> fatal e
    in
    let report =
      Farm.serve
        ~start:(fun _ -> Option.map (fun ck -> (Ck.framebuffer ck, Ck.todo ck)) ck)
        ~on_unit:(fun _ tiles st -> Option.iter (fun ck -> Ck.tiles_done ck tiles st) ck)
        ~inputs:(fun _ -> Some inputs)
        ~cancel ~fatal ~pool ~domains ~on_tiles:(Progress.update progress)
        ~on_frame:(fun _ _ fb st -> result := Some (fb, st))
        [ (0, fun () -> b.scene) ]
    in
    let wall = Unix.gettimeofday () -. t0 in
    Progress.finish progress;
    let fb, st =
      match !result with Some r -> r | None -> failwith "the frame never completed"
    in
    let st = match ck with Some ck -> Ck.stats ck | None -> st in
    (* Every pixel is here and every worker has been told to stop: the job ends now, so
       that the workers leave before the image is written. A worker killed while rank 0
       was still writing made mpirun kill rank 0 too, and the image was lost. *)
    let ranks = Mpi.size () and workers = ranks_text domains in
    Mpi.finalize ();
    Still_run.finish ~cancel
      ~record:(Still_run.record o b Output.default_encoding ~out)
      ~extra:[ ("mpi", Farm.report_json report) ]
      o ~out ~checkpoint:ck ~build:b.seconds ~wall ~domains ~ranks ~workers b.scene fb st
  in
  distributed ~resume o ~prepare ~lead ~scene_of:(fun prog _ ->
      let src = Scene_file.source o prog in
      let sc, files = still src in
      (sc, with_digests src files))

(* ---- animate ---- *)

(* The plan, frame names, manifest and digests are lancer animate's, so that either
   command can --resume the other's frames. *)
let animate_cmd (o : Options.t) (a : Frames_run.options) =
  let prepare () =
    Frames_run.check_video a;
    let prog, p = Frames_run.plan o a in
    (Program.bundle prog, p)
  in
  let lead (p : Animation.plan) ~fatal ~cancel ~pool ~domains =
    let progress = Frames_run.progress o p in
    let t0 = Unix.gettimeofday () in
    let written = ref 0 in
    (* Each frame is written atomically as soon as all its tiles are in, whatever order
       they finish in; the manifest follows each one. *)
    let on_frame k sc fb st =
      Frames_run.write_frame p k sc fb st;
      incr written;
      Progress.update progress !written
    in
    ignore
      (Farm.serve ~cancel ~fatal ~pool ~domains ~on_tiles:ignore ~on_frame
         ~inputs:(Animation.frame_inputs p)
         (List.map (fun k -> (k, fun () -> Animation.frame_scene ~cancel p k)) p.todo));
    Progress.finish progress;
    Animation.finish p;
    Frames_run.wrote ~extra:("; " ^ ranks_text domains) o p ~t0;
    Option.iter (Frames_run.make_video o p) a.video
  in
  let animation (src : Scenes.t) =
    match src.animation with
    | Some (fps, _) -> fps
    | None -> user "the scene has no animation block"
  in
  distributed o ~prepare ~lead ~scene_of:(fun prog k ->
      let src = Scene_file.source o prog in
      let sc, files =
        Scenes.scene src (Options.overrides o)
          ~time:(Float.of_int k /. animation src)
          ~frame:k
      in
      (sc, with_digests src files))

(* ---- command line ---- *)

let exits =
  [
    Cmd.Exit.info 0 ~doc:"on success.";
    Cmd.Exit.info 1
      ~doc:
        "on a user error (scene, option or file), reported once by rank 0; every rank \
         exits so.";
    Cmd.Exit.info 2
      ~doc:
        ("on an internal error: a bug in lancer; please report it at " ^ Cli.bug_tracker
       ^ ".");
  ]

let render =
  let doc = "render a scene to a PNG or PPM image over MPI ranks" in
  let man =
    [
      `S Manpage.s_description;
      `P
        "The same options and the same image bytes as $(b,lancer render). Rank 0 reads \
         the scene and hands out tiles; every other rank renders them with \
         $(b,--domains) domains.";
      `S Manpage.s_examples;
      `Pre
        "  mpirun -np 4 lancer-mpi render scenes/showcase.rts -o showcase.png --domains 2";
      `Pre
        "  mpirun --hostfile hosts -np 9 lancer-mpi render scene.rts --width 3840 \
         --height 2160 --quality final --resume";
    ]
    @ Cli.bugs
  in
  Cmd.v
    (Cmd.info "render" ~doc ~man ~exits ~envs:Cli.envs)
    Term.(
      const (fun o resume -> render_cmd o ~resume) $ Cli.(term Render) $ Cli.resume_still)

let animate =
  let doc = "render an animation's frames to DIR/frame_0000.png … over MPI ranks" in
  let man =
    [
      `S Manpage.s_description;
      `P
        "The same options and the same frames as $(b,lancer animate). Rank 0 hands out \
         whole frames (tiles when there are fewer frames than ranks) and writes each \
         frame once it is complete.";
      `S Manpage.s_examples;
      `Pre "  mpirun -np 4 lancer-mpi animate anim.rts -o frames/ --frames 0..47 --resume";
    ]
    @ Cli.bugs
  in
  Cmd.v
    (Cmd.info "animate" ~doc ~man ~exits ~envs:(Cli.envs @ Cli.slurm_envs))
    Term.(const animate_cmd $ Cli.(term Animate) $ Cli.frames_term)

let () =
  (* Interrupted before the command's own handler is in place (while MPI starts, or the
     options are read), rank 0 would otherwise exit into MPI_Finalize and wait there for
     the other ranks, which wait for it: the job would hang. Aborting ends every rank. *)
  (Report.early_exit := fun status -> Mpi.abort status);
  Mpi.init ();
  at_exit Mpi.finalize;
  let info =
    Cmd.info "lancer-mpi" ~version:Lancer.Version.v ~exits ~man:Cli.bugs
      ~envs:(Cli.envs @ Cli.slurm_envs)
      ~doc:"lancer's render and animate over Open MPI: run it under mpirun -np N"
  in
  let cmd = Cmd.group info [ render; animate ] in
  (* Every rank parses the same command line; only rank 0 speaks. *)
  Report.main (fun () ->
      let code =
        if Mpi.rank () = 0 then Cmd.eval' cmd
        else
          let null = Format.make_formatter (fun _ _ _ -> ()) ignore in
          Cmd.eval' ~help:null ~err:null cmd
      in
      if code = Cmd.Exit.cli_error && Mpi.rank () = 0 then
        Option.iter (Report.say ~program:"lancer-mpi") (Cli.negative_value_hint Sys.argv);
      Cli.status_of_eval code)
