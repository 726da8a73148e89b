(* Random spheres against the sphere count, the domain count and the image size. *)

open Lancer
module Timing = Lancer_measure.Timing

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
  let render_s = Timing.median (List.map snd runs) in
  let rays = Counters.total_rays (snd (fst (List.hd runs))) in
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
             ("scaling: unreadable row from the child process: " ^ String.trim out)))
  | Unix.WEXITED c | Unix.WSIGNALED c | Unix.WSTOPPED c ->
      raise
        (Job_error.User
           (Printf.sprintf
              "scaling: the child measuring %d spheres at %d×%d on %d domains failed \
               (status %d)"
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

let run ~repeat ~counts ~width ~height ~domains ~domain_counts ~sizes ~base_count ~sweeps
    ~in_process ~row ~json =
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
