open Lancer

let median xs =
  let a = Array.of_list xs in
  Array.sort Float.compare a;
  let n = Array.length a in
  if n = 0 then Float.nan
  else if n mod 2 = 1 then a.(n / 2)
  else 0.5 *. (a.((n / 2) - 1) +. a.(n / 2))

let time_render ?pool sc =
  let t0 = Unix.gettimeofday () in
  let fb, st = Render.render ?pool sc in
  (Unix.gettimeofday () -. t0, fb, st)

let domains_cmd (o : Options.t) counts repeat json =
  let prog = Scene_file.source o (Scene_file.load o.scene) in
  let time, frame = Options.time_of o prog in
  let sc = Options.scene_at o prog ~time ~frame in
  let cores = Domain.recommended_domain_count () in
  let rows =
    List.map
      (fun n ->
        if n < 1 then raise (Job_error.User "domain counts must be at least 1");
        Render.with_pool n (fun pool ->
            ignore (time_render ?pool sc) (* warm-up: pool start, caches *);
            let w0 = Gc.minor_words () in
            let runs =
              List.init (max 1 repeat) (fun _ ->
                  let t, _, st = time_render ?pool sc in
                  (t, st))
            in
            let words = Gc.minor_words () -. w0 in
            let st = snd (List.hd runs) in
            let rays = Stats.total_rays st in
            (* Gc.minor_words counts this domain's allocations only: meaningful on one domain,
               where the render runs on this one. *)
            let wpr =
              if n = 1 then words /. Float.of_int (max 1 (rays * List.length runs))
              else Float.nan
            in
            (n, median (List.map fst runs), rays, wpr)))
      counts
  in
  let base =
    match List.find_opt (fun (n, _, _, _) -> n = 1) rows with
    | Some (_, t, _, _) -> t
    | None -> Float.nan
  in
  let s = sc.settings in
  if json then
    print_endline
      (Yojson.Safe.pretty_to_string
         (`Assoc
            [
              ("scene", `String (Option.value o.scene ~default:"(showcase)"));
              ("width", `Int s.width);
              ("height", `Int s.height);
              ("cores", `Int cores);
              ("repeat", `Int repeat);
              ( "runs",
                `List
                  (List.map
                     (fun (n, t, rays, wpr) ->
                       `Assoc
                         [
                           ("domains", `Int n);
                           ("seconds", `Float t);
                           ("rays", `Int rays);
                           ("rays_per_second", `Float (Float.of_int rays /. t));
                           ("speedup", `Float (base /. t));
                           ( "minor_words_per_ray",
                             if Float.is_nan wpr then `Null else `Float wpr );
                         ])
                     rows) );
            ]))
  else (
    Printf.printf
      "scene %s, %d×%d, %d samples, depth %d; %d cores recommended; median of %d runs\n\n"
      (Option.value o.scene ~default:"(showcase)")
      s.width s.height s.samples s.depth cores repeat;
    Printf.printf
      "| domains | seconds | M rays/s | speed-up | efficiency | minor words/ray |\n\
       |---:|---:|---:|---:|---:|---:|\n";
    List.iter
      (fun (n, t, rays, wpr) ->
        Printf.printf "| %d | %.3f | %.2f | %.2f× | %.0f%% | %s |\n" n t
          (Float.of_int rays /. t /. 1e6)
          (base /. t)
          (100. *. base /. t /. Float.of_int n)
          (if Float.is_nan wpr then "—" else Printf.sprintf "%.1f" wpr))
      rows)

(* ---- quality ---- *)

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

(* The reference: the reference preset at 16×16 samples, depth 64, cached under the scene
   text, the size and the build. *)
let reference (o : Options.t) prog ~pool ~fresh =
  let base =
    Options.scene_at { o with quality = Some Quality.Reference } prog ~time:0. ~frame:0
  in
  let s = base.settings in
  let key =
    cache_key
      [ "reference v2"; scene_text o; string_of_int s.width; string_of_int s.height ]
  in
  let path = Filename.concat (cache_dir ()) ("reference-" ^ key ^ ".ppm") in
  match if fresh then Error "fresh" else Image.read_rgb8 path with
  | Ok img -> (img, true)
  | Error _ ->
      let sc =
        match Scene.with_settings base { s with samples = 16; depth = 64 } with
        | Ok sc -> sc
        | Error m -> raise (Job_error.User m)
      in
      let fb, _ = Render.render ?pool sc in
      let bytes = Image.to_bytes sc.settings.gamma fb in
      (try mkdir_p (cache_dir ()) with _ -> ());
      ignore (Image.write_rgb8 path fb.width fb.height bytes);
      ((fb.width, fb.height, bytes), false)

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

let measure_rows (o : Options.t) prog ~pool ~ref_img:((w, h, _) as ref_img) =
  let base =
    Options.scene_at
      { o with quality = None; width = Some w; height = Some h }
      prog ~time:0. ~frame:0
  in
  let run knob value sc =
    let t, fb, st = time_render ?pool sc in
    let img = (fb.Image.width, fb.height, Image.to_bytes sc.Scene.settings.gamma fb) in
    match Compare.compare ~threshold:1 ref_img img with
    | Ok cmp ->
        {
          knob;
          value;
          seconds = t;
          rays = Stats.total_rays st;
          rmse = cmp.rmse;
          psnr = cmp.psnr;
          over_share = cmp.over_share;
        }
    | Error m -> raise (Job_error.User m)
  in
  let with_s f =
    match Scene.with_settings base (f base.settings) with
    | Ok sc -> sc
    | Error m -> raise (Job_error.User m)
  in
  List.map
    (fun n ->
      run "samples" (Printf.sprintf "%d×%d" n n)
        (with_s (fun s -> { s with samples = n; adaptive = 0. })))
    [ 1; 2; 3; 4; 6 ]
  @ List.map
      (fun th ->
        run "adaptive" (Printf.sprintf "%g" th)
          (with_s (fun s -> { s with samples = 4; adaptive = th })))
      [ 0.2; 0.1; 0.05; 0.02 ]
  @ List.map
      (fun d -> run "depth" (string_of_int d) (with_s (fun s -> { s with depth = d })))
      [ 1; 2; 3; 5; 8; 16; 64 ]
  @ (if base.features.soft_shadows then
       List.map
         (fun n ->
           run "light samples" (Printf.sprintf "%d×%d" n n)
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
           run "lens samples" (Printf.sprintf "%d×%d" n n)
             (match
                Scene.with_camera
                  (with_s (fun s -> s))
                  (Camera.with_lens_samples base.camera n)
              with
             | Ok sc -> sc
             | Error m -> raise (Job_error.User m)))
         [ 1; 2; 4; 8 ]
     else [])
  @ List.map
      (fun (name, q) ->
        run "preset" name
          (match Quality.apply q base with
          | Ok sc -> sc
          | Error m -> raise (Job_error.User m)))
      Quality.all

let quality_cmd (o : Options.t) json svg fresh =
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
        let ref_img, ref_cached = reference o prog ~pool ~fresh in
        if not json then
          Printf.eprintf "reference render %s\n%!"
            (if ref_cached then "read from the cache" else "rendered and cached");
        let rows = measure_rows o prog ~pool ~ref_img in
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

(* ---- physics ---- *)

(* The drop of doc/numerics.md, in closed form (Drop), independently of the engine it
   checks. *)
let drop_height = Drop.height
let drop_radius = Drop.radius
let drop_g = Drop.g
let drop_v1 = Drop.impact_speed
let impact_time = Drop.impact_time
let drop_gap = Drop.gap

let method_name = function
  | Physics.Exact -> "exact"
  | Physics.Verlet -> "verlet"
  | Physics.Euler -> "euler"

(* Seconds per call of [f]: batches grown until one lasts [min_batch] s, median of 5. *)
let per_call ?(min_batch = 0.02) f =
  let batch n =
    let t0 = Unix.gettimeofday () in
    for _ = 1 to n do
      ignore (Sys.opaque_identity (f ()))
    done;
    Unix.gettimeofday () -. t0
  in
  let rec calibrate n =
    let t = batch n in
    if t >= min_batch || n >= 1 lsl 20 then n else calibrate (2 * n)
  in
  let n = calibrate 1 in
  median (List.init 5 (fun _ -> batch n /. Float.of_int n))

type phys_row = {
  e : float;
  meth : Physics.method_;
  step : float option;
  steps : int option;
  events : int;
  sim_seconds : float;
  max_pos_err : float;
  compared : int; (* impacts compared with the closed form *)
  through : bool; (* the centre went below the floor: an impact was missed *)
  max_impact_err : float option;
  max_apex_err : float option;
  first_apex : float option;
}

let physics_row ~until ~sample_rate ~e meth step =
  let world =
    {
      Physics.gravity = Vec3.v 0. (-.drop_g) 0.;
      method_ = meth;
      step = Option.value step ~default:(1. /. 240.);
    }
  in
  let floor = [ Physics.Plane { normal = Vec3.y_axis; offset = 0. } ] in
  let ball =
    Physics.body ~restitution:e ~name:"ball"
      ~center:(Vec3.v 0. (drop_radius +. drop_height) 0.)
      ~radius:drop_radius ()
  in
  let sim () = Physics.simulate world floor [ ball ] ~until in
  let seconds = per_call sim in
  let tr = sim () in
  let pos t =
    match Physics.sample tr "ball" t with Some (p, _) -> p | None -> assert false
  in
  let expected t = Vec3.v 0. (drop_radius +. drop_gap e t) 0. in
  let nframes = int_of_float (Float.round (until *. sample_rate)) in
  let max_pos_err = ref 0. in
  for i = 0 to nframes do
    let t = Float.of_int i /. sample_rate in
    max_pos_err := Float.max !max_pos_err (Vec3.length (Vec3.sub (pos t) (expected t)))
  done;
  let bounces =
    List.filter (fun (ev : Physics.event) -> ev.kind = Physics.Bounce) (Physics.events tr)
  in
  let btimes = Array.of_list (List.map (fun (ev : Physics.event) -> ev.time) bounces) in
  (* Impacts worth comparing: all those within the horizon for e = 1; for e < 1 the first
     five (apex ≥ 0.168 m: later ones sink under a fixed step's g·dt² jitter). *)
  let wanted =
    let rec count k =
      if k < 10_000 && impact_time e (k + 1) <= until then count (k + 1) else k
    in
    let n = count 0 in
    if e < 1. then min n 5 else n
  in
  let compared = min wanted (Array.length btimes) in
  (* The apex of the sampled trajectory between two of the engine's impacts. *)
  let apex a b =
    let y t = (pos t).Vec3.y in
    let rec go a b i =
      if i = 0 then y (0.5 *. (a +. b))
      else
        let m1 = a +. ((b -. a) /. 3.) and m2 = b -. ((b -. a) /. 3.) in
        if y m1 < y m2 then go m1 b (i - 1) else go a m2 (i - 1)
    in
    go a b 200 -. drop_radius
  in
  (* The apex after each compared impact whose ideal apex falls within the horizon; the
     last flight is searched up to the horizon (after a missed impact it never ends). *)
  let apexes =
    List.filter_map
      (fun i ->
        let k = i + 1 in
        if impact_time e k +. ((e ** Float.of_int k) *. drop_v1 /. drop_g) > until then
          None
        else
          Some
            ( k,
              apex btimes.(i)
                (if i + 1 < Array.length btimes then btimes.(i + 1) else until) ))
      (List.init compared Fun.id)
  in
  let through = ref false in
  for i = 0 to nframes do
    if (pos (Float.of_int i /. sample_rate)).Vec3.y < 0. then through := true
  done;
  let maxf = List.fold_left Float.max 0. in
  {
    e;
    meth;
    step;
    steps = Option.map (fun dt -> int_of_float (Float.ceil ((until /. dt) -. 1e-9))) step;
    events = List.length (Physics.events tr);
    sim_seconds = seconds;
    max_pos_err = !max_pos_err;
    compared;
    through = !through;
    max_impact_err =
      (if compared = 0 then None
       else
         Some
           (maxf
              (List.init compared (fun i ->
                   Float.abs (btimes.(i) -. impact_time e (i + 1))))));
    max_apex_err =
      (if apexes = [] then None
       else
         Some
           (maxf (List.map (fun (k, a) -> Float.abs (a -. Drop.apex_height e k)) apexes)));
    first_apex = (match apexes with (_, a) :: _ -> Some a | [] -> None);
  }

let physics_cmd rates until sample_rate json =
  if List.exists (fun r -> not (r > 0.)) rates then
    raise (Job_error.User "step rates must be positive");
  if not (until > 0.) then raise (Job_error.User "--until must be positive");
  if not (sample_rate > 0.) then raise (Job_error.User "--sample-rate must be positive");
  let configs =
    (Physics.Exact, None)
    :: List.concat_map
         (fun m -> List.map (fun r -> (m, Some (1. /. r))) rates)
         [ Physics.Verlet; Physics.Euler ]
  in
  let rows =
    List.concat_map
      (fun e -> List.map (fun (m, st) -> physics_row ~until ~sample_rate ~e m st) configs)
      [ 1.; 0.8 ]
  in
  let opt_f = function Some x -> `Float x | None -> `Null
  and opt_i = function Some x -> `Int x | None -> `Null in
  if json then
    print_endline
      (Yojson.Safe.pretty_to_string
         (`Assoc
            [
              ("drop_height", `Float drop_height);
              ("radius", `Float drop_radius);
              ("gravity", `Float drop_g);
              ("until", `Float until);
              ("sample_rate", `Float sample_rate);
              ("rest_fraction", `Float Physics.rest_fraction);
              ( "rows",
                `List
                  (List.map
                     (fun r ->
                       `Assoc
                         [
                           ("restitution", `Float r.e);
                           ("method", `String (method_name r.meth));
                           ("step", opt_f r.step);
                           ("steps", opt_i r.steps);
                           ("events", `Int r.events);
                           ("seconds", `Float r.sim_seconds);
                           ("max_position_error", `Float r.max_pos_err);
                           ("impacts_compared", `Int r.compared);
                           ("fell_through_floor", `Bool r.through);
                           ("max_impact_time_error", opt_f r.max_impact_err);
                           ("max_apex_error", opt_f r.max_apex_err);
                           ("first_apex", opt_f r.first_apex);
                         ])
                     rows) );
            ]))
  else (
    Printf.printf
      "Ball (r = %g m) dropped from %g m onto a floor, g = %g m/s², %g s; error against \
       the closed form, positions sampled at %g Hz; impacts and apexes: all within the \
       horizon for e = 1, the first 5 for e < 1\n\n"
      drop_radius drop_height drop_g until sample_rate;
    print_endline
      "| e | method | step (s) | steps | events | wall time (µs) | max position error \
       (m) | fell through | impacts compared | max impact time error (s) | max apex \
       error (m) | first apex (m) |";
    print_endline "|---:|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|";
    let o f = function Some x -> f x | None -> "—" in
    List.iter
      (fun r ->
        Printf.printf
          "| %g | %s | %s | %s | %d | %.1f | %.3g | %s | %d | %s | %s | %s |\n" r.e
          (method_name r.meth)
          (o (fun s -> Printf.sprintf "1/%g" (Float.round (1. /. s))) r.step)
          (o string_of_int r.steps) r.events (r.sim_seconds *. 1e6) r.max_pos_err
          (if r.through then "yes" else "no")
          r.compared
          (o (Printf.sprintf "%.3g") r.max_impact_err)
          (o (Printf.sprintf "%.3g") r.max_apex_err)
          (o (Printf.sprintf "%.6f") r.first_apex))
      rows)

(* ---- scaling ---- *)

(* [n] random spheres from a fixed seed, uniformly in a cube of side n^(1/3) (so the
   density, and the number of spheres along a ray, stays about the same), radii in
   [0.1, 0.4], one point light with shadows, seen from outside the cube. *)
let sphere_field n =
  let st = Random.State.make [| 12345; n |] in
  let l = 0.5 *. Float.cbrt (Float.of_int n) in
  let m = Material.default in
  let prims =
    List.init n (fun _ ->
        let c =
          Vec3.v
            (Random.State.float st (2. *. l) -. l)
            (Random.State.float st (2. *. l) -. l)
            (Random.State.float st (2. *. l) -. l)
        in
        let color =
          Color.v (Random.State.float st 1.) (Random.State.float st 1.)
            (Random.State.float st 1.)
        in
        Primitive.make { m with color }
          (Shape.sphere ~center:c ~radius:(0.1 +. Random.State.float st 0.3)))
  in
  let camera =
    Camera.make
      ~position:(Vec3.v 0.3 (0.4 *. l) (-3.2 *. l))
      ~look_at:Vec3.zero ~fov:45. ()
  in
  let lights = [ Light.point (Vec3.v (2. *. l) (3. *. l) (-4. *. l)) ] in
  (prims, camera, lights)

type scale_row = {
  count : int;
  width : int;
  height : int;
  doms : int;
  build_s : float; (* the scene: primitives validated, BVH built *)
  bvh_s : float; (* the BVH alone *)
  render_s : float;
  rays : int;
  words_per_ray : float;
  peak_kib : int option;
}

let timed f =
  let t0 = Unix.gettimeofday () in
  let r = f () in
  (r, Unix.gettimeofday () -. t0)

(* One configuration measured in this process. *)
let scale_measure ~repeat ~count ~width ~height ~domains =
  let prims, camera, lights = sphere_field count in
  let settings = { Settings.default with width; height; depth = 1 } in
  let _, bvh_s = timed (fun () -> Accel.build (Array.of_list prims)) in
  let sc, build_s = timed (fun () -> Scene.make_exn ~settings ~camera ~lights prims) in
  Gc.compact ();
  let w0 = Gc.minor_words () in
  (* the median of [repeat] renders on one pool *)
  let runs =
    Render.with_pool domains (fun pool ->
        List.init (max 1 repeat) (fun _ -> timed (fun () -> Render.render ?pool sc)))
  in
  let words = (Gc.minor_words () -. w0) /. Float.of_int (List.length runs) in
  let render_s = median (List.map snd runs) in
  let rays = Stats.total_rays (snd (fst (List.hd runs))) in
  ignore (Sys.opaque_identity sc);
  {
    count;
    width;
    height;
    doms = domains;
    build_s;
    bvh_s;
    render_s;
    rays;
    (* Gc.minor_words counts this domain's allocations only *)
    words_per_ray =
      (if domains = 1 then words /. Float.of_int (max 1 rays) else Float.nan);
    peak_kib = Render_report.peak_memory_kib ();
  }

let scale_row_json r =
  `Assoc
    [
      ("spheres", `Int r.count);
      ("width", `Int r.width);
      ("height", `Int r.height);
      ("domains", `Int r.doms);
      ("scene_build_seconds", `Float r.build_s);
      ("bvh_build_seconds", `Float r.bvh_s);
      ("render_seconds", `Float r.render_s);
      ("rays", `Int r.rays);
      ("rays_per_second", `Float (Float.of_int r.rays /. r.render_s));
      ( "minor_words_per_ray",
        if Float.is_nan r.words_per_ray then `Null else `Float r.words_per_ray );
      ("peak_memory_kib", match r.peak_kib with Some k -> `Int k | None -> `Null);
    ]

let scale_row_of_json j =
  let open Yojson.Safe.Util in
  {
    count = j |> member "spheres" |> to_int;
    width = j |> member "width" |> to_int;
    height = j |> member "height" |> to_int;
    doms = j |> member "domains" |> to_int;
    build_s = j |> member "scene_build_seconds" |> to_number;
    bvh_s = j |> member "bvh_build_seconds" |> to_number;
    render_s = j |> member "render_seconds" |> to_number;
    rays = j |> member "rays" |> to_int;
    words_per_ray =
      Option.value
        (j |> member "minor_words_per_ray" |> to_number_option)
        ~default:Float.nan;
    peak_kib = j |> member "peak_memory_kib" |> to_int_option;
  }

(* One configuration measured in a child process of this executable, so that its peak
   resident memory (VmHWM, which only grows) is its own. *)
let scale_child ~repeat ~count ~width ~height ~domains =
  let exe = Sys.executable_name in
  let args =
    [|
      exe;
      "bench";
      "scaling";
      "--repeat";
      string_of_int repeat;
      "--row";
      Printf.sprintf "%d,%dx%d,%d" count width height domains;
    |]
  in
  let ic = Unix.open_process_args_in exe args in
  let out = In_channel.input_all ic in
  match Unix.close_process_in ic with
  | Unix.WEXITED 0 -> (
      try scale_row_of_json (Yojson.Safe.from_string out)
      with _ ->
        raise
          (Job_error.User
             ("bench scaling: unreadable row from the child process: " ^ String.trim out))
      )
  | Unix.WEXITED c | Unix.WSIGNALED c | Unix.WSTOPPED c ->
      raise
        (Job_error.User
           (Printf.sprintf
              "bench scaling: the child measuring %d spheres at %d×%d on %d domains \
               failed (status %d)"
              count width height domains c))

let parse_size s =
  match String.split_on_char 'x' (String.lowercase_ascii s) with
  | [ w; h ] -> (
      match (int_of_string_opt w, int_of_string_opt h) with
      | Some w, Some h when w > 0 && h > 0 -> Some (w, h)
      | _ -> None)
  | _ -> None

let parse_row s =
  match String.split_on_char ',' s with
  | [ c; size; d ] -> (
      match (int_of_string_opt c, parse_size size, int_of_string_opt d) with
      | Some c, Some (w, h), Some d when c > 0 && d > 0 -> Some (c, w, h, d)
      | _ -> None)
  | _ -> None

let default_domain_counts () =
  let cores = Domain.recommended_domain_count () in
  let rec pow k = if k >= cores then [] else k :: pow (2 * k) in
  pow 1 @ [ cores ]

let scaling_cmd ~repeat ~counts ~width ~height ~domains ~domain_counts ~sizes ~base_count
    ~sweeps ~in_process ~row ~json =
  match row with
  | Some s -> (
      match parse_row s with
      | Some (count, width, height, domains) ->
          print_endline
            (Yojson.Safe.to_string
               (scale_row_json (scale_measure ~repeat ~count ~width ~height ~domains)))
      | None -> raise (Job_error.User ("--row expects COUNT,WxH,DOMAINS, not " ^ s)))
  | None ->
      if List.exists (fun n -> n < 1) counts || base_count < 1 then
        raise (Job_error.User "sphere counts must be at least 1");
      if width < 1 || height < 1 then
        raise (Job_error.User "--width and --height must be at least 1");
      if domains < 1 || List.exists (fun n -> n < 1) domain_counts then
        raise (Job_error.User "domain counts must be at least 1");
      let sizes =
        List.map
          (fun s ->
            match parse_size s with
            | Some wh -> wh
            | None -> raise (Job_error.User ("not a size WxH: " ^ s)))
          sizes
      in
      List.iter
        (fun s ->
          if not (List.mem s [ "counts"; "domains"; "sizes" ]) then
            raise (Job_error.User ("unknown sweep " ^ s ^ " (counts, domains or sizes)")))
        sweeps;
      let domain_counts =
        if domain_counts = [] then default_domain_counts () else domain_counts
      in
      if repeat < 1 then raise (Job_error.User "--repeat must be at least 1");
      let measure = if in_process then scale_measure ~repeat else scale_child ~repeat in
      let memory_scope =
        if in_process then "process (running maximum over the rows so far)"
        else "configuration (one child process each)"
      in
      if not json then
        Printf.printf
          "Random spheres (1 sample, shadows, depth 1), OCaml %s, %d cores recommended; \
           peak memory per %s\n\
           %!"
          Sys.ocaml_version
          (Domain.recommended_domain_count ())
          memory_scope;
      (* Each sweep's rows, printed as they are measured in Markdown. *)
      let sweep name title configs =
        if not (List.mem name sweeps) then []
        else (
          if not json then (
            Printf.printf "\n### %s\n\n" title;
            print_endline
              "| spheres | size | domains | scene build (s) | BVH build (s) | render (s) \
               | rays | M rays/s | minor words/ray | peak RSS (MiB) |";
            Printf.printf "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n%!");
          let rows =
            List.map
              (fun (count, (width, height), domains) ->
                let r = measure ~count ~width ~height ~domains in
                if not json then
                  Printf.printf
                    "| %d | %d×%d | %d | %.3f | %.3f | %.3f | %d | %.3f | %s | %s |\n%!"
                    r.count r.width r.height r.doms r.build_s r.bvh_s r.render_s r.rays
                    (Float.of_int r.rays /. r.render_s /. 1e6)
                    (if Float.is_nan r.words_per_ray then "—"
                     else Printf.sprintf "%.0f" r.words_per_ray)
                    (match r.peak_kib with
                    | Some k -> Printf.sprintf "%.0f" (Float.of_int k /. 1024.)
                    | None -> "—");
                r)
              configs
          in
          [ (name, rows) ])
      in
      (* in this order: the sweeps print as they go *)
      let by_count =
        sweep "counts"
          (Printf.sprintf "Object count (%d×%d, %d domain%s)" width height domains
             (if domains = 1 then "" else "s"))
          (List.map (fun n -> (n, (width, height), domains)) counts)
      in
      let by_domains =
        sweep "domains"
          (Printf.sprintf "Domains (%d spheres, %d×%d)" base_count width height)
          (List.map (fun d -> (base_count, (width, height), d)) domain_counts)
      in
      let by_size =
        sweep "sizes"
          (Printf.sprintf "Image size (%d spheres, 1 domain)" base_count)
          (List.map (fun wh -> (base_count, wh, 1)) sizes)
      in
      let results = by_count @ by_domains @ by_size in
      if json then
        print_endline
          (Yojson.Safe.pretty_to_string
             (`Assoc
                ([
                   ("scene", `String "random spheres, 1 sample, shadows, depth 1");
                   ("cores", `Int (Domain.recommended_domain_count ()));
                   ( "peak_memory_per",
                     `String (if in_process then "process" else "configuration") );
                 ]
                @ List.map
                    (fun (name, rows) -> (name, `List (List.map scale_row_json rows)))
                    results)))

(* ---- command line ---- *)

open Cmdliner

(* ---------------------------------------------------------------------------------- *)
(* An animation against one still of it, whole processes *)

(* Wall time of this executable run with [args], its output thrown away. *)
let child_time what args =
  let exe = Sys.executable_name in
  let null = Unix.openfile "/dev/null" [ Unix.O_WRONLY ] 0 in
  let t0 = Unix.gettimeofday () in
  let pid =
    Fun.protect
      ~finally:(fun () -> Unix.close null)
      (fun () ->
        Unix.create_process exe (Array.of_list (exe :: args)) Unix.stdin null null)
  in
  let _, st = Unix.waitpid [] pid in
  let dt = Unix.gettimeofday () -. t0 in
  match st with
  | Unix.WEXITED 0 -> dt
  | Unix.WEXITED c | Unix.WSIGNALED c | Unix.WSTOPPED c ->
      raise
        (Job_error.User
           (Printf.sprintf
              "bench animation: lancer %s failed (status %d): run it alone to see why"
              what c))

let rec remove_tree p =
  if Sys.file_exists p then
    if Sys.is_directory p then (
      Array.iter (fun f -> remove_tree (Filename.concat p f)) (Sys.readdir p);
      Sys.rmdir p)
    else Sys.remove p

let animation_cmd scene repeat domains json =
  if repeat < 1 then raise (Job_error.User "bench animation: --repeat must be at least 1");
  if not (Sys.file_exists scene) then
    raise (Job_error.User (Printf.sprintf "bench animation: no scene %s" scene));
  let dir =
    Filename.concat
      (Filename.get_temp_dir_name ())
      (Printf.sprintf "lancer-bench-animation-%d" (Unix.getpid ()))
  in
  Fun.protect
    ~finally:(fun () -> try remove_tree dir with Sys_error _ -> ())
    (fun () ->
      Unix.mkdir dir 0o700;
      let common =
        [ "-q" ]
        @ match domains with Some d -> [ "--domains"; string_of_int d ] | None -> []
      in
      let frames_dir = Filename.concat dir "frames" in
      let still = Filename.concat dir "still.png" in
      (* Alternated, so that a change in the machine's load falls on both. *)
      let runs =
        List.init repeat (fun _ ->
            remove_tree frames_dir;
            let a =
              child_time "animate" ([ "animate"; scene; "-o"; frames_dir ] @ common)
            in
            let s = child_time "render" ([ "render"; scene; "-o"; still ] @ common) in
            (a, s))
      in
      let frames =
        List.length
          (List.filter
             (fun f -> Filename.check_suffix f ".png")
             (Array.to_list (Sys.readdir frames_dir)))
      in
      let a = median (List.map fst runs) and s = median (List.map snd runs) in
      if json then
        print_endline
          (Yojson.Safe.to_string
             (`Assoc
                [
                  ("scene", `String scene);
                  ("frames", `Int frames);
                  ("animation_s", `Float a);
                  ("still_s", `Float s);
                  ("ratio", `Float (a /. s));
                ]))
      else (
        print_endline
          "| scene | frames | animation (s) | one still (s) | animation / still |";
        print_endline "|---|---:|---:|---:|---:|";
        Printf.printf "| %s | %d | %.2f | %.2f | %.1f |\n" scene frames a s (a /. s)))

let exits = Cli.exits

(* ---- language ---- *)

let language_loop = "for i in 0 to 3000000 { let x = sin(i) * cos(i) }\n"

let language_python =
  "import math\nfor i in range(3000001):\n    x = math.sin(i) * math.cos(i)\n"

(* The camera, light and size the grids below share, for n×n objects. *)
let grid_header n =
  Printf.sprintf
    "let n = %d\n\
     settings { width: 64, height: 48 }\n\
     camera { position: (0, 0.6 * n, -0.9 * n), look_at: (0, 0, 0), fov: 50 }\n\
     light { position: (-0.4 * n, 0.8 * n, -0.6 * n) }\n"
    n

let language_grid n =
  grid_header n
  ^ "for i in 0 to n - 1 { for j in 0 to n - 1 { sphere { center: (i - n / 2, 0.4, j - n \
     / 2), radius: 0.4 } } }\n"

(* The same grid, each sphere with its own material expression (the field of
   scenes/bench/field_100000.rts), and one of transformed boxes in groups. *)
let language_field n =
  grid_header n
  ^ "for i in 0 to n - 1 { for j in 0 to n - 1 { sphere { center: (i - n / 2, 0.4, j - n \
     / 2), radius: 0.4, material: material { color: (0.5 + 0.5 * sin(i), 0.5 + 0.5 * \
     cos(j), 0.6) } } } }\n"

let language_transformed n =
  grid_header n
  ^ "for i in 0 to n - 1 { group { translate: (i - n / 2, 0, 0), for j in 0 to n - 1 { \
     box { min: (-0.4, 0, -0.4), max: (0.4, 0.8, 0.4), rotate: (0, 3 * j, 0), translate: \
     (0, 0, j - n / 2), material: material { color: (0.9, 0.5, 0.2), specular: 0.5 } } } \
     } }\n"

(* One whole check of a program in this process (parse, static check, evaluation): its
   wall time, the words it allocated and the words its result holds. *)
let language_eval text =
  Gc.full_major ();
  let live0 = (Gc.stat ()).live_words in
  let w0 = Gc.minor_words () in
  let t0 = Unix.gettimeofday () in
  match Lancer_dsl.Dsl.load_string ~filename:"bench.rts" text with
  | Ok p ->
      let t = Unix.gettimeofday () -. t0 in
      let words = Gc.minor_words () -. w0 in
      Gc.full_major ();
      let live = (Gc.stat ()).live_words - live0 in
      ignore (Sys.opaque_identity p);
      (t, words, live)
  | Error es ->
      raise
        (Job_error.User
           ("the benchmark's program failed: "
           ^ String.concat "" (List.map Lancer_dsl.Error.to_string es)))

let on_path exe =
  let path = Option.value (Sys.getenv_opt "PATH") ~default:"" in
  List.find_map
    (fun d ->
      let f = Filename.concat (if d = "" then "." else d) exe in
      if Sys.file_exists f && not (Sys.is_directory f) then Some f else None)
    (String.split_on_char ':' path)

(* The wall time of a whole python3 process running [code]. *)
let python_time python code =
  let t0 = Unix.gettimeofday () in
  let pid =
    Unix.create_process python [| python; "-c"; code |] Unix.stdin Unix.stdout Unix.stderr
  in
  match snd (Unix.waitpid [] pid) with
  | Unix.WEXITED 0 -> Some (Unix.gettimeofday () -. t0)
  | _ -> None

let language_cmd repeat grid json =
  if repeat < 1 then raise (Job_error.User "--repeat must be at least 1");
  if grid < 1 then raise (Job_error.User "--grid must be at least 1");
  let python = on_path "python3" in
  let runs f = List.init repeat (fun _ -> f ()) in
  (* Alternated, so that a change in the machine's load falls on both. *)
  let loop, py =
    List.split
      (runs (fun () ->
           let t, _, _ = language_eval language_loop in
           (t, Option.bind python (fun p -> python_time p language_python))))
  in
  let loop_t = median loop in
  let py_t = match List.filter_map Fun.id py with [] -> None | ts -> Some (median ts) in
  let grid_runs = runs (fun () -> language_eval (language_grid grid)) in
  let grid_t = median (List.map (fun (t, _, _) -> t) grid_runs) in
  let objects = grid * grid in
  let per (_, words, live) =
    (words /. Float.of_int objects, Float.of_int live /. Float.of_int objects)
  in
  let words, live = per (List.hd grid_runs) in
  let other prog =
    let rs = runs (fun () -> language_eval (prog grid)) in
    let w, l = per (List.hd rs) in
    (median (List.map (fun (t, _, _) -> t) rs), w, l)
  in
  let field_t, field_words, field_live = other language_field in
  let tr_t, tr_words, tr_live = other language_transformed in
  if json then
    print_endline
      (Yojson.Safe.pretty_to_string
         (`Assoc
            [
              ("repeat", `Int repeat);
              ("loop_iterations", `Int 3_000_001);
              ("loop_seconds", `Float loop_t);
              ( "python3_loop_seconds",
                match py_t with Some t -> `Float t | None -> `Null );
              ( "ratio_to_python3",
                match py_t with Some t -> `Float (loop_t /. t) | None -> `Null );
              ("objects", `Int objects);
              ("objects_seconds", `Float grid_t);
              ("minor_words_per_object", `Float words);
              ("live_words_per_object", `Float live);
              ("material_objects_seconds", `Float field_t);
              ("material_minor_words_per_object", `Float field_words);
              ("material_live_words_per_object", `Float field_live);
              ("transformed_objects_seconds", `Float tr_t);
              ("transformed_minor_words_per_object", `Float tr_words);
              ("transformed_live_words_per_object", `Float tr_live);
            ]))
  else (
    Printf.printf
      "The scene language, a whole check in this process (parse, static check, \
       evaluation), median of %d run%s\n\n"
      repeat
      (if repeat = 1 then "" else "s");
    print_endline "| program | lancer (s) | python3 (s) | lancer / python3 |";
    print_endline "|---|---:|---:|---:|";
    (match py_t with
    | Some p ->
        Printf.printf
          "| `for i in 0 to 3000000 { let x = sin(i) * cos(i) }` | %.3f | %.3f | %.2f |\n"
          loop_t p (loop_t /. p)
    | None ->
        Printf.printf
          "| `for i in 0 to 3000000 { let x = sin(i) * cos(i) }` | %.3f | — | — |\n"
          loop_t);
    Printf.printf "| %s sphere blocks from two loops (%d × %d) | %.3f | — | — |\n"
      (if objects >= 1_000_000 && objects mod 1_000_000 = 0 then
         Printf.sprintf "%d million" (objects / 1_000_000)
       else string_of_int objects)
      grid grid grid_t;
    Printf.printf
      "| the same spheres, each with a material { color: … } of its own | %.3f | — | — |\n"
      field_t;
    Printf.printf
      "| as many rotated boxes with a material, in translated groups | %.3f | — | — |\n"
      tr_t;
    Printf.printf
      "\n\
       Per object, words allocated and words held by the description: %.0f and %.0f \
       (spheres), %.0f and %.0f (spheres with a material each), %.0f and %.0f (boxes in \
       groups).\n"
      words live field_words field_live tr_words tr_live;
    if python = None then
      print_endline
        "python3 is not on the PATH: the CPython row (the same loop with math.sin and \
         math.cos) was skipped."
    else if py_t = None then print_endline "python3 failed: the CPython row was skipped.")

let cmd =
  let doc = "measure speed and the speed/accuracy trade" in
  let json =
    Arg.(value & flag & info [ "json" ] ~doc:"Print JSON instead of a Markdown table.")
  in
  let domains =
    let counts =
      Arg.(
        value
        & opt (list int) [ 1; 2 ]
        & info [ "counts" ] ~docv:"N,N,..." ~doc:"Domain counts to time.")
    in
    let repeat =
      Arg.(
        value & opt int 3
        & info [ "repeat" ] ~docv:"R" ~doc:"Runs per count; the median is reported.")
    in
    let man =
      [
        `S Manpage.s_examples;
        `Pre "  lancer bench domains --width 1920 --height 1080 --counts 1,2,4,8,16";
      ]
    in
    Cmd.v
      (Cmd.info "domains"
         ~doc:
           "wall time and speed-up of one render over several domain counts, and on one \
            domain the minor words allocated per ray"
         ~man ~exits)
      Term.(
        const (fun o c r j -> Report.run (fun _ -> domains_cmd o c r j))
        $ Cli.(term Bench_domains)
        $ counts $ repeat $ json)
  in
  let quality =
    let svg =
      Arg.(
        value
        & opt (some string) None
        & info [ "svg" ] ~docv:"FILE" ~doc:"Also draw time against PSNR as an SVG chart.")
    in
    let fresh =
      Arg.(
        value & flag
        & info [ "fresh" ]
            ~doc:
              "Ignore the cache: render the reference and measure every row again (and \
               cache them anew).")
    in
    let man =
      [
        `S Manpage.s_description;
        `P
          "Renders the scene once per value of each quality knob and compares every \
           image with a reference render (the reference preset at 16×16 samples and \
           depth 64). The reference image and the measured rows are cached under \
           \\$XDG_CACHE_HOME/lancer (or ~/.cache/lancer), keyed by the scene text, the \
           size and options, the lancer build and the host, so a second run prints at \
           once; $(b,--fresh) measures again.";
        `S Manpage.s_examples;
        `Pre
          "  lancer bench quality scenes/showcase.rts --width 320 --height 240 --svg \
           trade.svg";
      ]
    in
    Cmd.v
      (Cmd.info "quality"
         ~doc:"time, rays and error against a reference for each quality knob" ~man ~exits)
      Term.(
        const (fun o j s f -> Report.run (fun _ -> quality_cmd o j s f))
        $ Cli.(term Bench_quality)
        $ json $ svg $ fresh)
  in
  let physics =
    let rates =
      Arg.(
        value
        & opt (list float) [ 30.; 240.; 1000. ]
        & info [ "rates" ] ~docv:"HZ,HZ,..."
            ~doc:"Steps per second of the fixed-step methods (the step is 1/HZ s).")
    in
    let until =
      Arg.(
        value & opt float 10.
        & info [ "until" ] ~docv:"S" ~doc:"Simulated time, in seconds.")
    in
    let sample_rate =
      Arg.(
        value & opt float 240.
        & info [ "sample-rate" ] ~docv:"HZ"
            ~doc:"Rate at which positions are compared with the closed form.")
    in
    let man =
      [
        `S Manpage.s_description;
        `P
          "Drops a ball (radius 0.1 m) from 1 m onto a floor under g = 9.81 m/s², with \
           restitution 1 and 0.8, and simulates it with the exact (event-driven) method \
           and with velocity Verlet and explicit Euler at each step. Each row gives the \
           cost (wall time of the simulation, median of repeated runs; fixed steps \
           taken; events) and the error against the closed-form motion: the largest \
           position error over frames, the largest error of the impact times and of the \
           apex heights (all impacts for e = 1, the first five for e = 0.8), and the \
           first apex, which is 1 m (e = 1) or 0.64 m (e = 0.8) exactly.";
        `P
          "For e = 0.8 the ideal ball bounces infinitely often before 4.0637 s; the \
           exact method rests the ball once a rebound would rise less than 1e-4 of its \
           radius, so its position error there is at most 1e-5 m.";
        `S Manpage.s_examples;
        `Pre "  lancer bench physics --rates 30,240,1000 --json";
      ]
    in
    Cmd.v
      (Cmd.info "physics"
         ~doc:
           "error and cost of the physics methods on a bouncing ball with a closed-form \
            answer"
         ~man ~exits)
      Term.(
        const (fun r u s j -> Report.run (fun _ -> physics_cmd r u s j))
        $ rates $ until $ sample_rate $ json)
  in
  let scaling =
    let counts =
      Arg.(
        value
        & opt (list int) [ 1000; 10_000; 100_000 ]
        & info [ "counts" ] ~docv:"N,N,..."
            ~doc:
              "Sphere counts of the object-count sweep (1000000 takes a few GiB and \
               minutes).")
    in
    let width =
      Arg.(
        value & opt int 320
        & info [ "width" ] ~docv:"W" ~doc:"Image width of the count and domain sweeps.")
    in
    let height =
      Arg.(
        value & opt int 240
        & info [ "height" ] ~docv:"H" ~doc:"Image height of the count and domain sweeps.")
    in
    let domains =
      Arg.(
        value & opt int 1
        & info [ "domains" ] ~docv:"D" ~doc:"Domains of the count sweep.")
    in
    let domain_counts =
      Arg.(
        value
        & opt (list int) []
        & info [ "domain-counts" ] ~docv:"N,N,..."
            ~doc:
              "Domain counts of the domain sweep (default 1, 2, 4, … up to the \
               recommended count for this machine).")
    in
    let sizes =
      Arg.(
        value
        & opt (list string) [ "160x120"; "320x240"; "640x480"; "1280x960" ]
        & info [ "sizes" ] ~docv:"WxH,..."
            ~doc:"Image sizes of the size sweep (one domain).")
    in
    let base_count =
      Arg.(
        value & opt int 10_000
        & info [ "base-count" ] ~docv:"N"
            ~doc:"Sphere count of the domain and size sweeps.")
    in
    let sweeps =
      Arg.(
        value
        & opt (list string) [ "counts"; "domains"; "sizes" ]
        & info [ "sweeps" ] ~docv:"NAME,..."
            ~doc:"Which sweeps to run: counts, domains, sizes.")
    in
    let in_process =
      Arg.(
        value & flag
        & info [ "in-process" ]
            ~doc:
              "Measure every configuration in this process instead of one child process \
               each (peak memory is then the running maximum, not the configuration's \
               own).")
    in
    let row =
      Arg.(
        value
        & opt (some string) None
        & info [ "row" ] ~docv:"COUNT,WxH,DOMAINS"
            ~doc:
              "Measure this one configuration in this process and print it as one line \
               of JSON (what the sweeps run in their child processes).")
    in
    let repeat =
      Arg.(
        value & opt int 3
        & info [ "repeat" ] ~docv:"R"
            ~doc:"Renders per configuration; the median time is reported.")
    in
    let man =
      [
        `S Manpage.s_description;
        `P
          "Renders N random spheres (fixed seed, uniform in a cube of side N^(1/3), one \
           point light with shadows, one sample, depth 1) and reports the scene build \
           and BVH build times, the render time (median of R renders), rays per second, \
           minor words allocated per ray and peak resident memory (VmHWM). Three sweeps: \
           the sphere count, the domain count and the image size. Each configuration \
           runs in a child process of this executable, so its peak memory is its own.";
        `S Manpage.s_examples;
        `Pre
          "  lancer bench scaling --counts 1000,10000,100000,1000000\n\
          \  lancer bench scaling --sweeps counts --counts 100,1000 --json";
      ]
    in
    Cmd.v
      (Cmd.info "scaling"
         ~doc:
           "build time, render time, rays/s and memory against object count, domains and \
            image size"
         ~man ~exits)
      Term.(
        const
          (fun
            counts
            width
            height
            domains
            domain_counts
            sizes
            base_count
            sweeps
            in_process
            row
            repeat
            json
          ->
            Report.run (fun _ ->
                scaling_cmd ~counts ~width ~height ~domains ~domain_counts ~sizes
                  ~base_count ~sweeps ~in_process ~row ~repeat ~json))
        $ counts $ width $ height $ domains $ domain_counts $ sizes $ base_count $ sweeps
        $ in_process $ row $ repeat $ json)
  in
  let animation =
    let scene =
      Arg.(
        value
        & pos 0 string "scenes/bench/field_moving.rts"
        & info [] ~docv:"SCENE" ~doc:"The animated scene (.rts) to time.")
    in
    let repeat =
      Arg.(
        value & opt int 3
        & info [ "repeat" ] ~docv:"R"
            ~doc:"Runs of each command, alternated; the median time is reported.")
    in
    let domains =
      Arg.(
        value
        & opt (some int) None
        & info [ "domains" ] ~docv:"D" ~doc:"Domains of both commands (default: theirs).")
    in
    let man =
      [
        `S Manpage.s_description;
        `P
          "Times $(b,lancer animate SCENE) (every frame of its animation) and $(b,lancer \
           render SCENE) (one still: frame 0), each a whole process from start to exit, \
           and prints their ratio: what the frames after the first cost. What does not \
           change between frames is evaluated, compiled and indexed once per animation.";
        `S Manpage.s_examples;
        `Pre "  lancer bench animation scenes/bench/field_moving.rts --repeat 3";
      ]
    in
    Cmd.v
      (Cmd.info "animation"
         ~doc:"wall time of a whole animation against one still of it, and their ratio"
         ~man ~exits)
      Term.(
        const (fun sc r d j -> Report.run (fun _ -> animation_cmd sc r d j))
        $ scene $ repeat $ domains $ json)
  in
  let language =
    let repeat =
      Arg.(
        value & opt int 3
        & info [ "repeat" ] ~docv:"N" ~doc:"Runs of each program (the median is shown).")
    in
    let grid =
      Arg.(
        value & opt int 1000
        & info [ "grid" ] ~docv:"N"
            ~doc:"The object program builds N × N spheres (1000: a million).")
    in
    let man =
      [
        `S Manpage.s_description;
        `P
          "Times the scene language on four programs, each a whole check in this process \
           (parse, static check, evaluation): a loop of 3 000 001 iterations computing \
           sin(i) * cos(i); a million sphere blocks built by two nested loops (the \
           objects' evaluation, without the renderer's build); as many spheres, each \
           with a material { color: … } of its own; and as many rotated boxes with a \
           material, in translated groups. When $(b,python3) is on the PATH, the same \
           loop in CPython (math.sin, math.cos) is timed as a whole process, alternating \
           with lancer's runs, and the ratio is shown.";
        `S Manpage.s_examples;
        `Pre "  lancer bench language --repeat 5";
      ]
    in
    Cmd.v
      (Cmd.info "language"
         ~doc:"speed of the scene language's evaluator, beside CPython on the same loop"
         ~man ~exits)
      Term.(
        const (fun r g j -> Report.run (fun _ -> language_cmd r g j))
        $ repeat $ grid $ json)
  in
  Cmd.group
    (Cmd.info "bench" ~doc ~exits)
    [ domains; quality; physics; scaling; animation; language ]
