let user = Job_error.user

let check_tolerance tolerance share =
  if tolerance < 0 || tolerance > 255 then
    user "--tolerance must be between 0 and 255 (got %d)" tolerance;
  if not (share >= 0. && share <= 1.) then
    user "--max-share must be between 0 and 1 (got %g)" share

type metric = Max | Rmse | Psnr | Flip | Ssim

let metric_names =
  [ ("max", Max); ("rmse", Rmse); ("psnr", Psnr); ("flip", Flip); ("ssim", Ssim) ]

let metric_name metric = fst (List.find (fun (_, m) -> m = metric) metric_names)

(* Refuse a metric's limit out of its range. *)
let check_limit =
  Option.iter (fun m ->
      match Compare.check_metric m with
      | Ok () -> ()
      | Error e -> user "--tolerance: %s" e)

(* The limit of a --metric given by --tolerance, as the library takes it; None for the
   per-channel tolerance. *)
let limit metric tolerance =
  let need what =
    user "--metric %s needs --tolerance: %s that still counts as equal"
      (metric_name metric) what
  in
  let m =
    match (metric, tolerance) with
    | Max, _ -> None
    | Rmse, None -> need "the largest RMSE (0–255)"
    | Psnr, None -> need "the smallest PSNR (dB)"
    | Flip, None -> need "the largest mean FLIP (0–1)"
    | Ssim, None -> need "the smallest SSIM (-1–1)"
    | Rmse, Some t -> Some (Compare.Rmse t)
    | Psnr, Some t -> Some (Compare.Psnr t)
    | Flip, Some t -> Some (Compare.Flip t)
    | Ssim, Some t -> Some (Compare.Ssim t)
  in
  check_limit m;
  m

(* The per-channel tolerance of --metric max, a whole number. *)
let channel_tolerance = function
  | None -> 1
  | Some t when Float.is_integer t && Float.abs t < 1e6 -> Float.to_int t
  | Some t -> user "--tolerance must be a whole number between 0 and 255 (got %g)" t

let judge metric tolerance ~share =
  let m = limit metric tolerance in
  let channel = match m with None -> channel_tolerance tolerance | Some _ -> 1 in
  check_tolerance channel share;
  (channel, m)

let diff ?out ?(json = false) ~metric ~tolerance ~share a b =
  let channel, judge = judge metric tolerance ~share in
  Option.iter
    (fun p ->
      Files.guard_writes
        ~reads:[ (a, "an image this diff compares"); (b, "an image this diff compares") ]
        [ (p, "the diff image") ])
    out;
  let read p =
    match Image.read_rgb8 p with Ok i -> i | Error m -> raise (Job_error.User m)
  in
  let ((wa, ha, _) as ia) = read a and ((wb, hb, _) as ib) = read b in
  if (wa, ha) <> (wb, hb) then
    user "%s is %d×%d but %s is %d×%d: only images of the same size can be compared" a wa
      ha b wb hb;
  let c =
    match Compare.compare ~threshold:channel ia ib with
    | Error m -> raise (Job_error.User m)
    | Ok c -> c
  in
  let map = Flip.error_map ia ib in
  let flip = Flip.mean map and ssim = Result.to_option (Ssim.ssim ia ib) in
  let judged =
    Option.map
      (fun m ->
        ( m,
          match m with
          | Compare.Rmse _ -> c.rmse
          | Compare.Psnr _ -> c.psnr
          | Compare.Flip _ -> flip
          | Compare.Ssim _ -> Option.value ssim ~default:Float.nan ))
      judge
  in
  (match judged with
  | Some (Compare.Ssim _, v) when Float.is_nan v ->
      user "--metric ssim: SSIM needs images of at least %d×%d pixels (these are %d×%d)"
        Ssim.window Ssim.window wa ha
  | _ -> ());
  let ok = Compare.within ~max_diff:channel ~max_share:share { c with judged } in
  let word =
    if c.max_diff = 0 then "same" else if ok then "within tolerance" else "differ"
  in
  let verdict =
    match judged with
    | Some j when c.max_diff <> 0 -> Format.asprintf "%s (%a)" word Compare.pp_judged j
    | _ -> word
  in
  Option.iter
    (fun p ->
      match Image.write_rgb8 p wa ha (Flip.grey map) with
      | Ok () -> ()
      | Error m -> raise (Job_error.User m))
    out;
  if json then
    let num v = if Float.is_finite v then `Float v else `Null in
    let doc =
      `Assoc
        ([
           ("a", `String a);
           ("b", `String b);
           ("verdict", `String word);
           ("within", `Bool ok);
           ("metric", `String (metric_name metric));
           ( "tolerance",
             match judge with
             | None -> `Int channel
             | Some (Compare.Rmse l | Psnr l | Flip l | Ssim l) -> num l );
           ("max_share", `Float share);
           ("width", `Int wa);
           ("height", `Int ha);
           ("max_diff", `Int c.max_diff);
           ("rmse", `Float c.rmse);
           ("psnr", num c.psnr);
           ("over", `Int c.over);
           ("over_share", `Float c.over_share);
           ("flip", `Float flip);
           ("ssim", match ssim with Some s -> `Float s | None -> `Null);
         ]
        @ match out with Some p -> [ ("diff_image", `String p) ] | None -> [])
    in
    print_endline (Yojson.Safe.pretty_to_string doc)
  else (
    Format.printf "%s: %a, mean FLIP %.4f, SSIM %s@." verdict Compare.pp c flip
      (match ssim with
      | Some s -> Printf.sprintf "%.4f" s
      | None -> Printf.sprintf "undefined (under %d×%d pixels)" Ssim.window Ssim.window);
    Option.iter (Printf.printf "FLIP error map: %s\n") out);
  ok

let golden ?cancel ?metric (o : Options.t) ~golden ~tolerance ~share ~update =
  check_tolerance tolerance share;
  check_limit metric;
  let prog = Scene_file.load o.scene in
  let src = Scene_file.source o prog in
  let time, frame = Options.time_of o src in
  let sc = Options.scene_at o src ~time ~frame in
  (* A golden of another size can never match: say so before rendering, and how to fix it. *)
  (if (not update) && Sys.file_exists golden then
     match Image.read_rgb8 golden with
     | Ok (gw, gh, _) when (gw, gh) <> (sc.settings.width, sc.settings.height) ->
         user
           "the golden %s is %d×%d but the render would be %d×%d: render at the golden's \
            size with --width %d --height %d, or remake the golden with --update"
           golden gw gh sc.settings.width sc.settings.height gw gh
     | _ -> ());
  let sibling suffix = Filename.remove_extension golden ^ suffix in
  Files.guard_writes
    ~reads:
      (if update then Scenes.reads src
       else (golden, "the golden image") :: Scenes.reads src)
    (if update then [ (golden, "the golden image") ]
     else
       [
         (sibling ".actual.png", "the actual image");
         (sibling ".diff.png", "the diff image");
       ]);
  let progress =
    Progress.for_options o ~label:"tiles" ~total:(Array.length (Render.tiles sc))
  in
  let fb, _ =
    Render.with_pool ?cancel (Options.domains o) (fun pool ->
        Render.render ?cancel ?pool
          ~on_tile:(fun d _ rays -> Progress.update ~rays progress d)
          sc)
  in
  Progress.finish progress;
  let actual = (fb.width, fb.height, Image.to_bytes sc.settings.gamma fb) in
  match Compare.golden ~tolerance ~max_share:share ?metric ~update ~golden actual with
  | Error m -> user "%s" m
  | Ok (Compare.Updated g) ->
      if not o.quiet then Printf.printf "golden written: %s\n" g;
      true
  | Ok (Compare.Missing { actual }) ->
      user
        "%s does not exist; the render is in %s (run again with --update to make it the \
         golden)"
        golden actual
  | Ok (Compare.Same c) ->
      if not o.quiet then
        Format.printf "%s %s: %a@."
          (if c.max_diff = 0 then "same as" else "within tolerance of")
          golden Compare.pp c;
      true
  | Ok (Compare.Different { figures; actual = a; diff }) ->
      Format.printf "differs from %s: %a@.actual: %s@.diff: %s@." golden Compare.pp
        figures a diff;
      Option.iter print_endline
        (Aov_run.golden_hint ~tolerance prog ~time ~frame sc ~golden actual);
      false
