(* lancer bench quality: each quality knob's time, rays and error against a reference,
   cached. *)

open Lancer

let cache_dir () =
  let base =
    match Sys.getenv_opt "XDG_CACHE_HOME" with
    | Some d when d <> "" -> d
    | _ ->
        Filename.concat
          (Option.value (Sys.getenv_opt "HOME") ~default:Filename.current_dir_name)
          ".cache"
  in
  Filename.concat base "lancer"

let rec mkdir_p d =
  if not (Sys.file_exists d) then (
    mkdir_p (Filename.dirname d);
    try Unix.mkdir d 0o755 with Unix.Unix_error (Unix.EEXIST, _, _) -> ())

let scene_text (o : Options.t) = snd (Scene_file.read o.scene)

(* The version of the lancer command (as [lancer --version] prints it). *)
let version = Lancer.Version.v

(* What the cached results depend on besides the scene: the version and the very build
   of this executable (a rebuilt renderer may shade, and time, differently). Rates also
   depend on the machine, hence its name. *)
let build_id =
  lazy
    (let exe =
       try Digest.to_hex (Digest.file Sys.executable_name) with _ -> "unknown"
     in
     let host = try Unix.gethostname () with _ -> "unknown" in
     Printf.sprintf "lancer %s|build %s|host %s|OCaml %s" version exe host
       Sys.ocaml_version)

let cache_key parts =
  Digest.to_hex (Digest.string (String.concat "\x00" (Lazy.force build_id :: parts)))

(* The reference: the reference preset at 16×16 samples and depth 64, cached under the
   scene text, the size and the build. *)
let reference_scene (o : Options.t) prog =
  let base =
    Options.scene_at { o with quality = Some Quality.Reference } prog ~time:0. ~frame:0
  in
  match Scene.map_settings base (fun s -> { s with samples = 16; depth = 64 }) with
  | Ok sc -> sc
  | Error m -> raise (Job_error.User m)

let reference_path (o : Options.t) (sc : Scene.t) =
  let s = sc.settings in
  let key =
    cache_key
      [ "reference v2"; scene_text o; string_of_int s.width; string_of_int s.height ]
  in
  Filename.concat (cache_dir ()) ("reference-" ^ key ^ ".ppm")

let cached_reference path ~fresh =
  if fresh then None else Result.to_option (Image.read_rgb8 path)

let render_reference ?on_tile ~pool path (sc : Scene.t) =
  let fb, _ = Render.render ?pool ?on_tile sc in
  let bytes = Image.to_bytes sc.settings.gamma fb in
  (try mkdir_p (cache_dir ()) with _ -> ());
  ignore (Image.write_rgb8 path fb.width fb.height bytes);
  (fb.width, fb.height, bytes)

type row = {
  knob : string;
  value : string;
  seconds : float;
  rays : int;
  rmse : float;
  psnr : float;
  over_share : float;
}

let row_json r =
  `Assoc
    [
      ("knob", `String r.knob);
      ("value", `String r.value);
      ("seconds", `Float r.seconds);
      ("rays", `Int r.rays);
      ("rmse", `Float r.rmse);
      ("psnr", if Float.is_finite r.psnr then `Float r.psnr else `String "inf");
      ("share_over_1", `Float r.over_share);
    ]

let row_of_json j =
  let open Yojson.Safe.Util in
  {
    knob = j |> member "knob" |> to_string;
    value = j |> member "value" |> to_string;
    seconds = j |> member "seconds" |> to_number;
    rays = j |> member "rays" |> to_int;
    rmse = j |> member "rmse" |> to_number;
    psnr =
      (match j |> member "psnr" with `String "inf" -> Float.infinity | p -> to_number p);
    over_share = j |> member "share_over_1" |> to_number;
  }

(* Measured rows cached under the scene text, the options and the build. *)
let read_rows path =
  match Yojson.Safe.from_file path with
  | exception _ -> None
  | j -> (
      let open Yojson.Safe.Util in
      try
        Some
          ( j |> member "measured_at" |> to_number,
            List.map row_of_json (j |> member "rows" |> to_list) )
      with _ -> None)

let write_rows path ~measured_at rows =
  (try mkdir_p (Filename.dirname path) with _ -> ());
  let j =
    `Assoc
      [
        ("build", `String (Lazy.force build_id));
        ("measured_at", `Float measured_at);
        ("rows", `List (List.map row_json rows));
      ]
  in
  ignore
    (Image.write_atomic path (fun oc -> output_string oc (Yojson.Safe.pretty_to_string j)))

(* A row to measure: its knob and value, the scene whose settings, lights and camera
   estimate its cost, and the scene it renders (made when it is its turn: an open
   shutter's instants are scenes of their own). *)
type spec = {
  s_knob : string;
  s_value : string;
  estimated : Scene.t;
  make : unit -> Scene.t;
}

let row_specs (o : Options.t) prog ~size:(w, h) =
  let o = { o with quality = None; width = Some w; height = Some h } in
  let base = Options.scene_at o prog ~time:0. ~frame:0 in
  let ok = function Ok sc -> sc | Error m -> raise (Job_error.User m) in
  let spec knob value sc =
    { s_knob = knob; s_value = value; estimated = sc; make = (fun () -> sc) }
  in
  (* A change of settings reaches the scenes at an open shutter's instants too. *)
  let with_s f = ok (Scene.map_settings base f) in
  List.map
    (fun n ->
      spec "samples" (Printf.sprintf "%d×%d" n n)
        (with_s (fun s -> { s with samples = n; adaptive = 0. })))
    [ 1; 2; 3; 4; 6 ]
  @ List.map
      (fun th ->
        spec "adaptive" (Printf.sprintf "%g" th)
          (with_s (fun s -> { s with samples = 4; adaptive = th })))
      [ 0.2; 0.1; 0.05; 0.02 ]
  @ List.map
      (fun d -> spec "depth" (string_of_int d) (with_s (fun s -> { s with depth = d })))
      [ 1; 2; 3; 5; 8; 16; 64 ]
  @ (if base.features.soft_shadows then
       List.map
         (fun n ->
           spec "light samples" (Printf.sprintf "%d×%d" n n)
             (Scene.map_lights
                (with_s (fun s -> s))
                (function
                  | Light.Point p when p.radius > 0. -> Light.Point { p with samples = n }
                  | l -> l)))
         [ 1; 2; 4; 8 ]
     else [])
  @ (if base.features.depth_of_field then
       List.map
         (fun n ->
           spec "lens samples" (Printf.sprintf "%d×%d" n n)
             (ok (Scene.map_camera base (fun c -> Camera.with_lens_samples c n))))
         [ 1; 2; 4; 8 ]
     else [])
  @ (if Camera.motion_blur base.camera then
       (* The scenes at n instants, each pixel's 4×4 samples spread over them. *)
       List.map
         (fun n ->
           let sc =
             ok (Scene.with_camera base (Camera.with_shutter_samples base.camera n))
           in
           let four s =
             ok (Scene.map_settings s (fun s -> { s with samples = 4; adaptive = 0. }))
           in
           {
             s_knob = "shutter samples";
             s_value = string_of_int n;
             estimated = four sc;
             make =
               (fun () ->
                 four
                   (fst
                      (Scenes.with_instants prog (Options.overrides o) sc ~time:0.
                         ~frame:0)));
           })
         [ 1; 2; 4; 8; 16 ]
     else [])
  @ List.map
      (fun (name, q) ->
        (* A preset's shutter samples make its instants: the scene is made again. *)
        let preset = ok (Quality.apply q base) in
        if Camera.motion_blur base.camera then
          {
            s_knob = "preset";
            s_value = name;
            estimated = preset;
            make =
              (fun () ->
                Options.scene_at { o with quality = Some q } prog ~time:0. ~frame:0);
          }
        else spec "preset" name preset)
      Quality.all

let measure ?on_tile ~pool ~ref_img spec =
  let sc = spec.make () in
  let t, fb, st = Timing.render ?pool ?on_tile sc in
  let img =
    (fb.Framebuffer.width, fb.height, Image.to_bytes sc.Scene.settings.gamma fb)
  in
  match Compare.compare ~threshold:1 ref_img img with
  | Ok cmp ->
      {
        knob = spec.s_knob;
        value = spec.s_value;
        seconds = t;
        rays = Counters.total_rays st;
        rmse = cmp.rmse;
        psnr = cmp.psnr;
        over_share = cmp.over_share;
      }
  | Error m -> raise (Job_error.User m)

(* ---- What a run will render, and how long it may take ---- *)

let estimated_rays (sc : Scene.t) = (Cost.estimate sc).direct

(* The rays of a calibration render: the reference at one pixel in k×k, at most about two
   million of check's estimated rays (and a sixteenth of the reference), timed to turn
   estimated rays into seconds. *)
let calibration_stride (sc : Scene.t) =
  max 4 (int_of_float (Float.ceil (Float.sqrt (estimated_rays sc /. 2e6))))

let seconds_per_estimated_ray ~pool (sc : Scene.t) =
  let k = calibration_stride sc in
  let t0 = Unix.gettimeofday () in
  let fb, _ = Render.render ?pool ~stride:k sc in
  let secs = Unix.gettimeofday () -. t0 in
  let share =
    Float.of_int (fb.width * fb.height)
    /. Float.of_int (sc.settings.width * sc.settings.height)
  in
  (secs /. Float.max 1. (estimated_rays sc *. share), k)

(* The knobs and their values, in a line: "samples 1×1 to 6×6, depth 1 to 64". *)
let knobs_text specs =
  let knobs =
    List.fold_left
      (fun acc s -> if List.mem s.s_knob acc then acc else s.s_knob :: acc)
      [] specs
  in
  String.concat ", "
    (List.rev_map
       (fun k ->
         match List.filter (fun s -> s.s_knob = k) specs with
         | [ s ] -> Printf.sprintf "%s %s" k s.s_value
         | s :: rest ->
             Printf.sprintf "%s %s to %s" k s.s_value
               (List.nth rest (List.length rest - 1)).s_value
         | [] -> k)
       knobs)

let plan_text ~scene ~size:(w, h) ~domains ~reference ~specs ~rays ~seconds ~stride =
  Printf.sprintf
    "bench quality: %d renders of %s at %d×%d on %d domain%s: %s%s; about %s rays \
     (lancer check's estimate), roughly %s (timed on one pixel in %d×%d of the \
     reference)"
    (List.length specs + if reference then 1 else 0)
    scene w h domains
    (if domains = 1 then "" else "s")
    (if reference then "the reference (16×16 samples, depth 64), then " else "")
    (knobs_text specs)
    (Render_report.rays_text rays)
    (Progress.hms seconds) stride stride

let run (o : Options.t) ~json ~svg ~fresh =
  let prog = Scene_file.source o (Scene_file.load o.scene) in
  let domains = Options.domains o in
  let s =
    (Options.scene_at { o with quality = Some Quality.Reference } prog ~time:0. ~frame:0)
      .settings
  in
  let w = s.width and h = s.height in
  let opt = function Some n -> string_of_int n | None -> "-" in
  let rows_path =
    Filename.concat (cache_dir ())
      ("quality-"
      ^ cache_key
          [
            "quality rows v1";
            scene_text o;
            string_of_int w;
            string_of_int h;
            opt o.samples;
            opt o.depth;
            string_of_int domains;
          ]
      ^ ".json")
  in
  let cached_rows = if fresh then None else read_rows rows_path in
  let rows, measured_at, cached, ref_cached =
    match cached_rows with
    | Some (at, rows) -> (rows, at, true, None)
    | None ->
        Render.with_pool domains @@ fun pool ->
        let ref_sc = reference_scene o prog in
        let ref_path = reference_path o ref_sc in
        let cached_ref = cached_reference ref_path ~fresh in
        let specs = row_specs o prog ~size:(w, h) in
        (* Before it starts: what it renders, and roughly how long that takes. *)
        let works =
          (match cached_ref with None -> [ estimated_rays ref_sc ] | Some _ -> [])
          @ List.map (fun s -> estimated_rays s.estimated) specs
        in
        let all = List.fold_left ( +. ) 0. works in
        let per_ray, stride = seconds_per_estimated_ray ~pool ref_sc in
        prerr_endline
          (plan_text
             ~scene:(Option.value o.scene ~default:"the showcase")
             ~size:(w, h) ~domains ~reference:(cached_ref = None) ~specs ~rays:all
             ~seconds:(per_ray *. all) ~stride);
        (* One progress report over every render, each weighed by its estimate. *)
        let bar = Progress.for_options o ~label:"renders" ~total:(List.length works) in
        let before = ref 0. and finished = ref 0 in
        let weigh w = if all > 0. then w /. all else 0. in
        let on_tile work done_ total rays =
          Progress.update ~rays
            ~share:
              (weigh
                 (!before +. (work *. Float.of_int done_ /. Float.of_int (max 1 total))))
            bar !finished
        in
        let step work =
          before := !before +. work;
          incr finished;
          Progress.update ~share:(weigh !before) bar !finished
        in
        let ref_img, ref_cached =
          match cached_ref with
          | Some img -> (img, true)
          | None ->
              let work = estimated_rays ref_sc in
              let img = render_reference ~on_tile:(on_tile work) ~pool ref_path ref_sc in
              step work;
              (img, false)
        in
        let rows =
          List.map
            (fun spec ->
              let work = estimated_rays spec.estimated in
              let r = measure ~on_tile:(on_tile work) ~pool ~ref_img spec in
              step work;
              r)
            specs
        in
        Progress.finish bar;
        if not json then
          Printf.eprintf "reference render %s\n%!"
            (if ref_cached then "read from the cache" else "rendered and cached");
        let at = Unix.time () in
        write_rows rows_path ~measured_at:at rows;
        (rows, at, false, Some ref_cached)
  in
  let date =
    let t = Unix.localtime measured_at in
    Printf.sprintf "%04d-%02d-%02d %02d:%02d" (t.tm_year + 1900) (t.tm_mon + 1) t.tm_mday
      t.tm_hour t.tm_min
  in
  if json then
    print_endline
      (Yojson.Safe.pretty_to_string
         (`Assoc
            [
              ("scene", `String (Option.value o.scene ~default:"(showcase)"));
              ("width", `Int w);
              ("height", `Int h);
              ("domains", `Int domains);
              ("cached", `Bool cached);
              ( "reference_cached",
                match ref_cached with Some b -> `Bool b | None -> `Null );
              ("measured_at", `Float measured_at);
              ("cache_file", `String rows_path);
              ("rows", `List (List.map row_json rows));
            ]))
  else (
    Printf.printf
      "scene %s at %d×%d on %d domains; error against a 16×16-sample, depth-64 \
       reference; %s\n\n"
      (Option.value o.scene ~default:"(showcase)")
      w h domains
      (if cached then
         Printf.sprintf "rows measured %s, read from the cache (--fresh to measure again)"
           date
       else Printf.sprintf "rows measured now (%s) and cached" date);
    Printf.printf
      "| knob | value | wall time (s) | M rays | RMSE (0–255) | PSNR dB | pixels off > \
       1/255 |\n\
       |---|---|---:|---:|---:|---:|---:|\n";
    List.iter
      (fun r ->
        Printf.printf "| %s | %s | %.3f | %.2f | %.3f | %s | %.2f%% |\n" r.knob r.value
          r.seconds
          (Float.of_int r.rays /. 1e6)
          r.rmse
          (if Float.is_finite r.psnr then Printf.sprintf "%.2f" r.psnr else "∞")
          (100. *. r.over_share))
      rows);
  let title =
    Printf.sprintf "%s at %d×%d, %d domains"
      (Option.value o.scene ~default:"showcase")
      w h domains
  in
  Option.iter
    (fun path ->
      Svg.write ~title path
        (List.map (fun r -> (r.knob, r.value, r.seconds, r.psnr)) rows))
    svg
