let user = Job_error.user

(* What changes every frame's pixels: the scene's text and includes (not the path it was
   typed as) and the overriding options. The frame number and the images and meshes a
   frame reads are recorded beside it. *)
let job_digest (src : Source.t) overrides =
  Digest.to_hex
    (Digest.string
       (String.concat "|"
          ("lancer-frames-v3" :: src.text_digest () :: Overrides.digest_fields overrides)))

type plan = {
  source : Source.t;
  overrides : Overrides.t;
  dir : string;
  fps : float;
  first : int;
  last : int;
  shard : (int * int) option;
  todo : int list;
  resumed : int;
  set : Frameset.t;
  inputs : (int, (string * string) list) Hashtbl.t;
  inputs_lock : Mutex.t;
}

let plan ?(getenv = Sys.getenv_opt) ~dir ~frames ~shard ~resume ~overrides load =
  let dir =
    match dir with
    | Some d -> d
    | None -> user "animate needs an output directory: -o DIR"
  in
  if Sys.file_exists dir && not (Sys.is_directory dir) then
    user "%s exists and is not a directory" dir;
  let shard = Option.map (Plan.resolve_shard ~getenv) shard in
  let source : Source.t = load () in
  let fps, count =
    match source.animation with
    | Some a -> a
    | None ->
        user
          "the scene has no animation block: add animation { fps: 24, frames: 48 }, or \
           use lancer render"
  in
  let first, last = match frames with Some r -> r | None -> (0, count - 1) in
  if last >= count then
    user "--frames %d..%d: the animation has frames 0..%d" first last (count - 1);
  (if not (Sys.file_exists dir) then
     try Unix.mkdir dir 0o755 with
     | Unix.Unix_error (Unix.EEXIST, _, _) when Sys.is_directory dir ->
         () (* another shard made it *)
     | Unix.Unix_error (e, _, _) -> user "cannot create %s: %s" dir (Unix.error_message e));
  let mine = Plan.shard_frames ~first ~last shard in
  (* Before anything is written into the directory. *)
  Files.guard_writes ~distinct:false ~reads:(Source.reads source)
    ((Filename.concat dir Frameset.view_name, "the frames record")
    :: List.map (fun k -> (Filename.concat dir (Frameset.frame_name k), "a frame")) mine);
  let set =
    (* A directory belongs to one scene file, named by its real path (the same from any
       working directory, and on every node that mounts it at the same place). *)
    let scene =
      match source.file with
      | "<stdin>" -> "<stdin>"
      | f -> ( try Unix.realpath f with Unix.Unix_error _ -> f)
    in
    Frameset.open_ ~dir ~scene ~job:(job_digest source overrides) ~count
  in
  let todo =
    if resume then
      List.filter
        (fun k -> not (Frameset.is_done set k ~input_digest:source.input_digest))
        mine
    else mine
  in
  if todo <> [] then Frameset.drop_view set;
  {
    source;
    overrides;
    dir;
    fps;
    first;
    last;
    shard;
    todo;
    resumed = List.length mine - List.length todo;
    set;
    inputs = Hashtbl.create 16;
    inputs_lock = Mutex.create ();
  }

let evaluate ?cancel p k =
  Source.scene ?cancel p.source p.overrides ~time:(Float.of_int k /. p.fps) ~frame:k

let frame_scene ?cancel p k =
  let sc, files = evaluate ?cancel p k in
  Mutex.protect p.inputs_lock (fun () -> Hashtbl.replace p.inputs k files);
  sc

let write_frame p k sc fb =
  Files.write_image (Filename.concat p.dir (Frameset.frame_name k)) sc fb;
  let inputs =
    match Mutex.protect p.inputs_lock (fun () -> Hashtbl.find_opt p.inputs k) with
    | Some i -> i
    | None -> snd (evaluate p k)
  in
  Mutex.protect p.inputs_lock (fun () -> Hashtbl.remove p.inputs k);
  Frameset.record p.set k ~inputs

let render ?cancel ~domains ~on_frame p =
  Render.with_pool ?cancel domains (fun pool ->
      (* The first frame's scene tells how large the scenes are; it is evaluated once and
         handed to the render that needs it. *)
      let first =
        ref (match p.todo with k :: _ -> Some (k, frame_scene ?cancel p k) | [] -> None)
      in
      let scene k =
        match !first with
        | Some (k', sc) when k' = k ->
            first := None;
            sc
        | _ -> frame_scene ?cancel p k
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
          let rec go start =
            if start < n then (
              let ks = Array.sub todo start (min batch (n - start)) in
              let scenes = Array.map scene ks in
              Pool.parallel_for pool (Array.length ks) (fun i ->
                  let fb, st = Render.render ?cancel scenes.(i) in
                  write_frame p ks.(i) scenes.(i) fb;
                  on_frame ks.(i) st);
              go (start + batch))
          in
          go 0
      | _ ->
          (* Few frames: one after the other, each over every domain in tiles. *)
          List.iter
            (fun k ->
              let sc = scene k in
              let fb, st = Render.render ?cancel ?pool sc in
              write_frame p k sc fb;
              on_frame k st)
            p.todo)

let finish p = ignore (Frameset.finish p.set ~input_digest:p.source.input_digest)

let describe_range p =
  Printf.sprintf "%d..%d at %g fps%s" p.first p.last p.fps
    (match p.shard with Some (k, n) -> Printf.sprintf ", shard %d/%d" k n | None -> "")

(* The video's name and place are checked before the frames are rendered, not after. *)
let check_video ~shard v =
  if shard then
    user
      "--video with --shard: a shard has only some of the frames; once every shard is \
       done, run lancer animate again with --resume --video";
  if not (Filename.check_suffix v ".mp4" || Filename.check_suffix v ".gif") then
    user "--video %s: the video must be a .mp4 or a .gif" v;
  Files.check_writable v

let make_video p out =
  if Sys.command "command -v ffmpeg >/dev/null 2>&1" <> 0 then
    user
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
    user "ffmpeg failed to make %s" out);
  try Unix.rename tmp out
  with Unix.Unix_error (e, _, _) ->
    (try Sys.remove tmp with Sys_error _ -> ());
    user "cannot write %s: %s" out (Unix.error_message e)
