(* lancer-mpi render|animate: lancer's render and animate over Open MPI ranks (SPEC §7,
   §8), with the same options and the same bytes. Every rank parses the same command
   line; rank 0 alone reads the scene file, checks everything, reports errors and
   writes files. It broadcasts the scene's text (or that the job is over, when there is
   an error) before any work starts, so that the other ranks need no file and every rank
   leaves with the same status. The work itself is Farm's. *)

open Lancer
open Cmdliner
module Cli = Lancer_cli.Cli
module Progress = Lancer_cli.Progress
module Dsl = Lancer_dsl.Dsl
module Mpi = Lancer_mpi.Mpi
module Farm = Lancer_mpi.Farm

(* What rank 0 broadcasts once its checks are done. *)
type setup = Go of { filename : string; text : string } | Quit

let user fmt = Printf.ksprintf (fun s -> raise (Cli.User_error s)) fmt

(* As Cli.load, but keeping the text to broadcast. *)
let scene_source (o : Cli.opts) =
  match o.scene with
  | None -> ("showcase.rts", Lancer_cli.Showcase.text)
  | Some path ->
      if not (Sys.file_exists path) then user "%s: no such file" path;
      if Sys.is_directory path then user "%s: is a directory, not a scene file" path;
      let text = try In_channel.with_open_bin path In_channel.input_all with Sys_error m -> user "%s" m in
      (path, text)

let load (filename, text) =
  match Dsl.load_string ~filename text with Ok p -> p | Error errs -> raise (Cli.User_error (Cli.errors_to_string errs))

(* The same defaults and early checks as lancer render (bin/common/commands.ml). *)
let default_output (o : Cli.opts) =
  match (o.output, o.scene) with
  | Some p, _ -> p
  | None, None -> "showcase.png"
  | None, Some s -> Filename.remove_extension (Filename.basename s) ^ ".png"

let check_output path =
  (match Image.format_of_path path with Ok _ -> () | Error m -> raise (Cli.User_error m));
  let dir = Filename.dirname path in
  if not (Sys.file_exists dir && Sys.is_directory dir) then user "cannot write %s: directory %s does not exist" path dir;
  if Sys.file_exists path && Sys.is_directory path then user "cannot write %s: is a directory" path

let progress_bar (o : Cli.opts) ~label ~total =
  Progress.create ~enabled:((not o.quiet) && Unix.isatty Unix.stderr) ~label ~total ()

let ranks_text domains =
  match Mpi.size () with
  | 1 -> Printf.sprintf "1 rank, %d domain%s" domains (if domains = 1 then "" else "s")
  | n -> Printf.sprintf "%d ranks: rank 0 serving, %d × %d domains" n (n - 1) domains

(* How rank 0 reports an exception that ends the job, and the status it ends with. *)
let fatal e = Cli.run (fun () -> raise e)

let describe = function Cli.User_error m -> m | e -> "internal error: " ^ Printexc.to_string e

(* The skeleton of both commands. [prepare] runs on rank 0 only and is (scene source,
   state); [lead] runs on rank 0 with a pool when it is alone; [scene_of prog key] is
   the scene of a frame on the other ranks. *)
let distributed (o : Cli.opts) ~prepare ~lead ~scene_of =
  if Mpi.rank () = 0 then
    Cli.run (fun () ->
        let source, state =
          try prepare ()
          with e ->
            ignore (Mpi.bcast Quit ~root:0);
            raise e
        in
        ignore (Mpi.bcast (Go { filename = fst source; text = snd source }) ~root:0);
        let domains = Cli.domains o in
        try Render.with_pool (if Mpi.size () = 1 then domains else 1) (fun pool -> lead state ~pool ~domains)
        with Farm.Worker_failed (rank, m) -> user "rank %d: %s" rank m)
  else
    match Mpi.bcast Quit ~root:0 with
    | Quit -> 1
    | Go { filename; text } ->
        (* Rank 0 has loaded the same text, so errors here are unexpected (an included
           file missing on this node): they reach rank 0 through Farm and are reported
           there. *)
        let prog = lazy (load (filename, text)) in
        let domains = match o.domains with Some n when n >= 1 -> n | _ -> max 1 (Domain.recommended_domain_count ()) in
        Render.with_pool domains (fun pool ->
            Farm.work ~describe ~pool ~domains ~scene_of:(fun key -> scene_of (Lazy.force prog) key));
        0

(* ---- render ---- *)

let render_cmd (o : Cli.opts) =
  let still prog =
    let time, frame = Cli.time_of o prog in
    Cli.scene_at o prog ~time ~frame
  in
  let prepare () =
    Cli.install_interrupt_handler ();
    let out = default_output o in
    check_output out;
    ignore (Cli.domains o);
    let source = scene_source o in
    let sc = still (load source) in
    (source, (out, sc))
  in
  let lead (out, sc) ~pool ~domains =
    let progress = progress_bar o ~label:"tiles" ~total:(Array.length (Render.tiles sc)) in
    let t0 = Unix.gettimeofday () in
    let result = ref None in
    Farm.serve ~fatal ~pool ~frames:[ (0, fun () -> sc) ] ~on_tiles:(Progress.update progress)
      ~on_frame:(fun _ _ fb st -> result := Some (fb, st));
    let wall = Unix.gettimeofday () -. t0 in
    Progress.finish progress;
    let fb, st = match !result with Some r -> r | None -> failwith "the frame never completed" in
    Cli.write_image out sc fb;
    Cli.warn_bad_samples st;
    Option.iter (fun p -> Cli.write_json p (Cli.stats_json o sc ~wall ~domains ~ranks:(Mpi.size ()) st)) o.stats;
    let rays = Float.of_int (Stats.total_rays st) /. 1e6 in
    if not o.quiet then
      Printf.printf "wrote %s (%d×%d, %.2f s, %s, %.1f M rays, %.2f M rays/s)\n%!" out sc.settings.width sc.settings.height wall
        (ranks_text domains) rays (rays /. Float.max wall 1e-9)
  in
  distributed o ~prepare ~lead ~scene_of:(fun prog _ -> still prog)

(* ---- animate ---- *)

(* The frame names, the manifest and its digests are lancer animate's
   (bin/common/animate.ml), so that either command can --resume the other's frames. *)
let manifest_name = "lancer-frames.json"
let frame_name k = Printf.sprintf "frame_%04d.png" k

let read_manifest dir =
  match Yojson.Safe.from_file (Filename.concat dir manifest_name) with
  | `Assoc kvs -> List.filter_map (function k, `String h -> Some (k, h) | _ -> None) kvs
  | _ -> []
  | exception _ -> []

let write_manifest dir entries =
  Cli.write_json (Filename.concat dir manifest_name) (`Assoc (List.map (fun (k, h) -> (k, `String h)) entries))

let frame_digest (o : Cli.opts) text k =
  let opt f = function Some v -> f v | None -> "-" in
  Digest.to_hex
    (Digest.string
       (String.concat "|"
          [ "lancer-frame-v1"; text; opt string_of_int o.width; opt string_of_int o.height; opt string_of_int o.samples;
            opt string_of_int o.depth; opt Lancer_cli.Quality.to_string o.quality; string_of_int k ]))

let make_video ~fps ~first ~dir ~quiet out =
  if Sys.command "command -v ffmpeg >/dev/null 2>&1" <> 0 then
    user "ffmpeg is not installed, so %s was not made; the frames are in %s (apt-get install ffmpeg)" out dir;
  let tmp = Filename.concat (Filename.dirname out) ("." ^ Filename.basename out ^ ".tmp" ^ Filename.extension out) in
  let cmd =
    Printf.sprintf "ffmpeg -loglevel error -y -framerate %g -start_number %d -i %s %s %s" fps first
      (Filename.quote (Filename.concat dir "frame_%04d.png"))
      (if Filename.check_suffix out ".gif" then "" else "-pix_fmt yuv420p")
      (Filename.quote tmp)
  in
  if Sys.command cmd <> 0 then begin
    (try Sys.remove tmp with Sys_error _ -> ());
    user "ffmpeg failed to make %s" out
  end;
  Unix.rename tmp out;
  if not quiet then Printf.printf "video: %s\n" out

let animation prog =
  match Dsl.animation prog with
  | Some a -> a
  | None -> user "the scene has no animation block: add animation { fps: 24, frames: 48 }, or use lancer render"

let animate_cmd (o : Cli.opts) ~frames ~resume ~video =
  let frame_scene prog k = Cli.scene_at o prog ~time:(Float.of_int k /. fst (animation prog)) ~frame:k in
  let prepare () =
    Cli.install_interrupt_handler ();
    let dir = match o.output with Some d -> d | None -> user "animate needs an output directory: -o DIR" in
    if Sys.file_exists dir && not (Sys.is_directory dir) then user "%s exists and is not a directory" dir;
    ignore (Cli.domains o);
    let ((_, text) as source) = scene_source o in
    let prog = load source in
    let fps, count = animation prog in
    let a, b = match frames with Some r -> r | None -> (0, count - 1) in
    if b >= count then user "--frames %d..%d: the animation has frames 0..%d" a b (count - 1);
    if not (Sys.file_exists dir) then (
      try Unix.mkdir dir 0o755 with Unix.Unix_error (e, _, _) -> user "cannot create %s: %s" dir (Unix.error_message e));
    let manifest = if resume then read_manifest dir else [] in
    let todo =
      List.filter
        (fun k ->
          let name = frame_name k in
          not (resume && Sys.file_exists (Filename.concat dir name) && List.assoc_opt name manifest = Some (frame_digest o text k)))
        (List.init (b - a + 1) (fun i -> a + i))
    in
    let skipped = b - a + 1 - List.length todo in
    if skipped > 0 && not o.quiet then Printf.printf "resuming: %d frames already rendered, %d to go\n%!" skipped (List.length todo);
    (source, (dir, text, prog, fps, a, b, manifest, todo))
  in
  let lead (dir, text, prog, fps, a, b, manifest, todo) ~pool ~domains =
    let progress = progress_bar o ~label:"frames" ~total:(List.length todo) in
    let t0 = Unix.gettimeofday () in
    let manifest = ref manifest and written = ref 0 in
    (* Each frame is written atomically as soon as all its tiles are in, whatever order
       they finish in; the manifest follows each one. *)
    let on_frame k sc fb st =
      Cli.warn_bad_samples st;
      let name = frame_name k in
      Cli.write_image (Filename.concat dir name) sc fb;
      manifest := (name, frame_digest o text k) :: List.remove_assoc name !manifest;
      write_manifest dir (List.sort compare !manifest);
      incr written;
      Progress.update progress !written
    in
    Farm.serve ~fatal ~pool ~frames:(List.map (fun k -> (k, fun () -> frame_scene prog k)) todo) ~on_tiles:ignore ~on_frame;
    Progress.finish progress;
    if not o.quiet then
      Printf.printf "wrote %d frames to %s in %.2f s (%d..%d at %g fps; %s)\n%!" (List.length todo) dir
        (Unix.gettimeofday () -. t0) a b fps (ranks_text domains);
    Option.iter (make_video ~fps ~first:a ~dir ~quiet:o.quiet) video
  in
  distributed o ~prepare ~lead ~scene_of:frame_scene

(* ---- command line ---- *)

let exits =
  Cmd.Exit.info 0 ~doc:"on success."
  :: Cmd.Exit.info 1 ~doc:"on a user error (scene, option or file), reported once by rank 0; every rank exits so."
  :: Cmd.Exit.info 2 ~doc:"on an internal error (a bug in lancer; please report it)."
  :: []

let render =
  let doc = "render a scene to a PNG or PPM image over MPI ranks" in
  let man =
    [ `S Manpage.s_description;
      `P "The same options and the same image bytes as $(b,lancer render). Rank 0 reads the scene and hands out tiles; every other rank renders them with $(b,--domains) domains.";
      `S Manpage.s_examples; `Pre "  mpirun -np 4 lancer-mpi render scenes/showcase.rts -o showcase.png --domains 2";
      `Pre "  mpirun --hostfile hosts -np 9 lancer-mpi render scene.rts --width 3840 --height 2160 --quality final" ]
  in
  Cmd.v (Cmd.info "render" ~doc ~man ~exits) Term.(const render_cmd $ Cli.opts_term)

let animate =
  let doc = "render an animation's frames to DIR/frame_0000.png … over MPI ranks" in
  let frames =
    let parse s = match Lancer_cli.Animate.frames_of_string s with Ok r -> Ok r | Error m -> Error (`Msg m) in
    let print ppf (a, b) = Format.fprintf ppf "%d..%d" a b in
    Arg.(value & opt (some (conv (parse, print))) None & info [ "frames" ] ~docv:"A..B" ~doc:"Render only frames A to B (inclusive).")
  in
  let resume = Arg.(value & flag & info [ "resume" ] ~doc:"Skip frames already rendered for the same scene and options.") in
  let video =
    Arg.(value & opt (some string) None & info [ "video" ] ~docv:"OUT.mp4" ~doc:"Assemble the frames into a video (.mp4 or .gif) with ffmpeg.")
  in
  let man =
    [ `S Manpage.s_description;
      `P "The same options and the same frames as $(b,lancer animate). Rank 0 hands out whole frames (tiles when there are fewer frames than ranks) and writes each frame once it is complete.";
      `S Manpage.s_examples; `Pre "  mpirun -np 4 lancer-mpi animate anim.rts -o frames/ --frames 0..47 --resume" ]
  in
  Cmd.v (Cmd.info "animate" ~doc ~man ~exits)
    Term.(const (fun o frames resume video -> animate_cmd o ~frames ~resume ~video) $ Cli.opts_term $ frames $ resume $ video)

let () =
  if not Mpi.available then begin
    prerr_endline "lancer-mpi: this lancer was built without Open MPI (mpicc was not on PATH); install libopenmpi-dev and rebuild";
    exit 1
  end;
  Mpi.init ();
  at_exit Mpi.finalize;
  let info =
    Cmd.info "lancer-mpi" ~version:"0.1.0" ~exits
      ~doc:"lancer's render and animate over Open MPI: run it under mpirun -np N"
  in
  let cmd = Cmd.group info [ render; animate ] in
  (* Every rank parses the same command line; only rank 0 speaks. *)
  let code =
    if Mpi.rank () = 0 then Cmd.eval' cmd
    else
      let null = Format.make_formatter (fun _ _ _ -> ()) ignore in
      Cmd.eval' ~help:null ~err:null cmd
  in
  exit code
