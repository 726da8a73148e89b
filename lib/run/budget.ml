(* --max-error: the cheapest settings whose error against the reference preset, predicted
   on probe pixels, is within a limit. *)

let user = Job_error.user

(* A knob: its name, its ladder from the cheapest value up to the reference's, and what a
   value does to a scene (the shutter's is made apart: its instants are scenes). *)
type knob = { name : string; ladder : float array; show : float -> string }

let grid v = Printf.sprintf "%d×%d" (int_of_float v) (int_of_float v)
let ints l = Array.of_list (List.map Float.of_int l)

(* The powers of two under [top], then [top]. *)
let doubling top =
  let rec go n = if n >= top then [ top ] else n :: go (2 * n) in
  ints (go 1)

let knobs ~(reference : Scene.t) (base : Scene.t) =
  let rd = reference.settings.depth in
  let lens = base.camera.lens_samples in
  [
    Some { name = "samples"; ladder = ints [ 1; 2; 3; 4; 5; 6; 7; 8 ]; show = grid };
    Some
      {
        name = "adaptive";
        (* Off at both ends: plain n×n samples are the cheapest at few samples and the
           reference's at its own. *)
        ladder = [| 0.; 0.2; 0.1; 0.05; 0.02; 0. |];
        show = (fun v -> if v = 0. then "off" else Printf.sprintf "%g" v);
      };
    Some
      {
        name = "depth";
        ladder = ints (List.filter (fun d -> d < rd) [ 1; 2; 3; 5; 8; 16 ] @ [ rd ]);
        show = (fun v -> string_of_int (int_of_float v));
      };
    (if base.features.soft_shadows then
       Some { name = "light samples"; ladder = ints [ 1; 2; 4; 8 ]; show = grid }
     else None);
    (if base.features.depth_of_field && lens > 1 then
       Some { name = "lens samples"; ladder = doubling lens; show = grid }
     else None);
    (if Camera.motion_blur base.camera then
       Some
         {
           name = "shutter samples";
           ladder = ints [ 1; 2; 4; 8; 16; 32 ];
           show = (fun v -> string_of_int (int_of_float v));
         }
     else None);
  ]
  |> List.filter_map Fun.id |> Array.of_list

type choice = {
  limit : Compare.metric;
  settings : (string * string) list;
  values : (string * float) list;
  scene : Scene.t;
  rays : float;
  predicted : float;  (** in the metric's own unit *)
  seconds : float;
  reference_seconds : float;
  search_seconds : float;
  search_rays : int;
  probes : int;
  probe_pixels : int;
}

let metric_name = function
  | Compare.Flip _ -> "mean FLIP"
  | Rmse _ -> "RMSE"
  | Psnr _ -> "PSNR"
  | Ssim _ -> "SSIM"

(* The metric as --metric names it. *)
let option_name = function
  | Compare.Flip _ -> "flip"
  | Rmse _ -> "rmse"
  | Psnr _ -> "psnr"
  | Ssim _ -> "ssim"

let check (m : Compare.metric) =
  let range =
    match m with
    | Flip e when e > 0. && e < 1. -> None
    | Flip e -> Some (Printf.sprintf "a mean FLIP, above 0 and under 1 (got %g)" e)
    | Rmse e when e > 0. && e <= 255. -> None
    | Rmse e -> Some (Printf.sprintf "an RMSE, above 0 and at most 255 (got %g)" e)
    | Psnr e when e > 0. && Float.is_finite e -> None
    | Psnr e -> Some (Printf.sprintf "a PSNR in dB, above 0 and finite (got %g)" e)
    | Ssim _ -> Some "not a metric it can choose settings by (flip, rmse or psnr)"
  in
  Option.iter (user "--max-error with --metric %s is %s" (option_name m)) range

(* What --max-error chooses itself cannot also be given. *)
let check_options (o : Options.t) ~resume =
  let given =
    List.filter_map Fun.id
      [
        Option.map (fun _ -> "--samples") o.samples;
        Option.map (fun _ -> "--depth") o.depth;
        Option.map (fun _ -> "--quality") o.quality;
        (if resume then Some "--resume" else None);
      ]
  in
  match given with
  | [] -> ()
  | opt :: _ ->
      user
        "--max-error chooses the samples, depth and quality settings itself: it cannot \
         be combined with %s"
        opt

(* What the search aims at: [margin] of the limit (of the RMSE a PSNR allows), since the
   probes are a sample of the image. *)
let margin = 0.75

(* The error of a probe image against the reference's, lower is better: mean FLIP or
   RMSE. A probe pixel stands for a stride×stride block, and FLIP depends on the size at
   which the eye sees an error: a change that is the same over neighbouring pixels (a
   missing reflection, a ghost of a moving object) is seen at the size of the block,
   [ppd / stride] pixels per degree; one that changes from pixel to pixel (noise,
   stair-steps) at the size of one pixel, the image's own [ppd], as if the probes were
   neighbours. The larger of the two is the error. *)
let error (m : Compare.metric) ~stride ref_img img =
  match m with
  | Flip _ ->
      let at ppd = Flip.mean (Flip.error_map ~ppd ref_img img) in
      let whole = at Flip.default_ppd in
      if stride = 1 then whole
      else Float.max whole (at (Flip.default_ppd /. Float.of_int stride))
  | Rmse _ | Psnr _ | Ssim _ -> (
      match Compare.compare ~threshold:1 ref_img img with
      | Ok c -> c.rmse
      | Error msg -> user "%s" msg)

(* The limit, in the unit of [error]. *)
let limit_error = function
  | Compare.Flip e | Rmse e -> e
  | Psnr db -> 255. /. (10. ** (db /. 20.))
  | Ssim _ -> 0.

let target m = margin *. limit_error m

(* The error as the metric states it. *)
let stated (m : Compare.metric) e =
  match m with
  | Psnr _ -> if e = 0. then Float.infinity else 20. *. Float.log10 (255. /. e)
  | _ -> e

(* The stride of about [n] probes: one pixel per stride×stride block. *)
let stride_for (sc : Scene.t) n =
  let px = sc.settings.width * sc.settings.height in
  max 1
    (int_of_float (Float.ceil (Float.sqrt (Float.of_int px /. Float.of_int (max 1 n)))))

(* How many probes: a first round of the search on about 1/2400 of the pixels (at least
   128), then a second on up to about 1/150 (see [choose]). *)
let first_probes px = max 128 (px / 2400)
let most_probes px = max (first_probes px) (px / 150)

(* What the whole search may cost, against the image at the first round's choice. *)
let share = 0.15

(* The pixels of the probe image: one per stride×stride block. *)
let probe_pixels (sc : Scene.t) stride =
  let up n = (n + stride - 1) / stride in
  up sc.settings.width * up sc.settings.height

let ok = function Ok sc -> sc | Error m -> user "%s" m

(* [base] at the knobs' [values] (by name; a knob not named keeps the base's setting,
   except samples and the adaptive threshold, at their cheapest): the scene of a choice.
   [at_shutter n] is [base] with [n] instants of its shutter. *)
let at_values ~at_shutter (base : Scene.t) values =
  let value name = List.assoc_opt name values in
  let v name d = Option.value (value name) ~default:d in
  let sc =
    match value "shutter samples" with
    | Some n -> at_shutter (int_of_float n)
    | None -> base
  in
  let sc =
    ok
      (Scene.map_settings sc (fun s ->
           {
             s with
             samples = int_of_float (v "samples" 1.);
             adaptive = v "adaptive" 0.;
             depth = int_of_float (v "depth" (Float.of_int s.depth));
           }))
  in
  let sc =
    match value "light samples" with
    | None -> sc
    | Some n ->
        let n = int_of_float n in
        Scene.map_lights sc (function
          | Light.Point p when p.radius > 0. ->
              Light.Point { p with samples = min n (max p.samples 8) }
          | l -> l)
  in
  match value "lens samples" with
  | None -> sc
  | Some n ->
      ok (Scene.map_camera sc (fun c -> Camera.with_lens_samples c (int_of_float n)))

let shutter ?cancel src overrides (base : Scene.t) ~time ~frame n =
  let sc = ok (Scene.with_camera base (Camera.with_shutter_samples base.camera n)) in
  Scenes.with_instants ?cancel src overrides sc ~time ~frame

let names =
  [ "samples"; "adaptive"; "depth"; "light samples"; "lens samples"; "shutter samples" ]

let check_values values =
  List.iter
    (fun (name, v) ->
      if not (List.mem name names) then
        user "%S is not a setting --max-error chooses (%s)" name
          (String.concat ", " names);
      let whole = Float.is_integer v && v >= 1. && v <= 4096. in
      let fits =
        match name with
        | "adaptive" -> v >= 0. && v < 1.
        | "depth" -> whole && int_of_float v <= Settings.max_depth
        | _ -> whole
      in
      if not fits then user "%g is not a value of the setting %S" v name)
    values

let apply ?cancel (src : Scenes.t) overrides (base : Scene.t) ~time ~frame values =
  check_values values;
  (* The files the shutter's instants read, where their number is chosen. *)
  let files = ref [] in
  let at_shutter n =
    let sc, f = shutter ?cancel src overrides base ~time ~frame n in
    files := f;
    sc
  in
  let sc = at_values ~at_shutter base values in
  (sc, !files)

let choose ?cancel ?pool ~domains (o : Options.t) (src : Scenes.t) (base : Scene.t) ~time
    ~frame limit =
  check limit;
  let t0 = Unix.gettimeofday () in
  let reference =
    Options.scene_at ?cancel { o with quality = Some Quality.Reference } src ~time ~frame
  in
  let knobs = knobs ~reference base in
  let pixels = base.settings.width * base.settings.height in
  let instants = Hashtbl.create 8 in
  let at_shutter n =
    match Hashtbl.find_opt instants n with
    | Some sc -> sc
    | None ->
        let sc, _ = shutter ?cancel src (Options.overrides o) base ~time ~frame n in
        Hashtbl.add instants n sc;
        sc
  in
  let values idx =
    Array.to_list (Array.mapi (fun j k -> (k.name, k.ladder.(idx.(j)))) knobs)
  in
  let make idx = at_values ~at_shutter base (values idx) in
  (match pool with
  | Some p -> fun f -> f p
  | None -> fun f -> Render.with_pool ?cancel domains f)
  @@ fun pool ->
  let rays = ref 0 and probes = ref 0 and probe_seconds = ref 0. in
  let probe ~stride sc =
    let t = Unix.gettimeofday () in
    let fb, st = Render.render ?cancel ?pool ~stride sc in
    probe_seconds := !probe_seconds +. (Unix.gettimeofday () -. t);
    let r = Counters.total_rays st in
    rays := !rays + r;
    incr probes;
    ((fb.Framebuffer.width, fb.height, Image.to_bytes sc.Scene.settings.gamma fb), r)
  in
  (* The rays of the whole image, from [r] rays of its probes at [stride]. *)
  let whole ~stride r =
    Float.of_int r *. Float.of_int pixels /. Float.of_int (probe_pixels base stride)
  in
  let start = Array.make (Array.length knobs) 0 in
  let goal = target limit in
  (* One round of the search on the probes of [stride]: the choice, its error and rays,
     the reference's rays. *)
  let round stride =
    let ref_img, ref_rays = probe ~stride reference in
    let memo = Hashtbl.create 64 in
    let eval idx =
      let key = Array.to_list idx in
      match Hashtbl.find_opt memo key with
      | Some r -> r
      | None ->
          let img, r = probe ~stride (make idx) in
          let e = error limit ~stride ref_img img in
          Hashtbl.add memo key (e, r);
          (e, r)
    in
    (* From the cheapest setting, raise one knob a notch at a time: the one whose error
       falls most per ray it adds (where none lowers the error, the one that leaves the
       least), until the error is within the goal or every knob is at the reference's. *)
    let rec climb idx (e, r) =
      if e <= goal then (idx, (e, r))
      else
        let best = ref None in
        Array.iteri
          (fun j k ->
            if idx.(j) < Array.length k.ladder - 1 then (
              let idx' = Array.copy idx in
              idx'.(j) <- idx.(j) + 1;
              let e', r' = eval idx' in
              let drop = e -. e' in
              let score =
                if drop > 0. then (1., drop /. Float.of_int (max 1 (r' - r)))
                else (0., -.e')
              in
              match !best with
              | Some (s, _, _) when compare score s <= 0 -> ()
              | _ -> best := Some (score, idx', (e', r'))))
          knobs;
        match !best with None -> (idx, (e, r)) | Some (_, idx', er) -> climb idx' er
    in
    (* Then each knob in turn lowered while the error stays within the goal: a notch the
       climb took early may not be needed once the others have risen. *)
    let rec descend idx (e, r) j =
      if j = Array.length knobs then (idx, (e, r))
      else if idx.(j) = 0 then descend idx (e, r) (j + 1)
      else
        let idx' = Array.copy idx in
        idx'.(j) <- idx.(j) - 1;
        let e', r' = eval idx' in
        if e' <= goal && r' <= r then descend idx' (e', r') j
        else descend idx (e, r) (j + 1)
    in
    let low = eval start in
    let idx, er = climb start low in
    let idx, (e, r) = if fst er <= goal then descend idx er 0 else (idx, er) in
    (* Settings that cost what the reference costs are no cheaper than the reference:
       where the climb ends there, the cheapest setting it tried whose error is within
       the limit itself (without the margin) is taken instead. *)
    let idx, (e, r) =
      if r < ref_rays then (idx, (e, r))
      else
        Hashtbl.fold
          (fun key (e', r') l ->
            if e' <= limit_error limit then (r', e', key) :: l else l)
          memo []
        |> List.sort compare
        |> function
        | (r', e', key) :: _ when r' < r -> (Array.of_list key, (e', r'))
        | _ -> (idx, (e, r))
    in
    (idx, e, r, ref_rays, snd low)
  in
  (* A first round on few probes says what a probe costs the search and what the image
     will cost at the choice; a second round follows on as many probes as keep the whole
     search within [share] of that image, where that is at least three times as many. *)
  let first = stride_for base (first_probes pixels) in
  let ((_, _, r1, ref1, low) as first_choice) = round first in
  let n1 = Float.of_int (probe_pixels base first) in
  let spent = Float.of_int !rays in
  let image = whole ~stride:first in
  (* The second round may also end at the cheapest settings, after the reference's
     probes and the cheapest's: the search stays within [share] of the cheapest's image
     too. *)
  let want =
    min (most_probes pixels)
      (int_of_float
         (Float.min
            (((share *. image r1) -. spent) /. (spent /. n1))
            (((share *. image low) -. spent) /. (Float.of_int (ref1 + low) /. n1))))
  in
  let stride, (idx, e, r, ref_rays, _) =
    if Float.of_int want >= 3. *. n1 then
      let s = stride_for base want in
      (s, round s)
    else (first, first_choice)
  in
  let scene = make idx in
  let per_ray = !probe_seconds /. Float.of_int (max 1 !rays) in
  let whole = whole ~stride in
  {
    limit;
    values = values idx;
    settings =
      Array.to_list (Array.mapi (fun j k -> (k.name, k.show k.ladder.(idx.(j)))) knobs);
    scene;
    rays = whole r;
    predicted = stated limit e;
    seconds = per_ray *. whole r;
    reference_seconds = per_ray *. whole ref_rays;
    search_seconds = Unix.gettimeofday () -. t0;
    search_rays = !rays;
    probes = !probes;
    probe_pixels = probe_pixels base stride;
  }

let limit_value = function Compare.Flip e | Rmse e | Psnr e | Ssim e -> e

let record_of_limit limit =
  { Provenance.metric = option_name limit; limit = limit_value limit; values = [] }

let record c = { (record_of_limit c.limit) with values = c.values }
let secs x = if x < 10. then Printf.sprintf "%.2f s" x else Printf.sprintf "%.0f s" x

let text c =
  let limit = limit_value c.limit in
  Printf.sprintf
    "max error %g (%s): %s; predicted error %s, predicted time %s against the \
     reference's %s; search %s (%d probe renders, of %d pixels in the last round)"
    limit (metric_name c.limit)
    (String.concat ", " (List.map (fun (k, v) -> k ^ " " ^ v) c.settings))
    (match c.limit with
    | Psnr _ -> Printf.sprintf "%.2f dB" c.predicted
    | _ -> Printf.sprintf "%.4f" c.predicted)
    (secs c.seconds) (secs c.reference_seconds) (secs c.search_seconds) c.probes
    c.probe_pixels

let json c =
  let num x = if Float.is_finite x then `Float x else `String "inf" in
  `Assoc
    [
      ("metric", `String (metric_name c.limit));
      ("limit", `Float (limit_value c.limit));
      ("settings", `Assoc (List.map (fun (k, v) -> (k, `String v)) c.settings));
      ("predicted_error", num c.predicted);
      ("predicted_seconds", `Float c.seconds);
      ("reference_predicted_seconds", `Float c.reference_seconds);
      ("search_seconds", `Float c.search_seconds);
      ("search_rays", `Int c.search_rays);
      ("probe_renders", `Int c.probes);
      ("probe_pixels", `Int c.probe_pixels);
    ]
