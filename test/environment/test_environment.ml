(* Cameras (orthographic, fisheye, depth of field), spot lights, the gradient background,
   fog and colour-map textures, each checked against its formula in closed form. *)
open Lancer

let v = Vec3.v
let close ?(eps = 1e-12) msg a b = Alcotest.(check (float eps)) msg a b

let check_vec ?(eps = 1e-12) msg (a : Vec3.t) (b : Vec3.t) =
  close ~eps (msg ^ " (x)") a.x b.x;
  close ~eps (msg ^ " (y)") a.y b.y;
  close ~eps (msg ^ " (z)") a.z b.z

let check_color ?(eps = 1e-12) msg (a : Color.t) (b : Color.t) =
  close ~eps (msg ^ " (r)") a.r b.r;
  close ~eps (msg ^ " (g)") a.g b.g;
  close ~eps (msg ^ " (b)") a.b b.b

let floats_equal a b =
  Float.Array.length a = Float.Array.length b
  &&
  let ok = ref true in
  Float.Array.iteri
    (fun i x -> if not (Float.equal x (Float.Array.get b i)) then ok := false)
    a;
  !ok

let matte ?(color = Color.white) ?texture () =
  { Material.default with color; ambient = 0.; diffuse = 1.; texture }

let prim m s = Primitive.make m s
let ok = function Ok x -> x | Error m -> Alcotest.fail m

(* ---- cameras ---- *)

let camera_tests =
  [
    Alcotest.test_case
      "an orthographic camera's rays form the grid of its window, all along f" `Quick
      (fun () ->
        (* From (0, 0, −5) looking at +z: r = +x, u = +y. W = 8, H = 4 (a = 2), width 4:
           the window spans x ∈ [−2, 2] and y ∈ [−1, 1]. *)
        let c = Camera.make ~kind:(Camera.Orthographic { width = 4. }) () in
        for j = 0 to 3 do
          for i = 0 to 7 do
            let x = Float.of_int i +. 0.5 and y = Float.of_int j +. 0.5 in
            let r = Camera.ray c ~width:8 ~height:4 x y in
            let ox = ((2. *. x /. 8.) -. 1.) *. 2.
            and oy = (1. -. (2. *. y /. 4.)) *. 4. /. 4. in
            check_vec
              (Printf.sprintf "origin of pixel (%d, %d)" i j)
              (Ray.origin r) (v ox oy (-5.));
            check_vec
              (Printf.sprintf "direction of pixel (%d, %d)" i j)
              (Ray.dir r) (v 0. 0. 1.)
          done
        done;
        check_vec "the top-left corner"
          (Ray.origin (Camera.ray c ~width:8 ~height:4 0. 0.))
          (v (-2.) 1. (-5.)));
    Alcotest.test_case
      "a 180° fisheye sees ±r and ±u at the edges of its circle, f at its centre" `Quick
      (fun () ->
        let c = Camera.make ~kind:Camera.Fisheye ~fov:180. () in
        let dir x y = Ray.dir (Camera.ray c ~width:100 ~height:60 x y) in
        (* S = 60: the circle has radius 30 pixels around (50, 30). *)
        check_vec "centre" (dir 50. 30.) (v 0. 0. 1.);
        check_vec "right edge" (dir 80. 30.) (v 1. 0. 0.);
        check_vec "left edge" (dir 20. 30.) (v (-1.) 0. 0.);
        check_vec "top edge" (dir 50. 0.) (v 0. 1. 0.);
        check_vec "bottom edge" (dir 50. 60.) (v 0. (-1.) 0.);
        (* Half-way to the right edge: θ = 45°. *)
        check_vec "half-way" (dir 65. 30.) (v (Float.sqrt 0.5) 0. (Float.sqrt 0.5));
        Alcotest.(check bool)
          "the right edge is in view" true
          (Camera.in_view c ~width:100 ~height:60 80. 30.);
        Alcotest.(check bool)
          "just beyond it is not" false
          (Camera.in_view c ~width:100 ~height:60 80.01 30.);
        Alcotest.(check bool)
          "a corner is not" false
          (Camera.in_view c ~width:100 ~height:60 0. 0.));
    Alcotest.test_case "a 360° fisheye looks straight back at the edge of its circle"
      `Quick (fun () ->
        let c = Camera.make ~kind:Camera.Fisheye ~fov:360. () in
        check_vec "edge"
          (Ray.dir (Camera.ray c ~width:40 ~height:40 40. 20.))
          (v 0. 0. (-1.));
        check_vec "half-way: 90° to the side"
          (Ray.dir (Camera.ray c ~width:40 ~height:40 20. 10.))
          (v 0. 1. 0.));
    Alcotest.test_case
      "outside the fisheye's circle a pixel is the background seen along f" `Quick
      (fun () ->
        let sky = { Settings.horizon = Color.v 1. 0.5 0.; zenith = Color.v 0. 0. 1. } in
        let settings =
          { Settings.default with width = 20; height = 10; sky = Some sky }
        in
        let camera =
          Camera.make ~kind:Camera.Fisheye ~fov:180. ~position:(v 0. 0. 0.)
            ~look_at:(v 0. 3. 4.) ()
        in
        let sc = Scene.make_exn ~settings ~camera ~lights:[] [] in
        (* f = (0, 0.6, 0.8): mix(horizon, zenith, 0.6). *)
        let st = Task.create () in
        check_color "corner" (Render.pixel sc st 0 0) (Color.v 0.4 0.2 0.6);
        Alcotest.(check int) "no ray traced for it" 0 st.primary);
    Alcotest.test_case
      "the perspective camera is unchanged: the top edge is fov/2 above the axis" `Quick
      (fun () ->
        let c = Camera.make ~fov:90. () in
        check_vec "top"
          (Ray.dir (Camera.ray c ~width:10 ~height:10 5. 0.))
          (Vec3.normalize (v 0. 1. 1.)));
    Alcotest.test_case "fov limits depend on the kind" `Quick (fun () ->
        let valid c = Result.is_ok (Camera.validate c) in
        Alcotest.(check bool)
          "perspective 180 refused" false
          (valid (Camera.make ~fov:180. ()));
        Alcotest.(check bool)
          "fisheye 360 accepted" true
          (valid (Camera.make ~kind:Camera.Fisheye ~fov:360. ()));
        Alcotest.(check bool)
          "fisheye 361 refused" false
          (valid (Camera.make ~kind:Camera.Fisheye ~fov:361. ()));
        Alcotest.(check bool)
          "orthographic width 0 refused" false
          (valid (Camera.make ~kind:(Camera.Orthographic { width = 0. }) ()));
        Alcotest.(check bool)
          "negative aperture refused" false
          (valid (Camera.make ~aperture:(-1.) ()));
        Alcotest.(check bool)
          "65 lens samples refused" false
          (valid (Camera.make ~aperture:0.1 ~lens_samples:65 ())));
  ]

(* ---- depth of field ---- *)

let dof_scene ?(aperture = 0.3) ?(lens_samples = 3) ?(samples = 1) () =
  let settings = { Settings.default with width = 48; height = 36; samples } in
  let camera =
    Camera.make ~position:(v 0. 1. (-6.)) ~look_at:(v 0. 0.5 0.) ~aperture
      ~focal_distance:6. ~lens_samples ()
  in
  let floor =
    matte
      ~texture:
        (Description.Checker { c1 = Color.white; c2 = Color.v 0.2 0.2 0.2; size = 0.5 })
      ()
  in
  Scene.make_exn ~settings ~camera
    ~lights:[ Light.point ~radius:0.5 ~samples:2 (v (-3.) 5. (-4.)) ]
    [
      prim floor (Shape.plane ~normal:Vec3.y_axis ~offset:0.);
      prim
        (matte ~color:(Color.v 0.9 0.2 0.2) ())
        (Shape.sphere ~center:(v (-1.) 0.6 (-2.)) ~radius:0.6);
      prim
        { Material.default with reflection = 0.6 }
        (Shape.sphere ~center:(v 1. 0.7 2.) ~radius:0.7);
    ]

let dof_tests =
  [
    Alcotest.test_case
      "every lens ray passes through the point focal_distance along the pinhole ray"
      `Quick (fun () ->
        let c =
          Camera.make ~position:(v 1. 2. (-3.)) ~look_at:(v 0. 0. 4.) ~aperture:0.5
            ~focal_distance:7. ~lens_samples:4 ()
        in
        let pin = Camera.ray c ~width:30 ~height:20 7.25 3.75 in
        let focus = Vec3.madd (Ray.origin pin) 7. (Ray.dir pin) in
        for a = 0 to 3 do
          for b = 0 to 3 do
            let lx, ly = Camera.lens_point c a b 0.3 0.7 in
            close ~eps:1e-12 "on the lens disk" 0.
              (Float.max 0. (Float.hypot lx ly -. 0.5));
            let r = Camera.lens_ray c pin lx ly in
            check_vec "starts on the lens" (Ray.origin r)
              (Vec3.madd (Vec3.madd (Ray.origin pin) lx c.r) ly c.u);
            let d = Vec3.length (Vec3.sub focus (Ray.origin r)) in
            check_vec ~eps:1e-9 "reaches the focus" (Ray.at r d) focus
          done
        done);
    Alcotest.test_case
      "lens point (a, b) sits in its stratum: radius A·√((a+u)/n), angle 2π(b+v)/n" `Quick
      (fun () ->
        let c = Camera.make ~aperture:2. ~focal_distance:5. ~lens_samples:4 () in
        let lx, ly = Camera.lens_point c 1 2 0.5 0.25 in
        close "radius" (2. *. Float.sqrt (1.5 /. 4.)) (Float.hypot lx ly);
        close "angle"
          (2. *. Float.pi *. 2.25 /. 4.)
          (Float.atan2 ly lx +. (2. *. Float.pi)));
    Alcotest.test_case "depth of field gives the same bytes on 1, 2 and 3 domains" `Quick
      (fun () ->
        let sc = dof_scene ~samples:2 () in
        let reference, rs = Render.render sc in
        List.iter
          (fun n ->
            let fb, st = Render.with_pool n (fun pool -> Render.render ?pool sc) in
            Alcotest.(check bool)
              (Printf.sprintf "%d domains" n)
              true
              (floats_equal fb.data reference.data);
            Alcotest.(check int)
              (Printf.sprintf "rays on %d domains" n)
              (Counters.total_rays rs) (Counters.total_rays st))
          [ 1; 2; 3 ]);
    Alcotest.test_case "each sample casts lens_samples² primary rays" `Quick (fun () ->
        let _, st = Render.render (dof_scene ~lens_samples:3 ~samples:2 ()) in
        Alcotest.(check int) "primary" (48 * 36 * 4 * 9) st.primary);
    Alcotest.test_case "the ray estimate counts lens_samples² camera rays per sample"
      `Quick (fun () ->
        let c = Cost.estimate (dof_scene ~lens_samples:3 ~samples:2 ()) in
        Alcotest.(check (float 0.)) "primary" (Float.of_int (48 * 36 * 4 * 9)) c.primary;
        let pinhole =
          Cost.estimate (dof_scene ~aperture:0. ~lens_samples:3 ~samples:2 ())
        in
        Alcotest.(check (float 0.))
          "no aperture: no lens rays"
          (Float.of_int (48 * 36 * 4))
          pinhole.primary);
    Alcotest.test_case "the error against a many-sample render falls as lens samples grow"
      `Quick (fun () ->
        let bytes n =
          let fb, _ = Render.render (dof_scene ~lens_samples:n ()) in
          Image.to_bytes Settings.Srgb fb
        in
        let reference = bytes 16 in
        let rmse n =
          match Compare.compare (48, 36, reference) (48, 36, bytes n) with
          | Ok c -> c.rmse
          | Error m -> Alcotest.fail m
        in
        let e1 = rmse 1 and e2 = rmse 2 and e4 = rmse 4 in
        Alcotest.(check bool)
          (Printf.sprintf "1×1 (%.2f) > 2×2 (%.2f) > 4×4 (%.2f)" e1 e2 e4)
          true
          (e1 > e2 && e2 > e4));
  ]

(* ---- spot lights ---- *)

let spot_tests =
  let sp =
    ok (Light.spot ~position:(v 0. 1. 0.) ~point_at:Vec3.zero ~inner:20. ~outer:40.)
  in
  let cosd a = Float.cos (a *. Float.pi /. 180.) in
  [
    Alcotest.test_case
      "the falloff is 1 at inner, 0 at outer and ½ half-way between the cosines" `Quick
      (fun () ->
        close "inside" 1. (Light.spot_factor sp (cosd 10.));
        close "at inner" 1. (Light.spot_factor sp (cosd 20.));
        close "at outer" 0. (Light.spot_factor sp (cosd 40.));
        close "beyond" 0. (Light.spot_factor sp (cosd 90.));
        close "half-way" 0.5 (Light.spot_factor sp (0.5 *. (cosd 20. +. cosd 40.)));
        (* t = 1/4: s = t²(3 − 2t) = 5/32 *)
        close "a quarter of the way from outer" (5. /. 32.)
          (Light.spot_factor sp (cosd 40. +. (0.25 *. (cosd 20. -. cosd 40.)))));
    Alcotest.test_case "a spot above a floor lights it with E times the falloff" `Quick
      (fun () ->
        (* Spot at (0, 1, 0) aimed straight down; a floor point at distance x from the foot
           is at θ = atan x from the axis, with N·L = cos θ and no attenuation. *)
        let light = Light.point ~spot:sp (v 0. 1. 0.) in
        let settings =
          { Settings.default with width = 4; height = 4; ambient = Color.black }
        in
        let sc =
          Scene.make_exn ~settings ~lights:[ light ]
            [ prim (matte ()) (Shape.plane ~normal:Vec3.y_axis ~offset:0.) ]
        in
        let at theta_deg =
          let x = Float.tan (theta_deg *. Float.pi /. 180.) in
          let p = v x 0. 0. in
          let o = v x 1. (-1.) in
          (Shade.trace sc (Task.create ()) (Ray.make o (Vec3.sub p o)) 1).r
        in
        close ~eps:1e-9 "at 10°" (cosd 10.) (at 10.);
        close ~eps:1e-9 "at 20° (inner)" (cosd 20.) (at 20.);
        let th = Float.acos (0.5 *. (cosd 20. +. cosd 40.)) *. 180. /. Float.pi in
        close ~eps:1e-9 "half-way" (0.5 *. cosd th) (at th);
        close ~eps:1e-9 "at 40° (outer)" 0. (at 40.);
        close ~eps:1e-9 "at 60°" 0. (at 60.));
    Alcotest.test_case "outside its cone a spot casts no shadow ray" `Quick (fun () ->
        let light = Light.point ~spot:sp (v 0. 1. 0.) in
        let sc =
          Scene.make_exn ~lights:[ light ]
            [ prim (matte ()) (Shape.plane ~normal:Vec3.y_axis ~offset:0.) ]
        in
        let st = Task.create () in
        ignore (Shade.trace sc st (Ray.make (v 5. 1. (-1.)) (v 0. (-1.) 1.)) 1);
        Alcotest.(check int) "shadow rays" 0 st.shadow);
    Alcotest.test_case "a spot light with a radius has soft shadows and the same cone"
      `Quick (fun () ->
        let soft = Light.point ~spot:sp ~radius:0.2 ~samples:4 (v 0. 1. 0.) in
        Alcotest.(check bool) "area light" true (Light.is_area soft);
        Alcotest.(check bool) "spot" true (Light.is_spot soft);
        let sc =
          Scene.make_exn ~lights:[ soft ]
            [ prim (matte ()) (Shape.plane ~normal:Vec3.y_axis ~offset:0.) ]
        in
        let st = Task.create () in
        let c = Shade.trace sc st (Ray.make (v 0.1 1. (-1.)) (v 0. (-1.) 1.)) 1 in
        Alcotest.(check int) "16 shadow rays" 16 st.shadow;
        close ~eps:1e-9 "unshadowed: as the hard spot" (Float.cos (Float.atan 0.1)) c.r);
    Alcotest.test_case "a spot needs 0 ≤ inner ≤ outer ≤ 180 and a target apart from it"
      `Quick (fun () ->
        let bad inner outer =
          Result.is_error
            (Light.spot ~position:Vec3.zero ~point_at:Vec3.y_axis ~inner ~outer)
        in
        Alcotest.(check bool) "inner > outer" true (bad 30. 20.);
        Alcotest.(check bool) "outer > 180" true (bad 10. 190.);
        Alcotest.(check bool) "negative inner" true (bad (-1.) 10.);
        Alcotest.(check bool) "a hard spot (inner = outer) is fine" false (bad 20. 20.);
        Alcotest.(check bool)
          "point_at = position" true
          (Result.is_error
             (Light.spot ~position:Vec3.zero ~point_at:Vec3.zero ~inner:1. ~outer:2.)));
  ]

(* ---- background gradient and fog ---- *)

let sky = { Settings.horizon = Color.v 0.9 0.8 0.6; zenith = Color.v 0.1 0.3 0.9 }

let environment_tests =
  [
    Alcotest.test_case
      "the gradient is the horizon at and below it, the zenith straight up" `Quick
      (fun () ->
        let s = { Settings.default with sky = Some sky } in
        check_color "horizon" (Settings.background_along s (v 1. 0. 0.)) sky.horizon;
        check_color "below" (Settings.background_along s (v 0. (-1.) 0.)) sky.horizon;
        check_color "zenith" (Settings.background_along s (v 0. 1. 0.)) sky.zenith;
        check_color "D.y = ½"
          (Settings.background_along s (v 0. 0.5 (Float.sqrt 0.75)))
          (Color.v 0.5 0.55 0.75));
    Alcotest.test_case "a ray that misses sees the gradient along its direction" `Quick
      (fun () ->
        let sc =
          Scene.make_exn ~settings:{ Settings.default with sky = Some sky } ~lights:[] []
        in
        check_color "up"
          (Shade.trace sc (Task.create ()) (Ray.make Vec3.zero (v 0. 1. 0.)) 1)
          sky.zenith;
        check_color "level"
          (Shade.trace sc (Task.create ()) (Ray.make Vec3.zero (v 0. 0. 1.)) 1)
          sky.horizon);
    Alcotest.test_case
      "fog keeps e^(−t/D) of a surface t away and adds the rest of its colour" `Quick
      (fun () ->
        (* A white emitting wall 3 units ahead, fog colour (0, 0.5, 1) at D = 2. *)
        let wall =
          { Material.default with color = Color.v 1. 1. 1.; ambient = 1.; diffuse = 0. }
        in
        let fc = Color.v 0. 0.5 1. in
        let settings =
          { Settings.default with fog = Some { color = fc; distance = 2. } }
        in
        let sc =
          Scene.make_exn ~settings ~lights:[]
            [ prim wall (Shape.plane ~normal:(v 0. 0. 1.) ~offset:3.) ]
        in
        let got = Shade.trace sc (Task.create ()) (Ray.make Vec3.zero (v 0. 0. 1.)) 1 in
        let e = Float.exp (-1.5) in
        check_color "fogged" got (Color.v e (e +. (0.5 *. (1. -. e))) 1.));
    Alcotest.test_case "a ray that hits nothing is all fog" `Quick (fun () ->
        let fc = Color.v 0.3 0.4 0.5 in
        let sc =
          Scene.make_exn
            ~settings:
              {
                Settings.default with
                sky = Some sky;
                fog = Some { color = fc; distance = 10. };
              }
            ~lights:[] []
        in
        check_color "miss"
          (Shade.trace sc (Task.create ()) (Ray.make Vec3.zero (v 0. 1. 0.)) 1)
          fc);
    Alcotest.test_case
      "fog applies to each segment of a reflected ray, not to shadow rays" `Quick
      (fun () ->
        (* A mirror 1 unit ahead reflecting straight back into an emitting wall 2 units
           behind the eye: segments of 1 and 3. The wall is lit by nothing but ambient, so
           shadow rays play no part; the mirror's own colour is black. *)
        let d = 4. and fc = Color.v 0.2 0.2 0.2 in
        let mirror = { Material.default with color = Color.black; reflection = 1. } in
        let wall =
          { Material.default with color = Color.white; ambient = 1.; diffuse = 0. }
        in
        let settings =
          { Settings.default with fog = Some { color = fc; distance = d } }
        in
        let sc =
          Scene.make_exn ~settings ~lights:[]
            [
              prim mirror (Shape.plane ~normal:(v 0. 0. 1.) ~offset:1.);
              prim wall (Shape.plane ~normal:(v 0. 0. 1.) ~offset:(-2.));
            ]
        in
        let got =
          (Shade.trace sc (Task.create ()) (Ray.make Vec3.zero (v 0. 0. 1.)) 1).r
        in
        let seg t c =
          (c *. Float.exp (-.t /. d)) +. (0.2 *. (1. -. Float.exp (-.t /. d)))
        in
        close ~eps:1e-9 "two segments" (seg 1. (seg 3. 1.)) got);
  ]

(* ---- colour maps ---- *)

let map_tests =
  let m =
    Texture.color_map
      [
        (0.2, Color.v 1. 0. 0.);
        (0.6, Color.v 0. 0. 1.);
        (0.6, Color.v 0. 1. 0.);
        (1., Color.v 1. 1. 1.);
      ]
  in
  [
    Alcotest.test_case
      "a colour map is linear between the bracketing entries, constant beyond the ends"
      `Quick (fun () ->
        check_color "below the first" (Texture.lookup m 0.1) (Color.v 1. 0. 0.);
        check_color "at the first" (Texture.lookup m 0.2) (Color.v 1. 0. 0.);
        check_color "a quarter" (Texture.lookup m 0.3) (Color.v 0.75 0. 0.25);
        check_color "a step: the later entry at its t" (Texture.lookup m 0.6)
          (Color.v 0. 1. 0.);
        check_color "after the step" (Texture.lookup m 0.8) (Color.v 0.5 1. 0.5));
    Alcotest.test_case "gradient takes the fractional part of P·axis" `Quick (fun () ->
        let tex = Description.Gradient { axis = v 0. 2. 0.; map = m } in
        check_color "P·axis = 0.6"
          (Texture.eval tex (v 5. 0.3 0.) 0. 0.)
          (Color.v 0. 1. 0.);
        check_color "P·axis = 2.3"
          (Texture.eval tex (v 0. 1.15 0.) 0. 0.)
          (Color.v 0.75 0. 0.25);
        check_color "P·axis = −0.7 → 0.3"
          (Texture.eval tex (v 0. (-0.35) 0.) 0. 0.)
          (Color.v 0.75 0. 0.25));
    Alcotest.test_case
      "a colour map on marble, wood or noise replaces the mix of its two colours" `Quick
      (fun () ->
        (* With the map black → white, the mapped texture is the two-colour one with
           c1 = black and c2 = white, at every point. *)
        let bw = Texture.color_map [ (0., Color.black); (1., Color.white) ] in
        List.iter
          (fun (name, pattern, two) ->
            for k = 0 to 20 do
              let p =
                v
                  (0.37 *. Float.of_int k)
                  (0.11 *. Float.of_int k)
                  (-0.23 *. Float.of_int k)
              in
              check_color
                (Printf.sprintf "%s at point %d" name k)
                (Texture.eval (Description.Mapped { pattern; map = bw }) p 0. 0.)
                (Texture.eval two p 0. 0.)
            done)
          [
            ( "marble",
              Description.Marble_pattern 0.7,
              Description.Marble { c1 = Color.black; c2 = Color.white; scale = 0.7 } );
            ( "wood",
              Description.Wood_pattern 0.3,
              Description.Wood { c1 = Color.black; c2 = Color.white; scale = 0.3 } );
            ( "noise",
              Description.Noise_pattern 0.5,
              Description.Noise { c1 = Color.black; c2 = Color.white; scale = 0.5 } );
          ]);
    Alcotest.test_case "entries out of order or outside [0, 1] are refused" `Quick
      (fun () ->
        Alcotest.(check bool)
          "decreasing" true
          (Option.is_some
             (Description.color_map_problem [ (0.5, Color.white); (0.4, Color.black) ]));
        Alcotest.(check bool)
          "t > 1" true
          (Option.is_some (Description.color_map_problem [ (1.5, Color.white) ]));
        Alcotest.(check bool)
          "empty" true
          (Option.is_some (Description.color_map_problem [])));
  ]

(* ---- features ---- *)

let feature_tests =
  [
    Alcotest.test_case "a scene says which of the new features it uses" `Quick (fun () ->
        let plain = Scene.make_exn ~lights:[ Light.point Vec3.zero ] [] in
        let f = plain.features in
        Alcotest.(check (list bool))
          "none in a plain scene"
          [ false; false; false; false; false; false; false ]
          [
            f.orthographic;
            f.fisheye;
            f.depth_of_field;
            f.spot_lights;
            f.sky;
            f.fog;
            f.color_maps;
          ];
        let tex =
          Description.Gradient
            { axis = Vec3.y_axis; map = Texture.color_map [ (0., Color.white) ] }
        in
        let sc =
          Scene.make_exn
            ~settings:
              {
                Settings.default with
                sky = Some sky;
                fog = Some { color = Color.white; distance = 1. };
              }
            ~camera:
              (Camera.make ~kind:Camera.Fisheye ~fov:200. ~aperture:0.1 ~focal_distance:3.
                 ())
            ~lights:
              [
                Light.point
                  ~spot:
                    (ok
                       (Light.spot ~position:Vec3.zero ~point_at:Vec3.y_axis ~inner:1.
                          ~outer:2.))
                  Vec3.zero;
              ]
            [ prim (matte ~texture:tex ()) (Shape.sphere ~center:Vec3.zero ~radius:1.) ]
        in
        let f = sc.features in
        Alcotest.(check (list bool))
          "all but orthographic"
          [ false; true; true; true; true; true; true ]
          [
            f.orthographic;
            f.fisheye;
            f.depth_of_field;
            f.spot_lights;
            f.sky;
            f.fog;
            f.color_maps;
          ]);
  ]

let () =
  Alcotest.run "environment"
    [
      ("cameras", camera_tests);
      ("depth of field", dof_tests);
      ("spot lights", spot_tests);
      ("background and fog", environment_tests);
      ("colour maps", map_tests);
      ("features", feature_tests);
    ]
