(* lancer animate: the options, the job layer's plan and render, and what is printed. *)
open Lancer
open Lancer_job

let frames_of_string = Plan.frames_of_string

type options = {
  frames : (int * int) option;
  resume : bool;
  video : string option;
  shard : Plan.shard option;
}

let default_options = { frames = None; resume = false; video = None; shard = None }

let plan ?getenv (o : Cli.opts) (a : options) =
  let program = ref None in
  (* The options first, as every command checks them: then the shard and the scene. *)
  ignore (Cli.domains o);
  let p =
    Animation.plan ?getenv ~dir:o.output ~frames:a.frames ~shard:a.shard ~resume:a.resume
      ~overrides:(Cli.overrides o) (fun () ->
        let prog = Cli.load_source (Cli.source o) in
        program := Some prog;
        Cli.scene_source o prog)
  in
  if p.resumed > 0 && not o.quiet then
    Printf.printf "resuming: %d frames already rendered, %d to go\n%!" p.resumed
      (List.length p.todo);
  (Option.get !program, p)

let write_frame p k sc fb st =
  Cli.warn_bad_samples st;
  Animation.write_frame p k sc fb

let make_video (o : Cli.opts) p out =
  Animation.make_video p out;
  if not o.quiet then Printf.printf "video: %s\n" out

let progress (o : Cli.opts) (p : Animation.plan) =
  Cli.progress o ~label:"frames" ~total:(List.length p.todo)

let interrupted = "the frames written so far are kept; run again with --resume to finish"

let check_video (a : options) =
  Option.iter (Animation.check_video ~shard:(a.shard <> None)) a.video

let run stop (o : Cli.opts) (a : options) =
  let cancel = Report.on_interrupt stop in
  check_video a;
  let _, p = plan o a in
  let domains = Cli.domains o in
  let bar = progress o p in
  let t0 = Unix.gettimeofday () in
  let finished = Atomic.make 0 in
  Animation.render ~cancel ~domains p ~on_frame:(fun _ st ->
      Cli.warn_bad_samples st;
      Progress.update ~rays:(Stats.total_rays st) bar (Atomic.fetch_and_add finished 1 + 1));
  Progress.finish bar;
  Animation.finish p;
  if not o.quiet then
    Printf.printf "wrote %d frames to %s in %.2f s (%s)\n%!" (List.length p.todo) p.dir
      (Unix.gettimeofday () -. t0)
      (Animation.describe_range p);
  Option.iter (make_video o p) a.video

let options_term =
  let open Cmdliner in
  let frames =
    let parse s =
      match frames_of_string s with Ok r -> Ok r | Error m -> Error (`Msg m)
    in
    let print ppf (a, b) = Format.fprintf ppf "%d..%d" a b in
    Arg.(
      value
      & opt (some (conv (parse, print))) None
      & info [ "frames" ] ~docv:"A..B" ~doc:"Render only frames A to B (inclusive).")
  in
  let resume =
    Arg.(
      value & flag
      & info [ "resume" ]
          ~doc:
            "Skip frames already rendered for the same scene, inputs and options \
             (checked against their recorded size and MD5).")
  in
  let video =
    Arg.(
      value
      & opt (some string) None
      & info [ "video" ] ~docv:"OUT.mp4"
          ~doc:"Assemble the frames into a video (.mp4 or .gif) with ffmpeg.")
  in
  let shard =
    let parse s =
      match Plan.shard_of_string s with Ok r -> Ok r | Error m -> Error (`Msg m)
    in
    let print ppf = function
      | Plan.Shard (k, n) -> Format.fprintf ppf "%d/%d" k n
      | Plan.Slurm -> Format.fprintf ppf "slurm"
    in
    Arg.(
      value
      & opt (some (conv (parse, print))) None
      & info [ "shard" ] ~docv:"K/N"
          ~doc:
            "Render only shard K of N (0 <= K < N): the frames whose index in the range \
             is K modulo N. Any number of shards may run at once into one directory. \
             $(b,slurm) takes K and N from the Slurm job array (SLURM_ARRAY_TASK_ID, \
             SLURM_ARRAY_TASK_COUNT, SLURM_ARRAY_TASK_MIN).")
  in
  Term.(
    const (fun frames resume video shard -> { frames; resume; video; shard })
    $ frames $ resume $ video $ shard)
