open Lancer

let frames_of_string s =
  let bad () = Error (Printf.sprintf "--frames expects A..B or K (got %S)" s) in
  match String.index_opt s '.' with
  | None -> ( match int_of_string_opt s with Some k when k >= 0 -> Ok (k, k) | _ -> bad ())
  | Some i ->
      if i + 1 >= String.length s || s.[i + 1] <> '.' then bad ()
      else
        let a = String.sub s 0 i and b = String.sub s (i + 2) (String.length s - i - 2) in
        match (int_of_string_opt a, int_of_string_opt b) with
        | Some a, Some b when a >= 0 && b >= a -> Ok (a, b)
        | _ -> bad ()

let manifest_name = "lancer-frames.json"
let frame_name k = Printf.sprintf "frame_%04d.png" k

let read_manifest dir =
  match Yojson.Safe.from_file (Filename.concat dir manifest_name) with
  | `Assoc kvs -> List.filter_map (function k, `String h -> Some (k, h) | _ -> None) kvs
  | _ -> []
  | exception _ -> []

let write_manifest dir entries =
  Cli.write_json (Filename.concat dir manifest_name) (`Assoc (List.map (fun (k, h) -> (k, `String h)) entries))

(* What changes the pixels of frame k: the scene text and the overriding options. *)
let frame_digest (o : Cli.opts) inputs k =
  let opt f = function Some v -> f v | None -> "-" in
  Digest.to_hex
    (Digest.string
       (String.concat "|"
          [ "lancer-frame-v2"; inputs; opt string_of_int o.width; opt string_of_int o.height; opt string_of_int o.samples;
            opt string_of_int o.depth; opt Quality.to_string o.quality; string_of_int k ]))

type plan = {
  opts : Cli.opts;
  source : string * string;
  prog : Lancer_dsl.Dsl.t;
  inputs : string;
  dir : string;
  fps : float;
  first : int;
  last : int;
  todo : int list;
  mutable manifest : (string * string) list;
}

let plan (o : Cli.opts) ~frames ~resume =
  let dir = match o.output with Some d -> d | None -> Cli.user "animate needs an output directory: -o DIR" in
  if Sys.file_exists dir && not (Sys.is_directory dir) then Cli.user "%s exists and is not a directory" dir;
  ignore (Cli.domains o);
  let source = Cli.source o in
  let prog = Cli.load_source source in
  let inputs = Lancer_dsl.Dsl.inputs_digest prog in
  let fps, count =
    match Lancer_dsl.Dsl.animation prog with
    | Some a -> a
    | None -> Cli.user "the scene has no animation block: add animation { fps: 24, frames: 48 }, or use lancer render"
  in
  let first, last = match frames with Some r -> r | None -> (0, count - 1) in
  if last >= count then Cli.user "--frames %d..%d: the animation has frames 0..%d" first last (count - 1);
  if not (Sys.file_exists dir) then (
    try Unix.mkdir dir 0o755 with Unix.Unix_error (e, _, _) -> Cli.user "cannot create %s: %s" dir (Unix.error_message e));
  let manifest = if resume then read_manifest dir else [] in
  let todo =
    List.filter
      (fun k ->
        let name = frame_name k in
        not (resume && Sys.file_exists (Filename.concat dir name) && List.assoc_opt name manifest = Some (frame_digest o inputs k)))
      (List.init (last - first + 1) (fun i -> first + i))
  in
  let skipped = last - first + 1 - List.length todo in
  if skipped > 0 && not o.quiet then Printf.printf "resuming: %d frames already rendered, %d to go\n%!" skipped (List.length todo);
  { opts = o; source; prog; inputs; dir; fps; first; last; todo; manifest }

let frame_scene p k = Cli.scene_at p.opts p.prog ~time:(Float.of_int k /. p.fps) ~frame:k

(* Frames may be written from several domains at once: the manifest is theirs in turn. *)
let manifest_lock = Mutex.create ()

let write_frame p k sc fb st =
  Cli.warn_bad_samples st;
  let name = frame_name k in
  Cli.write_image (Filename.concat p.dir name) sc fb;
  Mutex.protect manifest_lock (fun () ->
      p.manifest <- (name, frame_digest p.opts p.inputs k) :: List.remove_assoc name p.manifest;
      write_manifest p.dir (List.sort compare p.manifest))

let make_video p out =
  if Sys.command "command -v ffmpeg >/dev/null 2>&1" <> 0 then
    Cli.user "ffmpeg is not installed, so %s was not made; the frames are in %s (apt-get install ffmpeg)" out p.dir;
  let tmp = Filename.concat (Filename.dirname out) ("." ^ Filename.basename out ^ ".tmp" ^ Filename.extension out) in
  let cmd =
    Printf.sprintf "ffmpeg -loglevel error -y -framerate %g -start_number %d -i %s %s %s" p.fps p.first
      (Filename.quote (Filename.concat p.dir "frame_%04d.png"))
      (if Filename.check_suffix out ".gif" then
         (* One palette made from the frames themselves: sharper and smaller than the default. *)
         "-vf " ^ Filename.quote "split[a][b];[a]palettegen[p];[b][p]paletteuse"
       else
         (* H.264 in yuv420p needs even sizes: pad an odd width or height by one pixel. *)
         "-pix_fmt yuv420p -vf " ^ Filename.quote "pad=ceil(iw/2)*2:ceil(ih/2)*2")
      (Filename.quote tmp)
  in
  if Sys.command cmd <> 0 then begin
    (try Sys.remove tmp with Sys_error _ -> ());
    Cli.user "ffmpeg failed to make %s" out
  end;
  (try Unix.rename tmp out
   with Unix.Unix_error (e, _, _) ->
     (try Sys.remove tmp with Sys_error _ -> ());
     Cli.user "cannot write %s: %s" out (Unix.error_message e));
  if not p.opts.quiet then Printf.printf "video: %s\n" out

let progress p = Cli.progress p.opts ~label:"frames" ~total:(List.length p.todo)

let interrupted = "the frames written so far are kept; run again with --resume to finish"

(* The video's name and place are checked before the frames are rendered, not after. *)
let check_video =
  Option.iter (fun v ->
      if not (Filename.check_suffix v ".mp4" || Filename.check_suffix v ".gif") then
        Cli.user "--video %s: the video must be a .mp4 or a .gif" v;
      Cli.check_writable v)

let run (o : Cli.opts) ~frames ~resume ~video =
  Cli.install_interrupt_handler ();
  check_video video;
  let p = plan o ~frames ~resume in
  let domains = Cli.domains o in
  let bar = progress p in
  let t0 = Unix.gettimeofday () in
  Render.with_pool domains (fun pool ->
      (* The first frame's scene tells how large the scenes are; it is evaluated once and
         handed to the render that needs it. *)
      let first = ref (match p.todo with k :: _ -> Some (k, frame_scene p k) | [] -> None) in
      let scene k =
        match !first with
        | Some (k', sc) when k' = k ->
            first := None;
            sc
        | _ -> frame_scene p k
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
            if start < n then begin
              let ks = Array.sub todo start (min batch (n - start)) in
              let scenes = Array.map scene ks in
              Pool.parallel_for pool (Array.length ks) (fun i ->
                  let fb, st = Render.render scenes.(i) in
                  write_frame p ks.(i) scenes.(i) fb st;
                  Progress.update ~rays:(Stats.total_rays st) bar (Atomic.fetch_and_add finished 1 + 1));
              go (start + batch)
            end
          in
          go 0
      | _ ->
          (* Few frames: one after the other, each over every domain in tiles. *)
          List.iteri
            (fun i k ->
              let sc = scene k in
              let fb, st = Render.render ?pool sc in
              write_frame p k sc fb st;
              Progress.update ~rays:(Stats.total_rays st) bar (i + 1))
            p.todo);
  Progress.finish bar;
  if not o.quiet then
    Printf.printf "wrote %d frames to %s in %.2f s (%d..%d at %g fps)\n%!" (List.length p.todo) p.dir
      (Unix.gettimeofday () -. t0) p.first p.last p.fps;
  Option.iter (make_video p) video

let options_term =
  let open Cmdliner in
  let frames =
    let parse s = match frames_of_string s with Ok r -> Ok r | Error m -> Error (`Msg m) in
    let print ppf (a, b) = Format.fprintf ppf "%d..%d" a b in
    Arg.(value & opt (some (conv (parse, print))) None & info [ "frames" ] ~docv:"A..B" ~doc:"Render only frames A to B (inclusive).")
  in
  let resume = Arg.(value & flag & info [ "resume" ] ~doc:"Skip frames already rendered for the same scene and options.") in
  let video =
    Arg.(value & opt (some string) None & info [ "video" ] ~docv:"OUT.mp4" ~doc:"Assemble the frames into a video (.mp4 or .gif) with ffmpeg.")
  in
  Term.(const (fun f r v -> (f, r, v)) $ frames $ resume $ video)
