open Lancer
open Cmdliner

type command = Render | Animate | Golden | Bench_domains | Bench_quality

(* Each command lists only the options it acts on; the help text of the scene and of -o
   says what they are for in that command. An option a command does not take is a term
   of its default. *)
let none = Term.const None
let int_opt names docv doc = Arg.(value & opt (some int) None & info names ~docv ~doc)

let scene command =
  let optional ~doc =
    Arg.(value & pos 0 (some string) None & info [] ~docv:"SCENE.rts" ~doc)
  in
  let required ~doc =
    Term.(
      const Option.some
      $ Arg.(required & pos 0 (some string) None & info [] ~docv:"SCENE.rts" ~doc))
  in
  match command with
  | Render ->
      optional
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
      optional
        ~doc:"The scene to measure. Without one, the built-in showcase is measured."

let output = function
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

(* The language's bound on a side, checked as the option is read. *)
let side names docv doc =
  let parse s =
    match int_of_string_opt s with
    | None -> Error (`Msg (Printf.sprintf "invalid value '%s', expected an integer" s))
    | Some n when n < 1 || n > Options.max_side ->
        Error (`Msg (Printf.sprintf "must be 1 to %d pixels (got %d)" Options.max_side n))
    | Some n -> Ok n
  in
  Arg.(
    value & opt (some (conv (parse, Format.pp_print_int))) None & info names ~docv ~doc)

let width =
  side [ "width"; "W" ] "W" "Image width in pixels, 1 to 65536 (overrides the scene)."

let height =
  side [ "height"; "H" ] "H" "Image height in pixels, 1 to 65536 (overrides the scene)."

let size = Term.(const (fun w h -> (w, h)) $ width $ height)

let samples =
  int_opt [ "samples" ] "N"
    "N×N samples per pixel (overrides the scene and the quality preset)."

let depth =
  int_opt [ "depth" ] "D"
    "Maximum ray depth (overrides the scene and the quality preset)."

let quality = function
  | Bench_quality -> none
  | Render | Animate | Golden | Bench_domains ->
      Arg.(
        value
        & opt (some (enum Quality.all)) None
        & info [ "quality" ] ~docv:"PRESET"
            ~doc:
              "$(b,draft), $(b,preview), $(b,final) or $(b,reference): presets of \
               samples, depth, adaptive threshold and soft-shadow samples.")

let domains = function
  | Bench_domains -> none
  | Render | Animate | Golden | Bench_quality ->
      int_opt [ "domains"; "j" ] "N"
        "Domains (cores) to render with; default: the number this machine recommends."

let time = function
  | Render | Golden | Bench_domains ->
      Arg.(
        value
        & opt (some float) None
        & info [ "time"; "t" ] ~docv:"SECONDS"
            ~doc:
              "Render the scene at this time (a negative one is written $(b,--time=-1)).")
  | Animate | Bench_quality -> none

let frame = function
  | Render | Golden | Bench_domains ->
      int_opt [ "frame" ] "K"
        "Render frame K of the animation (time = K / fps); the scene needs an animation \
         block with more than K frames."
  | Animate | Bench_quality -> none

let stats = function
  | Render ->
      Arg.(
        value
        & opt (some string) None
        & info [ "stats" ] ~docv:"FILE"
            ~doc:
              "Write render statistics as JSON to FILE; $(b,-) writes them to standard \
               output (and the summary line to standard error).")
  | Animate | Golden | Bench_domains | Bench_quality -> none

let quiet = function
  | Render | Animate | Golden ->
      Arg.(
        value & flag
        & info [ "q"; "quiet" ]
            ~doc:
              "No progress line, no warnings (those of $(b,lancer check)), and no \
               summary when all went well.")
  | Bench_domains | Bench_quality -> Term.const false

let progress = function
  | Render | Animate | Golden ->
      Arg.(
        value & flag
        & info [ "progress" ]
            ~doc:
              "Report progress as lines from the start when stderr is not a terminal: a \
               line every 2 seconds, and what the build is doing (for logs, and under \
               mpirun). Without it such a log gets a line every 5 seconds once the \
               command has run that long.")
  | Bench_domains | Bench_quality -> Term.const false

let term c =
  let options scene output width height samples depth quality domains time frame stats
      quiet progress =
    {
      Options.scene;
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
    const options $ scene c $ output c $ width $ height $ samples $ depth $ quality c
    $ domains c $ time c $ frame c $ stats c $ quiet c $ progress c)

let resume_still =
  Arg.(
    value & flag
    & info [ "resume" ]
        ~doc:
          "Keep finished tiles in a checkpoint next to the output (OUT.checkpoint) and \
           continue from it after an interruption; it is removed once the image is \
           written.")

let formats =
  List.map (fun f -> (Image.format_name f, f)) Image.[ Png; Ppm; Exr; Hdr; Pfm ]

let encoding_term =
  let bits =
    Arg.(
      value
      & opt (some (enum [ ("8", 8); ("16", 16); ("32", 32) ])) None
      & info [ "bits" ] ~docv:"8|16|32"
          ~doc:
            "Bits per channel: 8 (the default) or 16 for a PNG or PPM image, with the \
             same encoding curve; 16 (half floats, the default) or 32 (floats) for an \
             EXR image.")
  in
  let alpha =
    Arg.(
      value & flag
      & info [ "alpha" ]
          ~doc:
            "Add an alpha channel (PNG or EXR): the share of each pixel's samples whose \
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
      & opt (some (enum formats)) None
      & info [ "format" ] ~docv:"png|ppm|exr|hdr|pfm"
          ~doc:
            "The format of the image written to standard output with $(b,-o -) (default \
             png); with a file name, its extension decides. EXR, HDR and PFM hold the \
             linear values themselves, before the encoding curve.")
  in
  Term.(
    const (fun bits alpha region crop format ->
        { Output.bits; alpha; region; crop; format })
    $ bits $ alpha $ region $ crop $ format)

let aov_term =
  Arg.(
    value
    & opt (some string) None
    & info [ "aov" ] ~docv:"object,depth,normal"
        ~doc:
          "Also write, beside the image $(i,OUT).png, images of what the ray through \
           each pixel's centre meets (any of the names, comma-separated): $(b,object) \
           the object, as 16-bit gray ids in $(i,OUT).object.png (0 the background, k \
           the k-th object of the scene), listed with their kind and file:line in \
           $(i,OUT).objects.json; $(b,depth) the distance to it in $(i,OUT).depth.pfm; \
           $(b,normal) its shading normal n as the colour (n+1)/2 in \
           $(i,OUT).normal.png. The image itself is the same as without.")

let max_error_term =
  let limit =
    Arg.(
      value
      & opt (some float) None
      & info [ "max-error" ] ~docv:"E"
          ~doc:
            "Choose the cheapest samples, adaptive threshold, depth, area-light, lens \
             and shutter samples whose error against the $(b,reference) preset, \
             predicted from probe pixels rendered at both, is at most $(i,E) (in the \
             unit of $(b,--metric)); say what was chosen, the predicted error and time \
             against the reference's, then render with them. An animation's are chosen \
             once, on its first, middle and last frames, and used for every frame. Not \
             with $(b,--samples), $(b,--depth), $(b,--quality), nor $(b,--resume) for a \
             still; an image's record keeps the settings chosen, for $(b,lancer verify).")
  in
  let metric =
    Arg.(
      value
      & opt (enum [ ("flip", `Flip); ("rmse", `Rmse); ("psnr", `Psnr) ]) `Flip
      & info [ "metric" ] ~docv:"flip|rmse|psnr"
          ~doc:
            "The unit of $(b,--max-error): $(b,flip), the mean FLIP (0–1, the default); \
             $(b,rmse), the RMSE (0–255); $(b,psnr), the PSNR in dB (then at least \
             $(i,E)).")
  in
  Term.(
    const (fun e m ->
        Option.map
          (fun e ->
            match m with
            | `Flip -> Compare.Flip e
            | `Rmse -> Compare.Rmse e
            | `Psnr -> Compare.Psnr e)
          e)
    $ limit $ metric)

let frames_term =
  let frames =
    let parse s =
      match Plan.frames_of_string s with Ok r -> Ok r | Error m -> Error (`Msg m)
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
             (checked against their recorded size and MD5), and say why the others a run \
             recorded are rendered again (another option, a changed scene or input, a \
             missing file).")
  in
  let video =
    Arg.(
      value
      & opt (some string) None
      & info [ "video" ] ~docv:"OUT.mp4"
          ~doc:
            "Assemble the frames into a video (.mp4 or .gif) with ffmpeg, which must be \
             on PATH: that is checked before any frame is rendered.")
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
  let format =
    Arg.(
      value
      & opt (enum formats) Image.Png
      & info [ "format" ] ~docv:"png|ppm|exr|hdr|pfm"
          ~doc:
            "The frames' format: frame_0000.png (the default), or .ppm, or the linear \
             .exr, .hdr or .pfm, which hold the values themselves, before the encoding \
             curve.")
  in
  let bits =
    Arg.(
      value
      & opt (some (enum [ ("8", 8); ("16", 16); ("32", 32) ])) None
      & info [ "bits" ] ~docv:"8|16|32"
          ~doc:
            "Bits per channel of the frames: 8 (the default) or 16 for PNG or PPM; 16 \
             (half floats, the default) or 32 (floats) for EXR.")
  in
  Term.(
    const (fun frames resume video shard format bits ->
        { Frames_run.frames; resume; video; shard; format; bits })
    $ frames $ resume $ video $ shard $ format $ bits)

(* The project's issue tracker (dune-project's bug_reports). *)
let bug_tracker = "https://github.com/lancer/lancer/issues"

let exits =
  [
    Cmd.Exit.info 0 ~doc:"on success.";
    Cmd.Exit.info 1
      ~doc:"on a user error: a scene, option or file problem, explained in one message.";
    Cmd.Exit.info 2
      ~doc:
        ("on an internal error: a bug in lancer; please report it at " ^ bug_tracker ^ ".");
    Cmd.Exit.info 130 ~doc:"when interrupted (Ctrl-C); no output file is left behind.";
  ]

(* Where bugs are reported: every man page's BUGS section. *)
let bugs =
  [
    `S Manpage.s_bugs;
    `P
      ("Report bugs at " ^ bug_tracker
     ^ ", with the scene and the command that show them.");
  ]

(* The environment every command reads, for its man page's ENVIRONMENT section. *)
let envs =
  [
    Cmd.Env.info "LANCER_PATH"
      ~doc:
        "Directories (separated by $(b,:)) where $(b,include \"lancer/...\") looks for \
         lancer's scene library before PREFIX/share beside the executable and the copy \
         built into it.";
    Cmd.Env.info "LANCER_PROGRESS_INTERVAL"
      ~doc:
        "The seconds between two progress lines when stderr is not a terminal (default \
         5, or 2 with $(b,--progress)); 0 prints a line for every tile or frame, \
         $(b,off) none (unless $(b,--progress) asks for them).";
    Cmd.Env.info "OCAMLRUNPARAM"
      ~doc:
        "The OCaml runtime's parameters. Under a limit on the address space (ulimit -v) \
         lancer sets the number of domains the runtime reserves memory for, unless this \
         sets it ($(b,d)).";
    Cmd.Env.info "MALLOC_ARENA_MAX"
      ~doc:
        "The C library's malloc arenas; under a limit on the address space lancer keeps \
         them to an eighth of it unless this (or GLIBC_TUNABLES) sets them.";
  ]

(* What --shard slurm reads. *)
let slurm_envs =
  List.map
    (fun (v, doc) -> Cmd.Env.info v ~doc)
    [
      ( "SLURM_ARRAY_TASK_ID",
        "With $(b,--shard slurm): this task's index in the job array." );
      ("SLURM_ARRAY_TASK_COUNT", "With $(b,--shard slurm): the number of tasks.");
      ("SLURM_ARRAY_TASK_MIN", "With $(b,--shard slurm): the first index (default 0).");
      ( "SLURM_ARRAY_TASK_STEP",
        "With $(b,--shard slurm): the step between indices (default 1)." );
    ]

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
