let user = Job_error.user

(* What changes every frame's pixels, named: the scene's text and includes (not the path
   it was typed as) and the overriding options. The frame number and the images and
   meshes a frame reads are recorded beside it. *)
let job_parts (src : Scenes.t) overrides ~format ~bits ~job =
  (("scene", src.text_digest ()) :: Overrides.named_fields overrides)
  @ job
  @
  (* Frames as PNG at the default depth keep the digest they always had. *)
  match (format, bits) with
  | Image.Png, None -> []
  | f, b ->
      [
        ("--format", Image.format_name f);
        ("--bits", match b with Some b -> string_of_int b | None -> "-");
      ]

let job_digest parts =
  Digest.to_hex
    (Digest.string (String.concat "|" ("lancer-frames-v3" :: List.map snd parts)))

type plan = {
  source : Scenes.t;
  overrides : Overrides.t;
  dir : string;
  format : Image.format;
  bits : int option;
  fps : float;
  first : int;
  last : int;
  shard : (int * int) option;
  todo : int list;
  resumed : int;
  stale : (string * int list) list;
  set : Frameset.t;
  inputs : (int, (string * string) list) Hashtbl.t;
  inputs_lock : Mutex.t;
  chosen :
    (Provenance.budget * (Scene.t -> time:float -> frame:int -> Scene.t * string list))
    option;
}

let plan ?(getenv = Sys.getenv_opt) ?(format = Image.Png) ?bits ?(job = []) ~dir ~frames
    ~shard ~resume ~overrides load =
  Option.iter (user "--bits %s") (Image.bits_problem format bits);
  let ext = Image.format_name format in
  let dir =
    match dir with
    | Some d -> d
    | None -> user "animate needs an output directory: -o DIR"
  in
  if Sys.file_exists dir && not (Sys.is_directory dir) then
    user "%s exists and is not a directory" dir;
  let shard = Option.map (Plan.resolve_shard ~getenv) shard in
  let source : Scenes.t = load () in
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
  (* Before anything is written into the directory: no frame replaces a file that this
     run has read, nor one that the scene names, which a later frame may read. *)
  Files.guard_writes ~distinct:false ~names:(source.names ()) ~reads:(Scenes.reads source)
    ((Filename.concat dir Frameset.view_name, "the frames record")
    :: List.map
         (fun k -> (Filename.concat dir (Frameset.frame_name ~ext k), "a frame"))
         mine);
  let set =
    (* A directory belongs to one scene file, named by its real path (the same from any
       working directory, and on every node that mounts it at the same place). *)
    let scene =
      match source.file with
      | "<stdin>" -> "<stdin>"
      | f -> ( try Unix.realpath f with Unix.Unix_error _ -> f)
    in
    let made_with = job_parts source overrides ~format ~bits ~job in
    Frameset.open_ ~ext ~made_with ~dir ~scene ~job:(job_digest made_with) ~count ()
  in
  let todo, stale =
    if resume then
      let why k = Frameset.why_not_done set k ~input_digest:source.input_digest in
      let todo =
        List.filter
          (fun k -> not (Frameset.is_done set k ~input_digest:source.input_digest))
          mine
      in
      (* The frames a run recorded that are rendered again, by reason, in order. *)
      let whys = List.filter_map (fun k -> Option.map (fun r -> (r, k)) (why k)) todo in
      let reasons =
        List.fold_left
          (fun acc (r, _) -> if List.mem r acc then acc else r :: acc)
          [] whys
      in
      let stale =
        List.rev_map
          (fun r ->
            (r, List.filter_map (fun (r', k) -> if r = r' then Some k else None) whys))
          reasons
      in
      (todo, stale)
    else (mine, [])
  in
  if todo <> [] then Frameset.drop_view set;
  {
    source;
    overrides;
    dir;
    format;
    bits;
    fps;
    first;
    last;
    shard;
    todo;
    resumed = List.length mine - List.length todo;
    stale;
    set;
    inputs = Hashtbl.create 16;
    inputs_lock = Mutex.create ();
    chosen = None;
  }

let with_settings p budget adjust = { p with chosen = Some (budget, adjust) }

let evaluate ?cancel p k =
  Scenes.scene ?cancel p.source p.overrides ~time:(Float.of_int k /. p.fps) ~frame:k

(* The files a frame read, each with its digest now: what its record keeps. *)
let with_digests p files = List.map (fun f -> (f, p.source.input_digest f)) files

let frame_scene ?cancel p k =
  let sc, files = evaluate ?cancel p k in
  let sc, files =
    match p.chosen with
    | Some (_, adjust) ->
        let sc, more = adjust sc ~time:(Float.of_int k /. p.fps) ~frame:k in
        (sc, List.sort_uniq compare (files @ more))
    | None -> (sc, files)
  in
  let files = with_digests p files in
  Mutex.protect p.inputs_lock (fun () -> Hashtbl.replace p.inputs k files);
  sc

let frame_inputs p k = Mutex.protect p.inputs_lock (fun () -> Hashtbl.find_opt p.inputs k)

let write_frame p k sc fb =
  let inputs =
    match Mutex.protect p.inputs_lock (fun () -> Hashtbl.find_opt p.inputs k) with
    | Some i -> i
    | None -> with_digests p (snd (evaluate p k))
  in
  let path =
    Filename.concat p.dir (Frameset.frame_name ~ext:(Image.format_name p.format) k)
  in
  (* The plan refused every file the scene names; this is checked again against what the
     frames evaluated so far have read, by any name, before each frame is written. *)
  Files.refuse_overwrite ~reads:(Scenes.reads p.source) path "a frame";
  let record =
    Provenance.make ?max_error:(Option.map fst p.chosen) ~image:path p.source p.overrides
      ~files:inputs
      ~time:(Float.of_int k /. p.fps)
      ~frame:k ~region:None ~crop:false ~alpha:false
      ~bits:(Option.value p.bits ~default:8)
  in
  let written = Files.write_image ?bits:p.bits ~record path sc fb in
  Mutex.protect p.inputs_lock (fun () -> Hashtbl.remove p.inputs k);
  Frameset.record p.set k ~written ~inputs

(* How many frames a window holds (see [render]): their scenes are all evaluated before
   the first is rendered, so at most about 64 MB of their object arrays (8 bytes an
   object), and at least two. Over the 24 frames of scenes/bench/field_moving.rts (100 000
   still spheres, one moving across a tenth of the picture in eight frames), windows of 4,
   8, 12 and 24 frames render 832 000, 479 000, 382 000 and 348 000 of the frames' 3.1 M
   pixels: the box grows more slowly than the frames it covers. *)
let window (sc : Scene.t) = max 2 (min 24 (8_000_000 / max 1 (Array.length sc.objects)))

(* Whether a frame's pixels may be shared with other frames': none of its pixels is drawn
   at random by frame (jitter, a lens, the instants of an open shutter), and what its
   moving part holds is bounded. *)
let reusable (sc : Scene.t) =
  Array.length sc.moments = 0
  && (not sc.settings.jitter)
  && (not (Camera.depth_of_field sc.view))
  && Option.is_some (Accel.moving_bounds [ sc.accel ])

(* Whether two frames' scenes (of one program) differ only in their moving parts: the
   same settings, camera (so the same origin), lights and features, and the same fixed
   part (the program's static part: the same statements' objects). A pixel none of
   whose queries meets either moving part then has the same colour in both, bit for
   bit: every query's answer is the fixed part's, and every other input is equal. *)
let shares_pixels (a : Scene.t) (b : Scene.t) =
  (match (Accel.fixed_key a.accel, Accel.fixed_key b.accel) with
  | Some x, Some y -> x = y
  | _ -> false)
  &&
  try
    a.settings = b.settings && a.camera = b.camera && a.lights = b.lights
    && a.features = b.features
  with Invalid_argument _ -> false

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
      (* Whole frames in parallel, one domain each, where there are enough of them and
         they are small: small frames keep every core busy, and their encoding and
         writing run in parallel too. Otherwise one after the other, each over every
         domain in tiles. Scenes are evaluated in order on this domain; a frame's bytes
         are the same either way. *)
      let parallel =
        match pool with
        | Some pool when List.length p.todo >= 2 * domains && small -> Some pool
        | _ -> None
      in
      (* Frames [fs] (with their scenes), each rendered with [reuse] over the pool's
         domains in tiles, or in parallel one domain each. *)
      let frames ?reuse fs =
        let render_one (k, sc) =
          let fb, st =
            Render.render ?cancel ?pool:(if parallel = None then pool else None) ?reuse sc
          in
          write_frame p k sc fb;
          on_frame k st
        in
        match parallel with
        | Some pool when List.compare_length_with fs 1 > 0 ->
            let fs = Array.of_list fs in
            Pool.parallel_for pool (Array.length fs) (fun i -> render_one fs.(i))
        | _ -> List.iter render_one fs
      in
      (* The frames after [head] that [keep] accepts, at most [n], evaluated now: those
         taken, the first refused (which starts the next turn), and the rest. *)
      let rec take keep n acc = function
        | k :: rest when n > 0 ->
            let sc = scene k in
            if keep sc then take keep (n - 1) ((k, sc) :: acc) rest
            else (List.rev acc, Some (k, sc), rest)
        | rest -> (List.rev acc, None, rest)
      in
      let rec go head todo =
        match (head, todo) with
        | None, [] -> ()
        | None, k :: rest -> go (Some (k, scene k)) rest
        | Some (k, sc), rest when reusable sc ->
            (* A window: the frames after [k] that share its pixels. Frame k is
               rendered watching where the window's moving parts reach, over every
               domain; the others render only the pixels that met it. *)
            let later, next, rest =
              take
                (fun sc' -> reusable sc' && shares_pixels sc sc')
                (window sc - 1)
                [] rest
            in
            (if later = [] then frames [ (k, sc) ]
             else
               let box =
                 match
                   Accel.moving_bounds
                     (List.map (fun (_, (s : Scene.t)) -> s.accel) ((k, sc) :: later))
                 with
                 | Some b -> b
                 | None -> invalid_arg "Animation.render: an unbounded moving part"
               in
               let mask = Bytes.make (sc.settings.width * sc.settings.height) '\001' in
               let base, st =
                 Render.render ?cancel ?pool ~reuse:(Watch { box; mask }) sc
               in
               write_frame p k sc base;
               on_frame k st;
               frames ~reuse:(Only { mask; base }) later);
            go next rest
        | Some (k, sc), rest ->
            let batch = if parallel = None then 1 else 2 * domains in
            let more, next, rest = take (fun _ -> true) (batch - 1) [] rest in
            frames ((k, sc) :: more);
            go next rest
      in
      go None p.todo)

let finish p = ignore (Frameset.finish p.set ~input_digest:p.source.input_digest)
let frames_text n = Printf.sprintf "%d frame%s" n (if n = 1 then "" else "s")

let describe_range p =
  Printf.sprintf "%d..%d at %g fps%s" p.first p.last p.fps
    (match p.shard with Some (k, n) -> Printf.sprintf ", shard %d/%d" k n | None -> "")

(* Whether [prog] is an executable file in a directory of PATH, as the shell finds it. *)
let on_path prog =
  let executable f =
    (not (Sys.is_directory f))
    &&
    match Unix.access f [ Unix.X_OK ] with
    | () -> true
    | exception Unix.Unix_error _ -> false
  in
  List.exists
    (fun d ->
      let f = Filename.concat (if d = "" then Filename.current_dir_name else d) prog in
      Sys.file_exists f && executable f)
    (String.split_on_char ':' (Option.value (Sys.getenv_opt "PATH") ~default:""))

(* The video's name and place, and ffmpeg, are checked before the frames are rendered,
   not after. *)
let check_video ?(format = Image.Png) ~shard v =
  if format <> Image.Png then
    user
      "--video with %s frames: a video is made from PNG frames; render PNG frames for \
       it, or assemble the %s frames with a compositor"
      (Image.format_name format) (Image.format_name format);
  if shard then
    user
      "--video with --shard: a shard has only some of the frames; once every shard is \
       done, run lancer animate again with --resume --video";
  if not (Filename.check_suffix v ".mp4" || Filename.check_suffix v ".gif") then
    user "--video %s: the video must be a .mp4 or a .gif" v;
  Files.check_writable v;
  if not (on_path "ffmpeg") then
    user
      "--video %s needs ffmpeg, which is not installed (not found on PATH): install it \
       (apt-get install ffmpeg), or render the frames without --video"
      v

let make_video p out =
  let tmp =
    Filename.concat (Filename.dirname out)
      ("." ^ Filename.basename out ^ ".tmp" ^ Filename.extension out)
  in
  let cmd =
    Printf.sprintf "ffmpeg -loglevel error -y -framerate %g -start_number %d -i %s %s %s"
      p.fps p.first
      (Filename.quote (Filename.concat p.dir "frame_%04d.png"))
      (* check_video refused any other format *)
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
