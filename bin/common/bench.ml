open Lancer

let median xs =
  let a = Array.of_list xs in
  Array.sort Float.compare a;
  let n = Array.length a in
  if n = 0 then Float.nan else if n mod 2 = 1 then a.(n / 2) else 0.5 *. (a.((n / 2) - 1) +. a.(n / 2))

let time_render ?pool sc =
  let t0 = Unix.gettimeofday () in
  let fb, st = Render.render ?pool sc in
  (Unix.gettimeofday () -. t0, fb, st)

let domains_cmd (o : Cli.opts) counts repeat json =
  let prog = Cli.load o.scene in
  let time, frame = Cli.time_of o prog in
  let sc = Cli.scene_at o prog ~time ~frame in
  let cores = Domain.recommended_domain_count () in
  let rows =
    List.map
      (fun n ->
        if n < 1 then raise (Cli.User_error "domain counts must be at least 1");
        Render.with_pool n (fun pool ->
            ignore (time_render ?pool sc) (* warm-up: pool start, caches *);
            let runs = List.init (max 1 repeat) (fun _ -> let t, _, st = time_render ?pool sc in (t, st)) in
            let st = snd (List.hd runs) in
            (n, median (List.map fst runs), Stats.total_rays st)))
      counts
  in
  let base = match rows with (1, t, _) :: _ -> t | _ -> (match List.find_opt (fun (n, _, _) -> n = 1) rows with Some (_, t, _) -> t | None -> Float.nan) in
  let s = sc.settings in
  if json then
    print_endline
      (Yojson.Safe.pretty_to_string
         (`Assoc
           [ ("scene", `String (Option.value o.scene ~default:"(showcase)")); ("width", `Int s.width); ("height", `Int s.height);
             ("cores", `Int cores); ("repeat", `Int repeat);
             ("runs", `List (List.map (fun (n, t, rays) ->
                   `Assoc [ ("domains", `Int n); ("seconds", `Float t); ("rays", `Int rays);
                            ("rays_per_second", `Float (Float.of_int rays /. t)); ("speedup", `Float (base /. t)) ]) rows)) ]))
  else begin
    Printf.printf "scene %s, %d×%d, %d samples, depth %d; %d cores recommended; median of %d runs\n\n"
      (Option.value o.scene ~default:"(showcase)") s.width s.height s.samples s.depth cores repeat;
    Printf.printf "| domains | seconds | M rays/s | speed-up | efficiency |\n|---:|---:|---:|---:|---:|\n";
    List.iter
      (fun (n, t, rays) ->
        Printf.printf "| %d | %.3f | %.2f | %.2f× | %.0f%% |\n" n t (Float.of_int rays /. t /. 1e6) (base /. t)
          (100. *. base /. t /. Float.of_int n))
      rows
  end

(* ---- quality ---- *)

let cache_dir () =
  let base =
    match Sys.getenv_opt "XDG_CACHE_HOME" with
    | Some d when d <> "" -> d
    | _ -> Filename.concat (Option.value (Sys.getenv_opt "HOME") ~default:Filename.current_dir_name) ".cache"
  in
  Filename.concat base "lancer"

let rec mkdir_p d =
  if not (Sys.file_exists d) then begin
    mkdir_p (Filename.dirname d);
    try Unix.mkdir d 0o755 with Unix.Unix_error (Unix.EEXIST, _, _) -> ()
  end

let scene_text (o : Cli.opts) =
  match o.scene with
  | None -> Showcase.text
  | Some p -> ( try In_channel.with_open_bin p In_channel.input_all with Sys_error m -> raise (Cli.User_error m))

(* The reference: the reference preset at twice its samples, depth 64. *)
let reference (o : Cli.opts) prog ~pool =
  let base = Cli.scene_at { o with quality = Some Quality.Reference } prog ~time:0. ~frame:0 in
  let s = base.settings in
  let key =
    Digest.to_hex
      (Digest.string (Printf.sprintf "v1|%s|%d|%d|%s" (scene_text o) s.width s.height (Sys.ocaml_version)))
  in
  let path = Filename.concat (cache_dir ()) ("reference-" ^ key ^ ".ppm") in
  match Image.read_rgb8 path with
  | Ok img -> (img, true)
  | Error _ ->
      let sc = match Scene.with_settings base { s with samples = 16; depth = 64 } with Ok sc -> sc | Error m -> raise (Cli.User_error m) in
      let fb, _ = Render.render ?pool sc in
      let bytes = Image.to_bytes sc.settings.gamma fb in
      (try mkdir_p (cache_dir ()) with _ -> ());
      ignore (Image.write_rgb8 path fb.width fb.height bytes);
      ((fb.width, fb.height, bytes), false)

type row = { knob : string; value : string; seconds : float; rays : int; cmp : Compare.t }

let quality_cmd (o : Cli.opts) json svg =
  let prog = Cli.load o.scene in
  let domains = Cli.domains o in
  Render.with_pool domains @@ fun pool ->
  let (w, h, _) as ref_img, cached = reference o prog ~pool in
  if not json then Printf.eprintf "reference render %s\n%!" (if cached then "read from the cache" else "rendered and cached");
  let base = Cli.scene_at { o with quality = None; width = Some w; height = Some h } prog ~time:0. ~frame:0 in
  let run knob value sc =
    let t, fb, st = time_render ?pool sc in
    let img = (fb.Image.width, fb.height, Image.to_bytes sc.Scene.settings.gamma fb) in
    match Compare.compare ~threshold:1 ref_img img with
    | Ok cmp -> { knob; value; seconds = t; rays = Stats.total_rays st; cmp }
    | Error m -> raise (Cli.User_error m)
  in
  let with_s f = match Scene.with_settings base (f base.settings) with Ok sc -> sc | Error m -> raise (Cli.User_error m) in
  let s0 = base.settings in
  let rows =
    List.map (fun n -> run "samples" (Printf.sprintf "%d×%d" n n) (with_s (fun s -> { s with samples = n; adaptive = 0. }))) [ 1; 2; 3; 4; 6 ]
    @ List.map (fun th -> run "adaptive" (Printf.sprintf "%g" th) (with_s (fun s -> { s with samples = 4; adaptive = th }))) [ 0.2; 0.1; 0.05; 0.02 ]
    @ List.map (fun d -> run "depth" (string_of_int d) (with_s (fun s -> { s with depth = d }))) [ 1; 2; 3; 5; 8; 16; 64 ]
    @ (if base.features.soft_shadows then
         List.map
           (fun n ->
             run "light samples" (Printf.sprintf "%d×%d" n n)
               (Scene.map_lights (with_s (fun s -> s)) (function
                 | Light.Point p when p.radius > 0. -> Light.Point { p with samples = n }
                 | l -> l)))
           [ 1; 2; 4; 8 ]
       else [])
    @ List.map
        (fun (name, q) ->
          run "preset" name (match Quality.apply q base with Ok sc -> sc | Error m -> raise (Cli.User_error m)))
        Quality.all
  in
  ignore s0;
  if json then
    print_endline
      (Yojson.Safe.pretty_to_string
         (`Assoc
           [ ("scene", `String (Option.value o.scene ~default:"(showcase)")); ("width", `Int w); ("height", `Int h);
             ("domains", `Int domains);
             ("rows", `List (List.map (fun r ->
                   `Assoc [ ("knob", `String r.knob); ("value", `String r.value); ("seconds", `Float r.seconds);
                            ("rays", `Int r.rays); ("rmse", `Float r.cmp.rmse);
                            ("psnr", if Float.is_finite r.cmp.psnr then `Float r.cmp.psnr else `String "inf");
                            ("share_over_1", `Float r.cmp.over_share) ]) rows)) ]))
  else begin
    Printf.printf "scene %s at %d×%d on %d domains; error against a 16×16-sample, depth-64 reference\n\n"
      (Option.value o.scene ~default:"(showcase)") w h domains;
    Printf.printf "| knob | value | seconds | M rays | RMSE (0–255) | PSNR dB | pixels off > 1/255 |\n|---|---|---:|---:|---:|---:|---:|\n";
    List.iter
      (fun r ->
        Printf.printf "| %s | %s | %.3f | %.2f | %.3f | %s | %.2f%% |\n" r.knob r.value r.seconds (Float.of_int r.rays /. 1e6) r.cmp.rmse
          (if Float.is_finite r.cmp.psnr then Printf.sprintf "%.2f" r.cmp.psnr else "∞") (100. *. r.cmp.over_share))
      rows
  end;
  Option.iter (fun path -> Svg.write path (List.map (fun r -> (r.knob, r.value, r.seconds, r.cmp.psnr)) rows)) svg

(* ---- command line ---- *)

open Cmdliner

let exits = Cli.exits

let cmd =
  let doc = "measure speed and the speed/accuracy trade" in
  let json = Arg.(value & flag & info [ "json" ] ~doc:"Print JSON instead of a Markdown table.") in
  let domains =
    let counts =
      Arg.(value & opt (list int) [ 1; 2 ] & info [ "counts" ] ~docv:"N,N,..." ~doc:"Domain counts to time.")
    in
    let repeat = Arg.(value & opt int 3 & info [ "repeat" ] ~docv:"R" ~doc:"Runs per count; the median is reported.") in
    let man =
      [ `S Manpage.s_examples; `Pre "  lancer bench domains --width 1920 --height 1080 --counts 1,2,4,8,16" ]
    in
    Cmd.v
      (Cmd.info "domains" ~doc:"wall time and speed-up of one render over several domain counts" ~man ~exits)
      Term.(const (fun o c r j -> Cli.run (fun () -> domains_cmd o c r j)) $ Cli.opts_term $ counts $ repeat $ json)
  in
  let quality =
    let svg = Arg.(value & opt (some string) None & info [ "svg" ] ~docv:"FILE" ~doc:"Also draw time against PSNR as an SVG chart.") in
    let man = [ `S Manpage.s_examples; `Pre "  lancer bench quality scenes/showcase.rts --width 320 --height 240 --svg trade.svg" ] in
    Cmd.v
      (Cmd.info "quality" ~doc:"time, rays and error against a reference for each quality knob" ~man ~exits)
      Term.(const (fun o j s -> Cli.run (fun () -> quality_cmd o j s)) $ Cli.opts_term $ json $ svg)
  in
  Cmd.group (Cmd.info "bench" ~doc ~exits) [ domains; quality ]

