(* lancer bench domains: one render's wall time over several domain counts. *)

open Lancer

let run (o : Options.t) ~counts ~repeat ~json =
  let prog = Scene_file.source o (Scene_file.load o.scene) in
  let time, frame = Options.time_of o prog in
  let sc = Options.scene_at o prog ~time ~frame in
  let cores = Domain.recommended_domain_count () in
  let rows =
    List.map
      (fun n ->
        if n < 1 then raise (Job_error.User "domain counts must be at least 1");
        Render.with_pool n (fun pool ->
            ignore (Timing.render ?pool sc) (* warm-up: pool start, caches *);
            let w0 = Gc.minor_words () in
            let runs =
              List.init (max 1 repeat) (fun _ ->
                  let t, _, st = Timing.render ?pool sc in
                  (t, st))
            in
            let words = Gc.minor_words () -. w0 in
            let st = snd (List.hd runs) in
            let rays = Counters.total_rays st in
            (* Gc.minor_words counts this domain's allocations only: meaningful on one domain,
               where the render runs on this one. *)
            let wpr =
              if n = 1 then words /. Float.of_int (max 1 (rays * List.length runs))
              else Float.nan
            in
            (n, Timing.median (List.map fst runs), rays, wpr)))
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
