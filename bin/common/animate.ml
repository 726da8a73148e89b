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
  let p = Filename.concat dir manifest_name in
  match Yojson.Safe.from_file p with
  | `Assoc kvs -> List.filter_map (function k, `String h -> Some (k, h) | _ -> None) kvs
  | _ -> []
  | exception _ -> []

let write_manifest dir entries =
  Cli.write_json (Filename.concat dir manifest_name) (`Assoc (List.map (fun (k, h) -> (k, `String h)) entries))

let scene_text (o : Cli.opts) =
  match o.scene with
  | None -> Showcase.text
  | Some p -> ( try In_channel.with_open_bin p In_channel.input_all with Sys_error m -> raise (Cli.User_error m))

(* What changes the pixels of frame k: the scene text and the overriding options. *)
let frame_digest (o : Cli.opts) text k =
  let opt f = function Some v -> f v | None -> "-" in
  Digest.to_hex
    (Digest.string
       (String.concat "|"
          [ "lancer-frame-v1"; text; opt string_of_int o.width; opt string_of_int o.height; opt string_of_int o.samples;
            opt string_of_int o.depth; opt Quality.to_string o.quality; string_of_int k ]))

let run (o : Cli.opts) ~frames ~resume ~video =
  Cli.install_interrupt_handler ();
  let dir = match o.output with Some d -> d | None -> raise (Cli.User_error "animate needs an output directory: -o DIR") in
  if Sys.file_exists dir && not (Sys.is_directory dir) then raise (Cli.User_error (Printf.sprintf "%s exists and is not a directory" dir));
  let prog = Cli.load o.scene in
  let fps, count =
    match Lancer_dsl.Dsl.animation prog with
    | Some a -> a
    | None -> raise (Cli.User_error "the scene has no animation block: add animation { fps: 24, frames: 48 }, or use lancer render")
  in
  let a, b = match frames with Some (a, b) -> (a, b) | None -> (0, count - 1) in
  if b >= count then
    raise (Cli.User_error (Printf.sprintf "--frames %d..%d: the animation has frames 0..%d" a b (count - 1)));
  if not (Sys.file_exists dir) then (try Unix.mkdir dir 0o755 with Unix.Unix_error (e, _, _) ->
    raise (Cli.User_error (Printf.sprintf "cannot create %s: %s" dir (Unix.error_message e))));
  let text = scene_text o in
  let manifest = ref (if resume then read_manifest dir else []) in
  let todo =
    List.filter
      (fun k ->
        let name = frame_name k in
        not (resume && Sys.file_exists (Filename.concat dir name) && List.assoc_opt name !manifest = Some (frame_digest o text k)))
      (List.init (b - a + 1) (fun i -> a + i))
  in
  let skipped = b - a + 1 - List.length todo in
  if skipped > 0 && not o.quiet then Printf.printf "resuming: %d frames already rendered, %d to go\n%!" skipped (List.length todo);
  let domains = Cli.domains o in
  let progress = Progress.create ~enabled:((not o.quiet) && Unix.isatty Unix.stderr) ~label:"frames" ~total:(List.length todo) () in
  let t0 = Unix.gettimeofday () in
  Render.with_pool domains (fun pool ->
      List.iteri
        (fun i k ->
          let time = Float.of_int k /. fps in
          let sc = Cli.scene_at o prog ~time ~frame:k in
          let fb, st = Render.render ?pool sc in
          Cli.warn_bad_samples st;
          let name = frame_name k in
          Cli.write_image (Filename.concat dir name) sc fb;
          manifest := (name, frame_digest o text k) :: List.remove_assoc name !manifest;
          write_manifest dir (List.sort compare !manifest);
          Progress.update progress (i + 1))
        todo);
  Progress.finish progress;
  if not o.quiet then
    Printf.printf "wrote %d frames to %s in %.2f s (%d..%d at %g fps)\n%!" (List.length todo) dir (Unix.gettimeofday () -. t0) a b fps;
  Option.iter
    (fun out ->
      let has_ffmpeg = Sys.command "command -v ffmpeg >/dev/null 2>&1" = 0 in
      if not has_ffmpeg then
        raise (Cli.User_error (Printf.sprintf "ffmpeg is not installed, so %s was not made; the frames are in %s (apt-get install ffmpeg)" out dir));
      let tmp = Filename.concat (Filename.dirname out) ("." ^ Filename.basename out ^ ".tmp" ^ Filename.extension out) in
      let cmd =
        Printf.sprintf "ffmpeg -loglevel error -y -framerate %g -start_number %d -i %s %s %s" fps a
          (Filename.quote (Filename.concat dir "frame_%04d.png"))
          (if Filename.check_suffix out ".gif" then "" else "-pix_fmt yuv420p")
          (Filename.quote tmp)
      in
      if Sys.command cmd <> 0 then begin
        (try Sys.remove tmp with _ -> ());
        raise (Cli.User_error (Printf.sprintf "ffmpeg failed to make %s" out))
      end;
      Unix.rename tmp out;
      if not o.quiet then Printf.printf "video: %s\n" out)
    video
