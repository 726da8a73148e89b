open Lancer

let frames_of_string s =
  let bad () = Error (Printf.sprintf "--frames expects A..B or K (got %S)" s) in
  match String.index_opt s '.' with
  | None -> (
      match int_of_string_opt s with Some k when k >= 0 -> Ok (k, k) | _ -> bad ())
  | Some i -> (
      if i + 1 >= String.length s || s.[i + 1] <> '.' then bad ()
      else
        let a = String.sub s 0 i and b = String.sub s (i + 2) (String.length s - i - 2) in
        match (int_of_string_opt a, int_of_string_opt b) with
        | Some a, Some b when a >= 0 && b >= a -> Ok (a, b)
        | _ -> bad ())

let frame_name = Frameset.frame_name

type shard = Shard of int * int | Slurm

let shard_of_string s =
  if s = "slurm" then Ok Slurm
  else
    match String.split_on_char '/' s with
    | [ k; n ] -> (
        match (int_of_string_opt k, int_of_string_opt n) with
        | Some k, Some n when n >= 1 && k >= 0 && k < n -> Ok (Shard (k, n))
        | Some k, Some n when n >= 1 ->
            Error (Printf.sprintf "--shard %s: K must be between 0 and %d" s (n - 1))
        | _ ->
            Error (Printf.sprintf "--shard expects K/N (0 <= K < N) or slurm (got %S)" s))
    | _ -> Error (Printf.sprintf "--shard expects K/N (0 <= K < N) or slurm (got %S)" s)

(* A Slurm job array: task IDs MIN, MIN + STEP, … COUNT of them (sbatch --array=0-15). *)
let slurm_shard getenv =
  let var name = getenv name in
  let int name =
    match var name with
    | None -> None
    | Some v -> (
        match int_of_string_opt (String.trim v) with
        | Some n -> Some n
        | None -> Cli.user "--shard slurm: %s=%S is not a number" name v)
  in
  match (int "SLURM_ARRAY_TASK_ID", int "SLURM_ARRAY_TASK_COUNT") with
  | None, _ | _, None ->
      Cli.user
        "--shard slurm: SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT are not set; run \
         it as a task of a Slurm job array (sbatch --array=0-15), or give --shard K/N"
  | Some id, Some count ->
      let min = Option.value (int "SLURM_ARRAY_TASK_MIN") ~default:0 in
      let step = Option.value (int "SLURM_ARRAY_TASK_STEP") ~default:1 in
      if
        count < 1 || step < 1 || id < min
        || (id - min) mod step <> 0
        || (id - min) / step >= count
      then
        Cli.user
          "--shard slurm: task %d is not one of the %d tasks from %d in steps of %d" id
          count min step;
      ((id - min) / step, count)

type options = {
  frames : (int * int) option;
  resume : bool;
  video : string option;
  shard : shard option;
}

let default_options = { frames = None; resume = false; video = None; shard = None }

(* What changes every frame's pixels: the scene's text and includes (not the path it was
   typed as) and the overriding options. The frame number and the images and meshes a
   frame reads are recorded beside it. *)
let job_digest (o : Cli.opts) prog =
  let opt f = function Some v -> f v | None -> "-" in
  Digest.to_hex
    (Digest.string
       (String.concat "|"
          [
            "lancer-frames-v3";
            Lancer_dsl.Dsl.text_digest prog;
            opt string_of_int o.width;
            opt string_of_int o.height;
            opt string_of_int o.samples;
            opt string_of_int o.depth;
            opt Quality.to_string o.quality;
          ]))

type plan = {
  opts : Cli.opts;
  source : string * string;
  prog : Lancer_dsl.Dsl.t;
  dir : string;
  fps : float;
  first : int;
  last : int;
  shard : (int * int) option;
  todo : int list;
  set : Frameset.t;
  inputs : (int, (string * string) list) Hashtbl.t;
  inputs_lock : Mutex.t;
}

let plan ?(getenv = Sys.getenv_opt) (o : Cli.opts) (a : options) =
  let dir =
    match o.output with
    | Some d -> d
    | None -> Cli.user "animate needs an output directory: -o DIR"
  in
  if Sys.file_exists dir && not (Sys.is_directory dir) then
    Cli.user "%s exists and is not a directory" dir;
  ignore (Cli.domains o);
  let shard =
    match a.shard with
    | None -> None
    | Some (Shard (k, n)) -> Some (k, n)
    | Some Slurm -> Some (slurm_shard getenv)
  in
  let source = Cli.source o in
  let prog = Cli.load_source source in
  let fps, count =
    match Lancer_dsl.Dsl.animation prog with
    | Some a -> a
    | None ->
        Cli.user
          "the scene has no animation block: add animation { fps: 24, frames: 48 }, or \
           use lancer render"
  in
  let first, last = match a.frames with Some r -> r | None -> (0, count - 1) in
  if last >= count then
    Cli.user "--frames %d..%d: the animation has frames 0..%d" first last (count - 1);
  (if not (Sys.file_exists dir) then
     try Unix.mkdir dir 0o755 with
     | Unix.Unix_error (Unix.EEXIST, _, _) when Sys.is_directory dir ->
         () (* another shard made it *)
     | Unix.Unix_error (e, _, _) ->
         Cli.user "cannot create %s: %s" dir (Unix.error_message e));
  let mine =
    List.filter
      (fun k -> match shard with None -> true | Some (i, n) -> (k - first) mod n = i)
      (List.init (last - first + 1) (fun i -> first + i))
  in
  (* Before anything is written into the directory. *)
  Cli.guard_writes ~distinct:false ~reads:(Cli.reads o prog)
    ((Filename.concat dir Frameset.view_name, "the frames record")
    :: List.map (fun k -> (Filename.concat dir (Frameset.frame_name k), "a frame")) mine);
  let set =
    (* A directory belongs to one scene file, named by its real path (the same from any
       working directory, and on every node that mounts it at the same place). *)
    let scene =
      match fst source with
      | "-" -> "<stdin>"
      | f -> ( try Unix.realpath f with Unix.Unix_error _ -> f)
    in
    Frameset.open_ ~dir ~scene ~job:(job_digest o prog) ~count
  in
  let input_digest = Lancer_dsl.Dsl.input_digest prog in
  let todo =
    if a.resume then
      List.filter (fun k -> not (Frameset.is_done set k ~input_digest)) mine
    else mine
  in
  let skipped = List.length mine - List.length todo in
  if skipped > 0 && not o.quiet then
    Printf.printf "resuming: %d frames already rendered, %d to go\n%!" skipped
      (List.length todo);
  if todo <> [] then Frameset.drop_view set;
  {
    opts = o;
    source;
    prog;
    dir;
    fps;
    first;
    last;
    shard;
    todo;
    set;
    inputs = Hashtbl.create 16;
    inputs_lock = Mutex.create ();
  }

let frame_scene ?cancel p k =
  let sc, files =
    Cli.scene_with_files ?cancel p.opts p.prog ~time:(Float.of_int k /. p.fps) ~frame:k
  in
  Mutex.protect p.inputs_lock (fun () -> Hashtbl.replace p.inputs k files);
  sc

let write_frame p k sc fb st =
  Cli.warn_bad_samples st;
  Cli.write_image (Filename.concat p.dir (frame_name k)) sc fb;
  let inputs =
    match Mutex.protect p.inputs_lock (fun () -> Hashtbl.find_opt p.inputs k) with
    | Some i -> i
    | None ->
        snd (Cli.scene_with_files p.opts p.prog ~time:(Float.of_int k /. p.fps) ~frame:k)
  in
  Mutex.protect p.inputs_lock (fun () -> Hashtbl.remove p.inputs k);
  Frameset.record p.set k ~inputs

let finish p =
  ignore (Frameset.finish p.set ~input_digest:(Lancer_dsl.Dsl.input_digest p.prog))

let describe_range p =
  Printf.sprintf "%d..%d at %g fps%s" p.first p.last p.fps
    (match p.shard with Some (k, n) -> Printf.sprintf ", shard %d/%d" k n | None -> "")

let make_video p out =
  if Sys.command "command -v ffmpeg >/dev/null 2>&1" <> 0 then
    Cli.user
      "ffmpeg is not installed, so %s was not made; the frames are in %s (apt-get \
       install ffmpeg)"
      out p.dir;
  let tmp =
    Filename.concat (Filename.dirname out)
      ("." ^ Filename.basename out ^ ".tmp" ^ Filename.extension out)
  in
  let cmd =
    Printf.sprintf "ffmpeg -loglevel error -y -framerate %g -start_number %d -i %s %s %s"
      p.fps p.first
      (Filename.quote (Filename.concat p.dir "frame_%04d.png"))
      (if Filename.check_suffix out ".gif" then
         (* One palette made from the frames themselves: sharper and smaller than the default. *)
         "-vf " ^ Filename.quote "split[a][b];[a]palettegen[p];[b][p]paletteuse"
       else
         (* H.264 in yuv420p needs even sizes: pad an odd width or height by one pixel. *)
         "-pix_fmt yuv420p -vf " ^ Filename.quote "pad=ceil(iw/2)*2:ceil(ih/2)*2")
      (Filename.quote tmp)
  in
  if Sys.command cmd <> 0 then (
    (try Sys.remove tmp with Sys_error _ -> ());
    Cli.user "ffmpeg failed to make %s" out);
  (try Unix.rename tmp out
   with Unix.Unix_error (e, _, _) ->
     (try Sys.remove tmp with Sys_error _ -> ());
     Cli.user "cannot write %s: %s" out (Unix.error_message e));
  if not p.opts.quiet then Printf.printf "video: %s\n" out

let progress p = Cli.progress p.opts ~label:"frames" ~total:(List.length p.todo)
let interrupted = "the frames written so far are kept; run again with --resume to finish"

(* The video's name and place are checked before the frames are rendered, not after. *)
let check_video (a : options) =
  if a.video <> None && a.shard <> None then
    Cli.user
      "--video with --shard: a shard has only some of the frames; once every shard is \
       done, run lancer animate again with --resume --video";
  Option.iter
    (fun v ->
      if not (Filename.check_suffix v ".mp4" || Filename.check_suffix v ".gif") then
        Cli.user "--video %s: the video must be a .mp4 or a .gif" v;
      Cli.check_writable v)
    a.video

let run (o : Cli.opts) (a : options) =
  let cancel = Cli.install_interrupt_handler () in
  check_video a;
  let p = plan o a in
  let domains = Cli.domains o in
  let bar = progress p in
  let t0 = Unix.gettimeofday () in
  Render.with_pool ~cancel domains (fun pool ->
      (* The first frame's scene tells how large the scenes are; it is evaluated once and
         handed to the render that needs it. *)
      let first =
        ref (match p.todo with k :: _ -> Some (k, frame_scene ~cancel p k) | [] -> None)
      in
      let scene k =
        match !first with
        | Some (k', sc) when k' = k ->
            first := None;
            sc
        | _ -> frame_scene ~cancel p k
      in
      (* Whole frames in parallel hold a batch of scenes and one framebuffer per domain at
         once: only when that stays small (about 1 KB an object, 27 bytes a pixel). *)
      let small =
        match !first with
        | None -> false
        | Some (_, sc) ->
            let bytes =
              (1024. *. Float.of_int (Array.length sc.objects))
              +. (27. *. Float.of_int sc.settings.width *. Float.of_int sc.settings.height)
            in
            Float.of_int (2 * domains) *. bytes < 2e9
      in
      match pool with
      | Some pool when List.length p.todo >= 2 * domains && small ->
          (* Whole frames in parallel, one domain each: small frames keep every core busy,
             and their encoding and writing run in parallel too. Scenes are evaluated in
             order on this domain, a batch at a time; a frame's bytes are the same either
             way. *)
          let todo = Array.of_list p.todo in
          let n = Array.length todo and batch = 2 * domains in
          let finished = Atomic.make 0 in
          let rec go start =
            if start < n then (
              let ks = Array.sub todo start (min batch (n - start)) in
              let scenes = Array.map scene ks in
              Pool.parallel_for pool (Array.length ks) (fun i ->
                  let fb, st = Render.render ~cancel scenes.(i) in
                  write_frame p ks.(i) scenes.(i) fb st;
                  Progress.update ~rays:(Stats.total_rays st) bar
                    (Atomic.fetch_and_add finished 1 + 1));
              go (start + batch))
          in
          go 0
      | _ ->
          (* Few frames: one after the other, each over every domain in tiles. *)
          List.iteri
            (fun i k ->
              let sc = scene k in
              let fb, st = Render.render ~cancel ?pool sc in
              write_frame p k sc fb st;
              Progress.update ~rays:(Stats.total_rays st) bar (i + 1))
            p.todo);
  Progress.finish bar;
  finish p;
  if not o.quiet then
    Printf.printf "wrote %d frames to %s in %.2f s (%s)\n%!" (List.length p.todo) p.dir
      (Unix.gettimeofday () -. t0)
      (describe_range p);
  Option.iter (make_video p) a.video

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
      match shard_of_string s with Ok r -> Ok r | Error m -> Error (`Msg m)
    in
    let print ppf = function
      | Shard (k, n) -> Format.fprintf ppf "%d/%d" k n
      | Slurm -> Format.fprintf ppf "slurm"
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
