open Lancer
open Lancer_job

exception User_error = Job_error.User

let user = Job_error.user

type opts = {
  scene : string option;
  output : string option;
  width : int option;
  height : int option;
  samples : int option;
  depth : int option;
  quality : Quality.t option;
  domains : int option;
  time : float option;
  frame : int option;
  stats : string option;
  quiet : bool;
  progress : bool;
}

let overrides (o : opts) : Overrides.t =
  {
    width = o.width;
    height = o.height;
    samples = o.samples;
    depth = o.depth;
    quality = o.quality;
  }

let default_opts () =
  {
    scene = None;
    output = None;
    width = None;
    height = None;
    samples = None;
    depth = None;
    quality = None;
    domains = None;
    time = None;
    frame = None;
    stats = None;
    quiet = false;
    progress = false;
  }

open Cmdliner

let max_side = 65536

type command = Render | Animate | Golden | Bench_domains | Bench_quality

(* Each command lists only the options it acts on; the help text of the scene and of -o
   says what they are for in that command. *)
let term command =
  let scene =
    let pos_scene ~doc =
      Arg.(value & pos 0 (some string) None & info [] ~docv:"SCENE.rts" ~doc)
    in
    let required ~doc =
      Term.(
        const Option.some
        $ Arg.(required & pos 0 (some string) None & info [] ~docv:"SCENE.rts" ~doc))
    in
    match command with
    | Render ->
        pos_scene
          ~doc:
            "The scene to render ($(b,-): read it from standard input). Without one, the \
             built-in showcase is rendered."
    | Animate ->
        required
          ~doc:
            "The scene to render ($(b,-): read it from standard input); it needs an \
             animation block."
    | Golden ->
        required
          ~doc:
            "The scene to render and compare with $(i,GOLDEN.png) ($(b,-): read it from \
             standard input)."
    | Bench_domains | Bench_quality ->
        pos_scene
          ~doc:"The scene to measure. Without one, the built-in showcase is measured."
  in
  let none = Term.const None in
  let output =
    match command with
    | Render ->
        Arg.(
          value
          & opt (some string) None
          & info [ "o"; "output" ] ~docv:"FILE"
              ~doc:
                "Output image (.png or .ppm); $(b,-) writes it to standard output; \
                 default: the scene's name with .png.")
    | Animate ->
        Arg.(
          value
          & opt (some string) None
          & info [ "o"; "output" ] ~docv:"DIR"
              ~doc:"Directory for the frames (created if missing).")
    | Golden | Bench_domains | Bench_quality -> none
  in
  let int_opt names docv doc =
    Arg.(value & opt (some int) None & info names ~docv ~doc)
  in
  (* The language's bound on a side, checked as the option is read. *)
  let side =
    let parse s =
      match int_of_string_opt s with
      | None -> Error (`Msg (Printf.sprintf "invalid value '%s', expected an integer" s))
      | Some n when n < 1 || n > max_side ->
          Error (`Msg (Printf.sprintf "must be 1 to %d pixels (got %d)" max_side n))
      | Some n -> Ok n
    in
    Arg.conv (parse, Format.pp_print_int)
  in
  let side_opt names docv doc =
    Arg.(value & opt (some side) None & info names ~docv ~doc)
  in
  let width =
    side_opt [ "width"; "W" ] "W"
      "Image width in pixels, 1 to 65536 (overrides the scene)."
  in
  let height =
    side_opt [ "height"; "H" ] "H"
      "Image height in pixels, 1 to 65536 (overrides the scene)."
  in
  let samples =
    int_opt [ "samples" ] "N"
      "N×N samples per pixel (overrides the scene and the quality preset)."
  in
  let depth =
    int_opt [ "depth" ] "D"
      "Maximum ray depth (overrides the scene and the quality preset)."
  in
  let quality =
    match command with
    | Bench_quality -> none
    | _ ->
        Arg.(
          value
          & opt (some (enum Quality.all)) None
          & info [ "quality" ] ~docv:"PRESET"
              ~doc:
                "$(b,draft), $(b,preview), $(b,final) or $(b,reference): presets of \
                 samples, depth, adaptive threshold and soft-shadow samples.")
  in
  let domains =
    match command with
    | Bench_domains -> none
    | _ ->
        int_opt [ "domains"; "j" ] "N"
          "Domains (cores) to render with; default: the number this machine recommends."
  in
  let time, frame =
    match command with
    | Render | Golden | Bench_domains ->
        ( Arg.(
            value
            & opt (some float) None
            & info [ "time"; "t" ] ~docv:"SECONDS"
                ~doc:
                  "Render the scene at this time (a negative one is written \
                   $(b,--time=-1))."),
          int_opt [ "frame" ] "K"
            "Render frame K of the animation (time = K / fps); the scene needs an \
             animation block with more than K frames." )
    | Animate | Bench_quality -> (none, none)
  in
  let stats =
    match command with
    | Render ->
        Arg.(
          value
          & opt (some string) None
          & info [ "stats" ] ~docv:"FILE" ~doc:"Write render statistics as JSON to FILE.")
    | _ -> none
  in
  let quiet, progress =
    match command with
    | Render | Animate | Golden ->
        ( Arg.(
            value & flag
            & info [ "q"; "quiet" ]
                ~doc:"No progress line, and no summary when all went well."),
          Arg.(
            value & flag
            & info [ "progress" ]
                ~doc:
                  "Report progress even when stderr is not a terminal: a line every 2 \
                   seconds (for logs, and under mpirun).") )
    | Bench_domains | Bench_quality -> (Term.const false, Term.const false)
  in
  let make scene output width height samples depth quality domains time frame stats quiet
      progress =
    {
      scene;
      output;
      width;
      height;
      samples;
      depth;
      quality;
      domains;
      time;
      frame;
      stats;
      quiet;
      progress;
    }
  in
  Term.(
    const make $ scene $ output $ width $ height $ samples $ depth $ quality $ domains
    $ time $ frame $ stats $ quiet $ progress)

let opts_term = term Render

let resume_still =
  Arg.(
    value & flag
    & info [ "resume" ]
        ~doc:
          "Keep finished tiles in a checkpoint next to the output (OUT.checkpoint) and \
           continue from it after an interruption; it is removed once the image is \
           written.")

(* ---- How the image of a still is written ---- *)

type encoding = {
  bits : int;
  alpha : bool;
  region : Image.region option;
  crop : bool;
  format : Image.format option;
}

let default_encoding =
  { bits = 8; alpha = false; region = None; crop = false; format = None }

let is_stdout p = p = "-"

(* The format of an output: its extension, or --format for standard output. *)
let format_of ?format path =
  if is_stdout path then Option.value format ~default:Image.Png
  else
    match (Image.format_of_path path, format) with
    | Error m, _ -> raise (User_error m)
    | Ok f, Some g when f <> g ->
        user
          "--format %s, but -o %s has the extension of the other format; --format is for \
           -o - (standard output)"
          (if g = Image.Png then "png" else "ppm")
          path
    | Ok f, _ -> f

let encoding_term =
  let bits =
    Arg.(
      value
      & opt (enum [ ("8", 8); ("16", 16) ]) 8
      & info [ "bits" ] ~docv:"8|16"
          ~doc:
            "Bits per channel of the image: 8 (default) or 16, with the same encoding \
             curve.")
  in
  let alpha =
    Arg.(
      value & flag
      & info [ "alpha" ]
          ~doc:
            "Add an alpha channel (PNG only): the share of each pixel's samples whose \
             primary ray hits a surface; 0 where only the background is seen.")
  in
  let region =
    let parse s =
      match List.map int_of_string_opt (String.split_on_char ',' s) with
      | [ Some x0; Some y0; Some x1; Some y1 ] -> Ok { Image.x0; y0; x1; y1 }
      | _ ->
          Error
            (`Msg
               (Printf.sprintf "--region expects x0,y0,x1,y1 (four integers), got %S" s))
    in
    let print ppf (r : Image.region) =
      Format.fprintf ppf "%d,%d,%d,%d" r.x0 r.y0 r.x1 r.y1
    in
    Arg.(
      value
      & opt (some (conv (parse, print))) None
      & info [ "region" ] ~docv:"X0,Y0,X1,Y1"
          ~doc:
            "Render only columns X0 to X1-1 of rows Y0 to Y1-1 (pixels, from the \
             top-left corner); the rest of the image is the background.")
  in
  let crop =
    Arg.(
      value & flag
      & info [ "crop" ]
          ~doc:"With $(b,--region): write only the region, not the whole image.")
  in
  let format =
    Arg.(
      value
      & opt (some (enum [ ("png", Image.Png); ("ppm", Image.Ppm) ])) None
      & info [ "format" ] ~docv:"png|ppm"
          ~doc:
            "The format of the image written to standard output with $(b,-o -) (default \
             png); with a file name, its extension decides.")
  in
  Term.(
    const (fun bits alpha region crop format -> { bits; alpha; region; crop; format })
    $ bits $ alpha $ region $ crop $ format)

(* What can be refused once the scene's size is known. *)
let check_encoding e ~out (sc : Scene.t) =
  if e.crop && e.region = None then user "--crop needs --region x0,y0,x1,y1";
  (match e.region with
  | Some r ->
      let w = sc.settings.width and h = sc.settings.height in
      if
        not
          (0 <= r.x0 && r.x0 < r.x1 && r.x1 <= w && 0 <= r.y0 && r.y0 < r.y1 && r.y1 <= h)
      then
        user
          "--region %d,%d,%d,%d is not inside the %d×%d image: it needs 0 <= x0 < x1 <= \
           %d and 0 <= y0 < y1 <= %d"
          r.x0 r.y0 r.x1 r.y1 w h w h
  | None -> ());
  if e.alpha && format_of ?format:e.format out = Image.Ppm then
    user "--alpha needs a PNG output: a PPM file has no alpha channel"

let progress o ~label ~total =
  let mode : Progress.mode =
    if o.quiet then Off
    else if Unix.isatty Unix.stderr then Terminal
    else if o.progress then Lines
    else Off
  in
  Progress.create ~mode ~label ~total ()

(* What the build is doing, on the progress channel: one line redrawn in place on a
   terminal, lines with --progress, nothing otherwise. *)
let building o what =
  match (o.quiet, Unix.isatty Unix.stderr, o.progress) with
  | true, _, _ -> ()
  | false, true, _ -> Printf.eprintf "\r\027[Kbuilding: %s…%!" what
  | false, false, true -> Printf.eprintf "building: %s\n%!" what
  | false, false, false -> ()

let built o = if (not o.quiet) && Unix.isatty Unix.stderr then Printf.eprintf "\r\027[K%!"

let writing o path f =
  let path = if path = "-" then "the image to standard output" else path in
  (match (o.quiet, Unix.isatty Unix.stderr, o.progress) with
  | true, _, _ | false, false, false -> ()
  | false, true, _ -> Printf.eprintf "\r\027[Kwriting %s…%!" path
  | false, false, true -> Printf.eprintf "writing %s\n%!" path);
  Fun.protect ~finally:(fun () -> built o) f

let build o f =
  let t0 = Unix.gettimeofday () in
  let r = Fun.protect ~finally:(fun () -> built o) (fun () -> f (building o)) in
  (r, Unix.gettimeofday () -. t0)

let summary ?size ~out (sc : Scene.t) ~build ~render ~workers (st : Stats.t) =
  let rays = Float.of_int (Stats.total_rays st) /. 1e6 in
  let w, h = Option.value size ~default:(sc.settings.width, sc.settings.height) in
  Printf.sprintf
    "wrote %s (%d×%d, %.2f s: build %.2f s, render %.2f s, %s, %.1f M rays, %.2f M \
     rays/s)"
    out w h (build +. render) build render workers rays
    (rays /. Float.max render 1e-9)

(* A count of rays the way a person reads it: 307 200, 18.4 M, 1.28 G. *)
let rays_text r =
  if not (r < 1e15) then "over 10^15"
  else if r >= 1e12 then Printf.sprintf "%.3g T" (r /. 1e12)
  else if r >= 1e9 then Printf.sprintf "%.3g G" (r /. 1e9)
  else if r >= 1e6 then Printf.sprintf "%.3g M" (r /. 1e6)
  else if r >= 1e3 then Printf.sprintf "%.3g k" (r /. 1e3)
  else Printf.sprintf "%.0f" r

(* [s] padded with spaces to [n] characters (UTF-8 characters, not bytes). *)
let pad n s =
  let w = ref 0 in
  String.iter (fun c -> if Char.code c land 0xC0 <> 0x80 then incr w) s;
  if !w >= n then s else s ^ String.make (n - !w) ' '

let cost_report (sc : Scene.t) =
  let range lo hi = if lo < hi then rays_text lo ^ "–" ^ rays_text hi else rays_text hi in
  let base = (Cost.estimate sc).direct in
  let line name (sc : Scene.t) =
    let c = Cost.estimate sc in
    Printf.sprintf "  %s %s %s %s %s\n" (pad 10 name)
      (pad 16 (range c.primary_low c.primary))
      (pad 18 (range c.direct_low c.direct))
      (pad 22 (Printf.sprintf "%s (depth %d)" (rays_text c.bound) sc.settings.depth))
      (if base > 0. then Printf.sprintf "%.3g" (c.direct /. base) else "-")
  in
  let presets =
    List.filter_map
      (fun (name, q) ->
        match Quality.apply q sc with Ok s -> Some (line name s) | Error _ -> None)
      Quality.all
  in
  "rays, estimated before rendering (each primary ray counted as a hit lit by every \
   light; a range where adaptive\n\
   sampling refines none to all of the pixels):\n"
  ^ Printf.sprintf "  %s %s %s %s %s\n" (pad 10 "quality") (pad 16 "primary")
      (pad 18 "with shadow rays")
      (pad 22 "at most, every bounce")
      "× as set"
  ^ line "as set" sc ^ String.concat "" presets

(* Renders estimated above this many rays (minutes on a small machine) say so first. *)
let long_render_rays = 1e9

let warn_long_render o (sc : Scene.t) =
  let c = Cost.estimate sc in
  if (not o.quiet) && c.direct > long_render_rays then
    Printf.eprintf
      "lancer: note: this render is estimated at up to %s rays (%s primary; at most %s \
       with every bounce): it may take long; `lancer check` compares the quality presets\n\
       %!"
      (rays_text c.direct) (rays_text c.primary) (rays_text c.bound)

let exits =
  [
    Cmd.Exit.info 0 ~doc:"on success.";
    Cmd.Exit.info 1
      ~doc:"on a user error: a scene, option or file problem, explained in one message.";
    Cmd.Exit.info 2 ~doc:"on an internal error (a bug in lancer; please report it).";
    Cmd.Exit.info 130 ~doc:"when interrupted (Ctrl-C); no output file is left behind.";
  ]

(* The OCaml runtime refuses to start more than 128 domains. *)
let max_domains = 128

let domains o =
  match o.domains with
  | Some n when n < 1 -> user "--domains must be at least 1 (got %d)" n
  | Some n when n > max_domains ->
      user
        "--domains must be at most %d, the most the OCaml runtime can run (got %d; this \
         machine recommends %d)"
        max_domains n
        (Domain.recommended_domain_count ())
  | Some n -> n
  | None -> max 1 (Domain.recommended_domain_count ())

(* A scene named "-" is read from standard input, once however often it is asked for; its
   errors are located in "<stdin>" and its includes are found from the current
   directory. *)
let stdin_name = "<stdin>"

let stdin_text =
  lazy
    (if Unix.isatty Unix.stdin then
       prerr_endline "lancer: reading the scene from standard input (end it with Ctrl-D)";
     set_binary_mode_in stdin true;
     try In_channel.input_all stdin
     with Sys_error m -> user "cannot read the scene from standard input: %s" m)

let source o =
  match o.scene with
  | None -> ("showcase.rts", Showcase.text)
  | Some "-" -> (stdin_name, Lazy.force stdin_text)
  | Some path ->
      if not (Sys.file_exists path) then user "%s: no such file" path;
      if Sys.is_directory path then user "%s: is a directory, not a scene file" path;
      Option.iter
        (fun m -> user "%s: cannot read the scene: %s" path m)
        (Program.source_problem path);
      let text =
        try In_channel.with_open_bin path In_channel.input_all
        with Sys_error m -> user "%s" m
      in
      (path, text)

(* An exact simulation that gave up after Physics.max_events is worth a warning: the
   bodies move on without colliding after that. *)
let warn_truncated prog =
  Option.iter
    (fun time ->
      Printf.eprintf
        "lancer: warning: the physics simulation stopped handling collisions after %d \
         events (at %.6g s); bodies fly freely from there\n\
         %!"
        Physics.max_events time)
    (Program.truncated_physics prog)

let load_source ?progress ?digests (filename, text) =
  match Program.load_string ?progress ?digests ~filename text with
  | Ok p ->
      warn_truncated p;
      p
  | Error errs when filename = "showcase.rts" && text == Showcase.text ->
      user "the built-in showcase does not load:\n%s" (Job_error.errors_text errs)
  | Error errors -> raise (Job_error.Scene { errors; note = "" })

let load_bundle b =
  match Program.load_bundle b with
  | Ok p -> p
  | Error errors -> raise (Job_error.Scene { errors; note = "" })

let load ?progress ?digests scene =
  load_source ?progress ?digests (source { (default_opts ()) with scene })
let scene_source (o : opts) prog = Program.source ~builtin:(o.scene = None) prog

let default_output o =
  match (o.output, o.scene) with
  | Some p, _ -> p
  | None, None -> "showcase.png"
  | None, Some "-" ->
      user
        "a scene read from standard input has no name to make the image's from: give one \
         with -o FILE"
  | None, Some s -> Filename.remove_extension (Filename.basename s) ^ ".png"

let check_writable = Files.check_writable

let check_output ?format path =
  ignore (format_of ?format path);
  if is_stdout path then (
    if Unix.isatty Unix.stdout then
      user
        "-o - writes the image to standard output, which is a terminal here; redirect it \
         (-o - > image.png) or pipe it")
  else check_writable path

(* ---- What a run reads and what it writes ---- *)

let reads = Source.reads
let guard_writes ?distinct ~reads writes = Files.guard_writes ?distinct ~reads writes

(* --stats takes a value: [lancer render --stats scene.rts] means the scene was taken as
   its value. A statistics file is JSON; lancer's own kinds of files are refused. *)
let check_stats_name = function
  | None -> ()
  | Some p -> (
      match String.lowercase_ascii (Filename.extension p) with
      | (".rts" | ".png" | ".ppm" | ".obj" | ".gif" | ".mp4") as e ->
          let kind =
            match e with
            | ".rts" -> "a scene"
            | ".obj" -> "a mesh"
            | ".gif" | ".mp4" -> "a video"
            | _ -> "an image"
          in
          user
            "--stats %s: statistics are written as JSON, and that name is %s's; did \
             --stats take the scene as its value? Write --stats FILE.json"
            p kind
      | _ -> ())

(* The records an animation keeps in its frames directory (Frameset's names): no other
   output may replace them. *)

let refuse_frames_records paths =
  List.iter
    (fun (p, what) ->
      if
        String.equal (Filename.basename p) Frameset.view_name
        || String.equal (Filename.basename (Filename.dirname p)) Frameset.journal_dir
      then
        user
          "%s %s would replace a record of an animation's frames directory: write it \
           elsewhere"
          what p)
    paths

let guard_render (o : opts) src ~out =
  if is_stdout out && o.stats = Some "-" then
    user "--stats - and -o - would both write to standard output: give --stats a file";
  refuse_frames_records
    ((if is_stdout out then [] else [ (out, "-o") ])
    @ match o.stats with Some p -> [ (p, "--stats") ] | None -> []);
  guard_writes ~reads:(reads src)
    ((if is_stdout out then [] else [ (out, "the image") ])
    @ match o.stats with Some p -> [ (p, "the statistics") ] | None -> [])

let time_of (o : opts) src = Source.time_of src ~time:o.time ~frame:o.frame

let scene_with_files ?progress ?cancel o src ~time ~frame =
  Source.scene ?progress ?cancel src (overrides o) ~time ~frame

let scene_at ?progress ?cancel o src ~time ~frame =
  fst (scene_with_files ?progress ?cancel o src ~time ~frame)

let checkpoint o src ~out ~time ~frame ~files sc =
  let ck =
    Checkpoint.start ~out ~key:(Checkpoint.key src (overrides o) ~time ~frame ~files) sc
  in
  if Checkpoint.resumed ck > 0 && not o.quiet then
    Printf.printf "resuming: %d of %d tiles already rendered\n%!" (Checkpoint.resumed ck)
      (Checkpoint.tiles ck);
  ck

(* Standard output carries the image's bytes and nothing else; a reader that goes away
   (a closed pipe) is an error to report, not a signal that kills. *)
let write_stdout fmt raster =
  Sys.set_signal Sys.sigpipe Sys.Signal_ignore;
  set_binary_mode_out stdout true;
  match
    Image.output_raster fmt stdout raster;
    flush stdout
  with
  | () -> ()
  | exception Sys_error m -> user "cannot write the image to standard output: %s" m

let write_image ?cancel ?(encoding = default_encoding) ?alpha path (sc : Scene.t) fb =
  let crop = if encoding.crop then encoding.region else None in
  if is_stdout path then
    Files.uninterrupted ?cancel "the image on standard output" (fun () ->
        write_stdout
          (format_of ?format:encoding.format path)
          (Image.encode ~gamma:sc.settings.gamma ~bits:encoding.bits ?alpha ?crop fb))
  else ignore (Files.write_image ?cancel ~bits:encoding.bits ?alpha ?crop path sc fb)

let peak_memory_kib () =
  match In_channel.with_open_text "/proc/self/status" In_channel.input_all with
  | exception _ -> None
  | text ->
      List.find_map
        (fun line ->
          match String.split_on_char ':' line with
          | [ "VmHWM"; v ] -> Scanf.sscanf_opt (String.trim v) "%d kB" Fun.id
          | _ -> None)
        (String.split_on_char '\n' text)

let stats_json o (sc : Scene.t) ~build ~wall ~domains ~ranks (st : Stats.t) =
  let s = sc.settings in
  let rays = Stats.total_rays st in
  let opt_int = function Some n -> `Int n | None -> `Null in
  `Assoc
    [
      ("scene", match o.scene with Some p -> `String p | None -> `String "(showcase)");
      ("width", `Int s.width);
      ("height", `Int s.height);
      ("samples", `Int s.samples);
      ("depth", `Int s.depth);
      ("adaptive", `Float s.adaptive);
      ("time", `Float sc.time);
      ("frame", `Int sc.frame);
      ("domains", `Int domains);
      ("ranks", `Int ranks);
      ("wall_seconds", `Float (build +. wall));
      ("build_seconds", `Float build);
      ("render_seconds", `Float wall);
      ( "rays",
        `Assoc
          [
            ("primary", `Int st.primary);
            ("shadow", `Int st.shadow);
            ("reflected", `Int st.reflected);
            ("refracted", `Int st.refracted);
            ("total", `Int rays);
          ] );
      ("rays_per_second", `Float (if wall > 0. then Float.of_int rays /. wall else 0.));
      ("bad_samples", `Int st.bad_samples);
      ("peak_memory_kib", opt_int (peak_memory_kib ()));
      ("objects", `Int (Scene.object_count sc));
      ("lights", `Int (Array.length sc.lights));
      ( "features",
        `Assoc (List.map (fun (k, b) -> (k, `Bool b)) (Features.to_list sc.features)) );
      ( "options",
        `Assoc
          [
            ( "quality",
              match o.quality with
              | Some q -> `String (Quality.to_string q)
              | None -> `Null );
            ("width", opt_int o.width);
            ("height", opt_int o.height);
            ("samples", opt_int o.samples);
            ("depth", opt_int o.depth);
            ("domains", opt_int o.domains);
          ] );
    ]

let write_json = Files.write_json

let warn_bad_samples (st : Stats.t) =
  if st.bad_samples > 0 then
    match st.first_bad with
    | Some (i, j) ->
        Printf.eprintf
          "lancer: warning: %d samples were NaN or infinite (first at pixel %d,%d); they \
           were replaced by the background\n\
           %!"
          st.bad_samples i j
    | None -> ()

(* Cmdliner reads "-5" as an option, so "--time -5" fails: find such a value and say how
   to write it. *)
let negative_value_hint argv =
  let is_negative a =
    String.length a >= 2
    && a.[0] = '-'
    && (match a.[1] with '0' .. '9' | '.' -> true | _ -> false)
    && Float.of_string_opt a <> None
  in
  let args = Array.to_list argv in
  let rec find = function
    | "--" :: _ | [] | [ _ ] -> None
    | opt :: v :: _
      when is_negative v
           && String.length opt > 1
           && opt.[0] = '-'
           && not (String.contains opt '=') ->
        let long = String.length opt > 2 && opt.[1] = '-' in
        Some
          (if long then Printf.sprintf "a negative value is written with '=': %s=%s" opt v
           else
             Printf.sprintf "a negative value is written next to its option: %s%s" opt v)
    | _ :: rest -> find rest
  in
  match args with _ :: rest -> find rest | [] -> None

let status_of_eval code =
  if code = Cmd.Exit.cli_error then 1
  else if code = Cmd.Exit.internal_error then 2
  else code
