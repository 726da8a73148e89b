(* The rays this run cast: a resumed render's counters include the checkpoint's tiles. *)
let run_rays ~resumed_rays st = Counters.total_rays st - resumed_rays

(* A noise estimate in 8-bit steps, to two significant digits. *)
let noise_text e = if e >= 10. then Printf.sprintf "%.0f" e else Printf.sprintf "%.2g" e

let summary ?size ?(resumed_rays = 0) ~out (sc : Scene.t) ~build ~render ~workers
    (st : Counters.t) =
  let rays = Float.of_int (Counters.total_rays st) /. 1e6 in
  let now = Float.of_int (run_rays ~resumed_rays st) /. 1e6 in
  let w, h = Option.value size ~default:(sc.settings.width, sc.settings.height) in
  Printf.sprintf
    "wrote %s (%d×%d, %.2f s: build %.2f s, render %.2f s, %s, %.1f M rays%s, %.2f M \
     rays/s%s)"
    out w h (build +. render) build render workers rays
    (if resumed_rays > 0 then Printf.sprintf " (%.1f M of them in this run)" now else "")
    (now /. Float.max render 1e-9)
    (match Counters.noise st with
    | Some e -> Printf.sprintf ", noise ≈ %s/255" (noise_text e)
    | None -> "")

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

let stats_json ?(resumed_rays = 0) (o : Options.t) (sc : Scene.t) ~build ~wall ~domains
    ~ranks (st : Counters.t) =
  let s = sc.settings in
  let rays = Counters.total_rays st in
  let now = run_rays ~resumed_rays st in
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
      ("resumed_rays", `Int resumed_rays);
      ("rays_per_second", `Float (if wall > 0. then Float.of_int now /. wall else 0.));
      ("bad_samples", `Int st.bad_samples);
      ("noise", match Counters.noise st with Some e -> `Float e | None -> `Null);
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

let warn_bad_samples (st : Counters.t) =
  if st.bad_samples > 0 then
    match st.first_bad with
    | Some (i, j) ->
        Printf.eprintf
          "lancer: warning: %d samples were NaN or infinite (first at pixel %d,%d); they \
           were replaced by the background\n\
           %!"
          st.bad_samples i j
    | None -> ()

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

let warn_long_render (o : Options.t) (sc : Scene.t) =
  let c = Cost.estimate sc in
  if (not o.quiet) && c.direct > long_render_rays then
    Printf.eprintf
      "lancer: note: this render is estimated at up to %s rays (%s primary; at most %s \
       with every bounce): it may take long; `lancer check` compares the quality presets\n\
       %!"
      (rays_text c.direct) (rays_text c.primary) (rays_text c.bound)
