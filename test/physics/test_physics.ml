(* Physics tests: the closed-form bouncing ball of doc/reference/numerics.md, the
   fixed-step errors, tunnelling, sphere–sphere impulses, and properties of the exact
   integrator. *)

open Lancer
module P = Physics

let g = 9.81
let r = 0.1
let floor = P.Plane { normal = Vec3.y_axis; offset = 0. }

(* A ball of radius r whose lowest point starts 1 m above the floor y = 0. *)
let drop ?(world = P.default_world) ?(until = 10.) e =
  let ball =
    P.body ~name:"ball" ~center:(Vec3.v 0. (1. +. r) 0.) ~radius:r ~restitution:e ()
  in
  P.simulate world [ floor ] [ ball ] ~until

let state tr t =
  match P.sample tr "ball" t with Some s -> s | None -> Alcotest.fail "no ball"

let pos tr t = fst (state tr t)
let bounces tr = List.filter (fun (e : P.event) -> e.kind <> P.Leave) (P.events tr)
let check_close eps msg expected actual = Alcotest.(check (float eps)) msg expected actual

(* Height of the ball's lowest point at its apex between impacts k and k+1: closed form of
   the flight that starts at impact k. *)
let apex tr t_k =
  let p, v = state tr t_k in
  p.y -. r +. (v.y *. v.y /. (2. *. g))

let elastic_impact_times () =
  let tr = drop ~until:93. 1. in
  let evs = bounces tr in
  Alcotest.(check bool) "at least 101 impacts" true (List.length evs >= 101);
  List.iteri
    (fun k (e : P.event) ->
      if k <= 100 then
        check_close 1e-9
          (Printf.sprintf "impact %d" k)
          (0.451523640986 +. (float k *. 0.903047281971))
          e.time)
    evs

let elastic_apex_stays () =
  let tr = drop ~until:93. 1. in
  List.iteri
    (fun k (e : P.event) ->
      if k <= 100 then check_close 1e-9 (Printf.sprintf "apex %d" k) 1. (apex tr e.time))
    (bounces tr);
  (* and sampled at the midpoint between two impacts *)
  check_close 1e-9 "sampled apex after 50 bounces" (1. +. r)
    (pos tr (0.451523640986 +. (50.5 *. 0.903047281971))).y

let damped_impacts () =
  let tr = drop 0.8 in
  let expected =
    [ 0.451523640986; 1.173961466563; 1.751911727025; 2.214271935394; 2.584160102090 ]
  in
  let evs = bounces tr in
  List.iteri
    (fun k t -> check_close 1e-9 (Printf.sprintf "impact %d" k) t (List.nth evs k).time)
    expected;
  List.iteri
    (fun k h ->
      check_close 1e-9 (Printf.sprintf "apex %d" k) h (apex tr (List.nth evs k).time))
    [ 0.64; 0.4096; 0.262144; 0.16777216 ]

let damped_comes_to_rest () =
  let tr = drop ~until:100. 0.8 in
  let evs = P.events tr in
  let rests = List.filter (fun (e : P.event) -> e.kind = P.Rest) evs in
  Alcotest.(check int) "one rest event" 1 (List.length rests);
  let t_rest = (List.hd rests).time in
  Alcotest.(check bool)
    "rests at or before 4.063712768872 s" true (t_rest <= 4.063712768872);
  Alcotest.(check bool) "a finite, small number of events" true (List.length evs < 100);
  Alcotest.(check bool)
    "nothing after resting" true
    (List.for_all (fun (e : P.event) -> e.time <= t_rest) evs);
  List.iter
    (fun t ->
      let p, v = state tr t in
      check_close 1e-12 (Printf.sprintf "on the floor at %g s" t) r p.y;
      check_close 0. (Printf.sprintf "still at %g s" t) 0. (Vec3.length v))
    [ 4.07; 5.; 10.; 99. ];
  Alcotest.(check bool) "not truncated" false (P.truncated tr)

let verlet_free_flight () =
  let world = { P.default_world with method_ = P.Verlet; step = 1. /. 30. } in
  let b =
    P.body ~name:"ball" ~center:Vec3.zero ~velocity:(Vec3.v 1. 5. (-2.)) ~radius:r ()
  in
  let tr = P.simulate world [] [ b ] ~until:10. in
  let exact = P.simulate P.default_world [] [ b ] ~until:10. in
  List.iter
    (fun t ->
      let d =
        Vec3.length
          (Vec3.sub
             (fst (Option.get (P.sample tr "ball" t)))
             (fst (Option.get (P.sample exact "ball" t))))
      in
      Alcotest.(check bool)
        (Printf.sprintf "Verlet within 1e-10 m at %g s (%g)" t d)
        true (d < 1e-10))
    [ 1. /. 30.; 1.; 2.5; 5.01; 10. ]

let euler_drift () =
  let world = { P.default_world with method_ = P.Euler; step = 1. /. 30. } in
  let b = P.body ~name:"ball" ~center:Vec3.zero ~radius:r () in
  let tr = P.simulate world [] [ b ] ~until:10. in
  let exact_y = -0.5 *. g *. 100. in
  let drift = (fst (Option.get (P.sample tr "ball" 10.))).y -. exact_y in
  check_close 1e-9 "Euler lags by g·dt·t/2 = 1.635 m" 1.635 drift

let fixed_step_adds_energy () =
  let world = { P.default_world with method_ = P.Verlet; step = 1. /. 30. } in
  let tr = drop ~world ~until:2. 1. in
  let apex = ref 0. in
  for k = 0 to 1000 do
    let t = 0.6 +. (float k *. 0.001) in
    apex := Float.max !apex ((pos tr t).y -. r)
  done;
  check_close 1e-3 "first apex 1.068 m instead of 1 m at dt = 1/30" 1.068 !apex

let plate =
  P.Parallelogram
    { origin = Vec3.v (-0.5) 0. (-0.5); edge1 = Vec3.v 1. 0. 0.; edge2 = Vec3.v 0. 0. 1. }

let fast_ball y0 =
  P.body ~name:"ball" ~center:(Vec3.v 0.1 y0 0.2) ~velocity:(Vec3.v 0. (-4.43) 0.)
    ~radius:0.05 ()

let tunnelling () =
  let no_g = { P.default_world with gravity = Vec3.zero } in
  let verlet =
    P.simulate
      { no_g with method_ = P.Verlet; step = 1. /. 30. }
      [ plate ]
      [ fast_ball 0.2 ]
      ~until:1.
  in
  Alcotest.(check bool)
    "Verlet at 1/30 s passes through the plate" true ((pos verlet 1.).y < 0.);
  let exact = P.simulate no_g [ plate ] [ fast_ball 0.2 ] ~until:1. in
  Alcotest.(check bool) "exact bounces off it" true ((pos exact 1.).y > 0.);
  check_close 1e-12 "at the time of contact" (0.15 /. 4.43)
    (List.hd (P.events exact)).time;
  (* with gravity, from many starting heights *)
  for k = 0 to 200 do
    let y0 = 0.06 +. (float k *. 0.01) in
    let tr = P.simulate P.default_world [ plate ] [ fast_ball y0 ] ~until:1. in
    Alcotest.(check bool)
      (Printf.sprintf "caught from %.2f m" y0)
      true
      (List.exists (fun (e : P.event) -> e.target = P.Collider 0) (P.events tr)
      && (pos tr 1.).y > 0.)
  done

let edge_and_corner () =
  let no_g = { P.default_world with gravity = Vec3.zero } in
  (* a ball aimed at the plate's edge x = 0.5, beside the face: hits the edge capsule *)
  let b =
    P.body ~name:"ball" ~center:(Vec3.v 0.52 1. 0.) ~velocity:(Vec3.v 0. (-1.) 0.)
      ~radius:0.05 ()
  in
  let tr = P.simulate no_g [ plate ] [ b ] ~until:2. in
  let e = List.hd (P.events tr) in
  (* contact when the distance to the edge line is 0.05: y = √(0.05² − 0.02²) *)
  check_close 1e-12 "edge contact time"
    (1. -. Float.sqrt ((0.05 *. 0.05) -. (0.02 *. 0.02)))
    e.time;
  Alcotest.(check bool) "deflected outwards" true ((snd (state tr 2.)).x > 0.);
  let box = P.Box { min = Vec3.v (-1.) (-1.) (-1.); max = Vec3.v 1. 0. 1. } in
  let b =
    P.body ~name:"ball" ~center:(Vec3.v 2. 1. 2.) ~velocity:(Vec3.v (-1.) (-1.) (-1.))
      ~radius:0.1 ()
  in
  let tr = P.simulate no_g [ box ] [ b ] ~until:3. in
  let e = List.hd (P.events tr) in
  check_close 1e-9 "corner contact time" (1. -. (0.1 /. Float.sqrt 3.)) e.time;
  check_close 1e-9 "reflected straight back" 1. (snd (state tr 3.)).x

let head_on () =
  let no_g = { P.default_world with gravity = Vec3.zero } in
  let a =
    P.body ~name:"a" ~center:(Vec3.v (-1.) 0. 0.) ~velocity:(Vec3.v 2. 0. 0.) ~radius:0.5
      ()
  in
  let b = P.body ~name:"b" ~center:(Vec3.v 1. 0. 0.) ~radius:0.5 () in
  let tr = P.simulate no_g [] [ a; b ] ~until:2. in
  let va = snd (Option.get (P.sample tr "a" 2.))
  and vb = snd (Option.get (P.sample tr "b" 2.)) in
  check_close 1e-12 "impact at 0.5 s" 0.5 (List.hd (P.events tr)).time;
  check_close 1e-12 "a stops" 0. va.x;
  check_close 1e-12 "b takes its velocity" 2. vb.x;
  (* unequal masses, under gravity: momentum and (e = 1) energy are conserved *)
  let a =
    P.body ~name:"a" ~center:(Vec3.v (-1.) 0. 0.) ~velocity:(Vec3.v 2. 0.3 0.1)
      ~radius:0.5 ~mass:1. ()
  in
  let b =
    P.body ~name:"b" ~center:(Vec3.v 1. 0.1 0.) ~velocity:(Vec3.v (-1.) 0. 0.) ~radius:0.4
      ~mass:3. ()
  in
  let tr = P.simulate P.default_world [] [ a; b ] ~until:1. in
  Alcotest.(check int) "one impact" 1 (List.length (P.events tr));
  let momentum t =
    let va = snd (Option.get (P.sample tr "a" t))
    and vb = snd (Option.get (P.sample tr "b" t)) in
    (Vec3.add va (Vec3.smul 3. vb), (0.5 *. Vec3.length2 va) +. (1.5 *. Vec3.length2 vb))
  in
  let t_hit = (List.hd (P.events tr)).time in
  let m0, k0 = momentum (t_hit -. 1e-12) and m1, k1 = momentum t_hit in
  Alcotest.(check bool) "momentum conserved" true (Vec3.equal_f ~eps:1e-9 m0 m1);
  check_close 1e-9 "kinetic energy conserved" k0 k1

(* ---- properties ---- *)

let seed = 20240611
let rand = Random.State.make [| seed |]

let energy tr (bodies : P.body list) gvec t =
  List.fold_left
    (fun acc (b : P.body) ->
      let p, v = Option.get (P.sample tr b.name t) in
      acc +. (b.mass *. ((0.5 *. Vec3.length2 v) -. Vec3.dot gvec p)))
    0. bodies

let scene_gen =
  QCheck.Gen.(
    let f lo hi = float_range lo hi in
    map
      (fun ((h, vx, vz, e), (tilt, e2, boxed)) -> (h, vx, vz, e, tilt, e2, boxed))
      (pair
         (quad (f 0.2 3.) (f (-2.) 2.) (f (-2.) 2.) (f 0. 1.))
         (triple (f (-0.3) 0.3) (f 0. 1.) bool)))

let energy_never_increases =
  QCheck.Test.make ~count:60 ~name:"energy never increases across an exact bounce (e ≤ 1)"
    (QCheck.make scene_gen) (fun (h, vx, vz, e, tilt, e2, boxed) ->
      let ground = P.Plane { normal = Vec3.v tilt 1. 0.; offset = 0. } in
      let cols =
        if boxed then
          [ ground; P.Box { min = Vec3.v (-3.) 0. (-3.); max = Vec3.v (-2.) 1. 3. } ]
        else [ ground ]
      in
      let bodies =
        [
          P.body ~name:"a"
            ~center:(Vec3.v 0. (h +. 1.) 0.)
            ~velocity:(Vec3.v vx 0. vz) ~radius:0.2 ~restitution:e ();
          P.body ~name:"b"
            ~center:(Vec3.v 0.1 (h +. 2.) 0.)
            ~velocity:(Vec3.v (-.vx) 1. 0.) ~radius:0.3 ~mass:2. ~restitution:e2 ();
        ]
      in
      let tr = P.simulate P.default_world cols bodies ~until:6. in
      let times =
        List.sort_uniq Float.compare
          (0. :: 6. :: List.map (fun (e : P.event) -> e.time) (P.events tr))
      in
      let rec mids = function
        | a :: (b :: _ as rest) -> (0.5 *. (a +. b)) :: mids rest
        | _ -> []
      in
      let es = List.map (energy tr bodies P.default_world.gravity) (mids times) in
      let rec ok = function
        | a :: (b :: _ as rest) ->
            b <= a +. (1e-9 *. Float.max 1. (Float.abs a)) && ok rest
        | _ -> true
      in
      ok es)

let sample_is_deterministic_and_continuous =
  QCheck.Test.make ~count:200 ~name:"sampling is deterministic and continuous in time"
    QCheck.(pair (float_range 0. 8.) (float_range 0. 1.))
    (fun (t, e) ->
      let tr = drop ~until:8. e in
      let tr' = drop ~until:8. e in
      let p, v = state tr t and p', v' = state tr' t in
      let q, _ = state tr (t +. 1e-7) in
      (* speed is at most √(2·g·1 m) ≈ 4.43 m/s *)
      p = p' && v = v' && Vec3.length (Vec3.sub q p) <= 4.5e-7)

let any_frame_rate () =
  let tr = drop ~until:8. 0.9 in
  let at fps k = state tr (float k /. fps) in
  (* the same instants reached at 24, 30 and 60 fps, and the whole sequence twice *)
  for k = 0 to 96 do
    let a = at 12. k and b = at 24. (2 * k) and c = at 60. (5 * k) in
    Alcotest.(check bool)
      (Printf.sprintf "instant %d/12 s identical" k)
      true
      (a = b && b = c)
  done;
  let tr2 = drop ~until:8. 0.9 in
  Alcotest.(check bool) "recomputed identically" true (P.events tr = P.events tr2)

let resting_on_a_plate_slides_off () =
  (* A ball dropped onto a tilted plate comes to rest, slides down, leaves the border. *)
  let plate =
    P.Parallelogram
      {
        origin = Vec3.v (-1.) 0.5 (-1.);
        edge1 = Vec3.v 2. (-0.2) 0.;
        edge2 = Vec3.v 0. 0. 2.;
      }
  in
  let b = P.body ~name:"ball" ~center:(Vec3.v 0. 1. 0.) ~radius:0.1 ~restitution:0.5 () in
  let tr = P.simulate P.default_world [ plate; floor ] [ b ] ~until:20. in
  Alcotest.(check (list string))
    "rests on the plate, leaves it, rests on the floor"
    [ "rest 0"; "leave 0"; "rest 1" ]
    (List.filter_map
       (fun (e : P.event) ->
         match (e.kind, e.target) with
         | P.Rest, P.Collider c -> Some (Printf.sprintf "rest %d" c)
         | P.Leave, P.Collider c -> Some (Printf.sprintf "leave %d" c)
         | _ -> None)
       (P.events tr));
  Alcotest.(check bool)
    "no grazing impacts" true
    (List.for_all
       (fun (e : P.event) -> e.kind <> P.Bounce || e.speed > 1e-3)
       (P.events tr));
  check_close 1e-9 "ends on the floor" 0.1 (pos tr 20.).y;
  Alcotest.(check bool) "not truncated" false (P.truncated tr)

let placed_at_rest () =
  let b =
    P.body ~name:"ball" ~center:(Vec3.v 0. r 0.) ~velocity:(Vec3.v 0.5 0. 0.) ~radius:r ()
  in
  let tr = P.simulate P.default_world [ floor ] [ b ] ~until:10. in
  Alcotest.(check int) "one rest event" 1 (List.length (P.events tr));
  let p, v = state tr 10. in
  check_close 0. "on the floor" r p.y;
  check_close 1e-12 "sliding without friction" 5. p.x;
  check_close 0. "no vertical speed" 0. v.y

let v_groove () =
  let planes =
    [
      P.Plane { normal = Vec3.v 1. 1. 0.; offset = 0. };
      P.Plane { normal = Vec3.v (-1.) 1. 0.; offset = 0. };
    ]
  in
  let b =
    P.body ~name:"ball" ~center:(Vec3.v 0.3 2. 0.) ~velocity:(Vec3.v 0. 0. 0.5)
      ~radius:0.2 ~restitution:0.6 ()
  in
  let tr = P.simulate P.default_world planes [ b ] ~until:10. in
  Alcotest.(check bool)
    "finitely many events" true
    (List.length (P.events tr) < 100 && not (P.truncated tr));
  let p, v = state tr 10. in
  check_close 1e-9 "in the crease" 0. p.x;
  check_close 1e-9 "touching both planes" (0.2 *. Float.sqrt 2.) p.y;
  check_close 1e-12 "sliding along it" 0.5 v.z;
  check_close 1e-12 "and only along it" 0. (Vec3.length (Vec3.v v.x v.y 0.))

let onto_a_resting_ball () =
  let a = P.body ~name:"a" ~center:(Vec3.v 0. 0.5 0.) ~radius:0.5 ~restitution:0.5 () in
  let b = P.body ~name:"b" ~center:(Vec3.v 0. 3. 0.) ~radius:0.5 ~restitution:0.5 () in
  let tr = P.simulate P.default_world [ floor ] [ a; b ] ~until:1. in
  match List.filter (fun (e : P.event) -> e.target = P.Body "b") (P.events tr) with
  | [] -> Alcotest.fail "no impact"
  | hit :: _ ->
      let va = snd (Option.get (P.sample tr "a" hit.time))
      and vb = snd (Option.get (P.sample tr "b" hit.time)) in
      check_close 1e-12 "impact after a 1.5 m fall" (Float.sqrt (3. /. g)) hit.time;
      check_close 0. "the supported ball does not move" 0. (Vec3.length va);
      check_close 1e-9 "the falling one rebounds with e₁·e₂ of its speed"
        (0.25 *. hit.speed) vb.y

let () =
  let qc = QCheck_alcotest.to_alcotest ~rand in
  Alcotest.run "physics"
    [
      ( "bouncing ball",
        [
          Alcotest.test_case
            "an elastic ball hits the floor at 0.4515 + k·0.9030 s for k up to 100" `Quick
            elastic_impact_times;
          Alcotest.test_case "an elastic ball rises to 1 m after every bounce" `Quick
            elastic_apex_stays;
          Alcotest.test_case
            "a ball with e = 0.8 hits at the closed-form times and apexes" `Quick
            damped_impacts;
          Alcotest.test_case
            "a ball with e = 0.8 comes to rest before 4.0637 s and stays there" `Quick
            damped_comes_to_rest;
        ] );
      ( "fixed step",
        [
          Alcotest.test_case "Verlet is exact in free flight to 1e-10 m over 10 s" `Quick
            verlet_free_flight;
          Alcotest.test_case "Euler drifts by g·dt·t/2 in free flight" `Quick euler_drift;
          Alcotest.test_case "clamping at step end adds energy to a bounce" `Quick
            fixed_step_adds_energy;
        ] );
      ( "contacts",
        [
          Alcotest.test_case
            "a small fast ball tunnels through a thin plate at fixed step, not in exact"
            `Quick tunnelling;
          Alcotest.test_case "edges and corners are hit where the capsule and sphere say"
            `Quick edge_and_corner;
          Alcotest.test_case
            "a head-on elastic collision exchanges velocities and conserves momentum"
            `Quick head_on;
          Alcotest.test_case "a ball placed on the floor stays on it" `Quick
            placed_at_rest;
          Alcotest.test_case
            "a ball dropped into a V groove rests in the crease and slides along it"
            `Quick v_groove;
          Alcotest.test_case
            "a ball falling on a supported ball bounces as off a fixed one" `Quick
            onto_a_resting_ball;
          Alcotest.test_case "a ball resting on a tilted plate slides off its border"
            `Quick resting_on_a_plate_slides_off;
        ] );
      ( "properties",
        [
          qc energy_never_increases;
          qc sample_is_deterministic_and_continuous;
          Alcotest.test_case "the trajectory is identical sampled at any frame rate"
            `Quick any_frame_rate;
        ] );
    ]
