let user = Job_error.user

let runs ks =
  let rec go acc = function
    | [] -> List.rev acc
    | k :: rest -> (
        match acc with
        | (a, b) :: acc' when k = b + 1 -> go ((a, k) :: acc') rest
        | _ -> go ((k, k) :: acc) rest)
  in
  String.concat ", "
    (List.map
       (fun (a, b) -> if a = b then string_of_int a else Printf.sprintf "%d..%d" a b)
       (go [] ks))

let frames prog spec =
  let fps, count =
    match Program.animation prog with Some (fps, n) -> (fps, n) | None -> (24., 1)
  in
  let first, last =
    if String.equal spec "all" then (0, count - 1)
    else
      match Plan.frames_of_string spec with
      | Ok r -> r
      | Error _ -> user "--frames expects all, A..B or K (got %S)" spec
  in
  if first < 0 || first > last then
    user "--frames %s: the first frame must be at least 0 and at most the last" spec;
  if last >= count then
    if Program.animation prog = None then
      user "--frames %s: the scene is a still (frame 0 only)" spec
    else user "--frames %s: the animation has frames 0..%d" spec (count - 1);
  (fps, first, last)

(* One scene: its summary and estimates, or its JSON. *)
let one prog o ~json =
  let time, frame = Options.time_of o (Scene_file.source o prog) in
  (* Check reads the scene's objects, features and estimates, and traces no ray: no
     acceleration structure. Its summary needs one scene and not the description's
     objects, which may go as they are compiled (the program is loaded for one scene);
     the JSON lists them. *)
  match Program.scene ~index:false prog ~time ~frame with
  | Error errors -> raise (Job_error.Scene { errors; note = "" })
  | Ok sc ->
      let sc = Overrides.apply (Options.overrides o) sc in
      if json then print_endline (Yojson.Safe.pretty_to_string (Program.to_json prog sc))
      else (
        print_string (Program.summary prog sc);
        print_string (Render_report.cost_report sc))

(* Every frame is evaluated; the errors of the first that fails are shown, and the
   others that fail are listed. *)
let every prog (o : Options.t) spec =
  let fps, first, last = frames prog spec in
  let first_scene = ref None and failed = ref [] and first_errors = ref [] in
  for k = first to last do
    match Program.scene ~index:false prog ~time:(Float.of_int k /. fps) ~frame:k with
    | Ok sc -> if Option.is_none !first_scene then first_scene := Some sc
    | Error errs ->
        if !failed = [] then first_errors := errs;
        failed := k :: !failed
  done;
  let n = last - first + 1 in
  (match List.rev !failed with
  | [] -> ()
  | ks ->
      raise
        (Job_error.Scene
           {
             errors = !first_errors;
             note =
               Printf.sprintf "%d of the %d frames checked (%d..%d) fail: %s"
                 (List.length ks) n first last (runs ks);
           }));
  (match !first_scene with
  | Some sc ->
      print_string (Program.summary prog (Overrides.apply (Options.overrides o) sc))
  | None -> ());
  Printf.printf "frames checked: %d..%d (%d frame%s), every one evaluates\n" first last n
    (if n = 1 then "" else "s")

let run ?width ?height ~scene ~json ~time ~frames () =
  let o = { Options.default with scene = Some scene; time; width; height } in
  let prog =
    Scene_file.load ~single:(frames = None && (not json) && Options.at_start o) o.scene
  in
  match frames with
  | None -> one prog o ~json
  | Some _ when time <> None -> user "give either --time or --frames, not both"
  | Some _ when json ->
      user "--json prints one frame: choose it with --time, not --frames"
  | Some spec -> every prog o spec
