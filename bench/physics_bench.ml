(* The physics methods against the closed form of a dropped ball (Drop). *)

open Lancer
module Timing = Lancer_measure.Timing

(* The drop of doc/reference/numerics.md, in closed form (Drop), independently of the
   engine it checks. *)
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
  Timing.median (List.init 5 (fun _ -> batch n /. Float.of_int n))

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

let run ~rates ~until ~sample_rate ~json =
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
