let user = Job_error.user

let check_tolerance tolerance share =
  if tolerance < 0 || tolerance > 255 then
    user "--tolerance must be between 0 and 255 (got %d)" tolerance;
  if not (share >= 0. && share <= 1.) then
    user "--max-share must be between 0 and 1 (got %g)" share

(* One word for the outcome, before the figures. *)
let verdict ~tolerance ~share (c : Compare.t) =
  if c.max_diff = 0 then "same"
  else if Compare.within ~max_diff:tolerance ~max_share:share c then "within tolerance"
  else "differ"

let diff ?out ~tolerance ~share a b =
  check_tolerance tolerance share;
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
  match Compare.compare ~threshold:tolerance ia ib with
  | Error m -> raise (Job_error.User m)
  | Ok c ->
      Format.printf "%s: %a@." (verdict ~tolerance ~share c) Compare.pp c;
      Option.iter
        (fun p ->
          let w, h, _ = ia in
          match
            Image.write_rgb8 p w h (Compare.diff_image ~threshold:tolerance ia ib)
          with
          | Ok () -> Printf.printf "diff image: %s\n" p
          | Error m -> raise (Job_error.User m))
        out;
      Compare.within ~max_diff:tolerance ~max_share:share c

let golden ?cancel (o : Options.t) ~golden ~tolerance ~share ~update =
  check_tolerance tolerance share;
  let src = Scene_file.source o (Scene_file.load o.scene) in
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
      (if update then Source.reads src
       else (golden, "the golden image") :: Source.reads src)
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
  match Compare.golden ~tolerance ~max_share:share ~update ~golden actual with
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
  | Ok (Compare.Different { figures; actual; diff }) ->
      Format.printf "differs from %s: %a@.actual: %s@.diff: %s@." golden Compare.pp
        figures actual diff;
      false
