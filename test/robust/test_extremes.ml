(* Numerical stability at the extremes, where test/core and test/geometry stop: grazing
   rays at 1e-12 rad on every flat primitive, rays lying in a plane through the camera,
   lit spheres of radius 1e-6 to 1e6 seen from close by (self-shadowing), the hall of
   mirrors at depth 1, 2, 64 and 1000 against its closed form, and samples that come out
   NaN or infinite. *)
open Lancer

let v = Vec3.v
let inf = Float.infinity

let rel msg ~tol expected got =
  if not (Float.abs (got -. expected) <= tol *. Float.abs expected) then
    Alcotest.failf "%s: expected %.17g, got %.17g (relative tolerance %g)" msg expected
      got tol

let check_color ?(eps = 1e-12) msg (a : Color.t) (b : Color.t) =
  if
    not
      (Float.abs (a.r -. b.r) <= eps
      && Float.abs (a.g -. b.g) <= eps
      && Float.abs (a.b -. b.b) <= eps)
  then
    Alcotest.failf "%s: expected (%.17g, %.17g, %.17g), got (%.17g, %.17g, %.17g)" msg a.r
      a.g a.b b.r b.g b.b

let mat ?(color = Color.white) ?(ambient = 0.1) ?(diffuse = 0.9) ?(specular = 0.)
    ?(reflection = 0.) () =
  { Material.default with color; ambient; diffuse; specular; reflection }

let prim m s = Primitive.make m s
let case name f = Alcotest.test_case name `Quick f

(* ---- grazing rays at 1e-12 rad ---- *)

(* From 1 above the plane z = 0, descending at 1e-12 rad along +x: the hit is at t ≈ 1e12,
   P ≈ (1e12, 0, 0). Each flat primitive is made large enough to contain that point. *)
let grazing_tests =
  let r = Ray.make_raw (v 0. 0. 1.) (v 1. 0. (-1e-12)) in
  let big = 1e13 in
  let shapes =
    [
      ( "triangle",
        Shape.triangle ~a:(v (-.big) (-.big) 0.) ~b:(v big (-.big) 0.) ~c:(v 0. big 0.) );
      ( "parallelogram",
        Shape.parallelogram ~origin:(v (-.big) (-.big) 0.)
          ~edge1:(v (2. *. big) 0. 0.)
          ~edge2:(v 0. (2. *. big) 0.) );
      ("disk", Shape.disk ~center:Vec3.zero ~normal:Vec3.z_axis ~radius:big);
      ("box", Shape.box ~min:(v (-.big) (-.big) (-1.)) ~max:(v big big 0.));
      ("plane", Shape.plane ~normal:Vec3.z_axis ~offset:0.);
    ]
  in
  List.map
    (fun (name, s) ->
      case (Printf.sprintf "a ray grazing a %s at 1e-12 rad hits it 1e12 away" name)
        (fun () ->
          let t = Shape.intersect s r 0. inf in
          rel name ~tol:1e-6 1e12 t;
          let n = Shape.normal s (Ray.at r t) in
          rel (name ^ " normal") ~tol:1e-12 1. (Float.abs n.z)))
    shapes
  @ [
      case "a grazing hit 1e12 away is lit, not shadowed by its own surface, and finite"
        (fun () ->
          (* Ambient 0.1 + diffuse 0.9 under a light straight above: 1 exactly, unless the
             shadow ray starts below the floor (an offset that does not grow with |P|). *)
          let sc =
            Scene.make_exn
              ~lights:[ Light.directional (v 0. 0. (-1.)) ]
              [ prim (mat ()) (Shape.plane ~normal:Vec3.z_axis ~offset:0.) ]
          in
          let st = Task.create () in
          check_color ~eps:1e-9 "lit floor" Color.white (Shade.trace sc st r 1);
          Alcotest.(check int) "one shadow ray" 1 st.shadow);
      case "a camera lying in a floor plane sees no NaN along the horizon row" (fun () ->
          (* H odd: the middle row's rays have a zero vertical component and start on the
             plane, the 0/0 case of doc/reference/numerics.md. *)
          let settings =
            { Settings.default with width = 9; height = 5; background = Color.v 0. 0. 1. }
          in
          let sc =
            Scene.make_exn ~settings
              ~camera:(Camera.make ~position:Vec3.zero ~look_at:(v 0. 0. 1.) ())
              ~lights:[ Light.directional (v 0. (-1.) 0.) ]
              [ prim (mat ()) (Shape.plane ~normal:Vec3.y_axis ~offset:0.) ]
          in
          let fb, st = Render.render sc in
          Alcotest.(check int) "no bad samples" 0 st.bad_samples;
          Alcotest.(check bool)
            "every value finite" true
            (Float.Array.for_all Float.is_finite fb.data);
          for i = 0 to 8 do
            check_color
              (Printf.sprintf "horizon pixel %d is background" i)
              settings.background (Framebuffer.get fb i 2)
          done);
    ]

(* ---- spheres from 1e-6 to 1e6 ---- *)

let sphere_tests =
  let planet r =
    (* A camera 0.5·r above the top of a sphere of radius r, looking down at it, a light
       from behind the camera: every visible point is lit, and no shadow ray may find
       the sphere it leaves. Rendering with shadows on and off must then give the same
       framebuffer; hit points rounded inside the sphere and started off it by too small
       an offset would come out shadowed. *)
    case
      (Printf.sprintf
         "a sphere of radius %g seen from 0.5·r above is lit, not self-shadowed" r)
      (fun () ->
        let settings = { Settings.default with width = 15; height = 15 } in
        let make shadows =
          Scene.make_exn ~settings:{ settings with shadows }
            ~camera:
              (Camera.make
                 ~position:(v 0. (1.5 *. r) 0.)
                 ~look_at:Vec3.zero ~up:Vec3.z_axis ~fov:60. ())
            ~lights:[ Light.directional (v 0.1 (-1.) 0.2) ]
            [ prim (mat ()) (Shape.sphere ~center:Vec3.zero ~radius:r) ]
        in
        let lit, st = Render.render (make true)
        and unshadowed, _ = Render.render (make false) in
        Alcotest.(check int) "no bad samples" 0 st.bad_samples;
        for j = 0 to 14 do
          for i = 0 to 14 do
            check_color ~eps:0.
              (Printf.sprintf "pixel %d,%d" i j)
              (Framebuffer.get unshadowed i j)
              (Framebuffer.get lit i j)
          done
        done;
        (* The centre pixel sees the top, N = (0, 1, 0): ambient + diffuse·N·L. *)
        let k = 0.1 +. (0.9 /. Float.sqrt 1.05) in
        check_color ~eps:1e-9 "centre pixel" (Color.v k k k) (Framebuffer.get lit 7 7))
  in
  [
    case
      "a sphere of radius 1e6 is hit at 2e6 and 4e6 from 3e6 away, and at 1e6 from its \
       centre" (fun () ->
        let s = Shape.sphere ~center:(v 0. 0. 3e6) ~radius:1e6 in
        let r = Ray.make Vec3.zero Vec3.z_axis in
        rel "near" ~tol:1e-15 2e6 (Shape.intersect s r 0. inf);
        rel "far" ~tol:1e-15 4e6 (Shape.intersect s r 2e6 inf);
        rel "inside" ~tol:1e-15 1e6
          (Shape.intersect s (Ray.make (v 0. 0. 3e6) Vec3.x_axis) 0. inf));
    case "a sphere of radius 1e-6 is hit from 1e6 away at 1e6 ∓ 1e-6 (to 1e-9)" (fun () ->
        let s = Shape.sphere ~center:(v 0. 0. 1e6) ~radius:1e-6 in
        let r = Ray.make Vec3.zero Vec3.z_axis in
        Alcotest.(check (float 1e-9)) "near" (1e6 -. 1e-6) (Shape.intersect s r 0. inf));
    planet 1e-6;
    planet 1.;
    planet 1e6;
    planet 1e12;
  ]

(* ---- depth: the hall of mirrors in closed form ---- *)

(* Two parallel mirrors (reflection ρ, ambient a, no lights), a ray perpendicular to them:
   every hit adds (1 − ρ)·a and passes ρ on, and the ray at the depth limit reflects black,
   so the colour is a·(1 − ρ^d) after d hits and d − 1 reflected rays. *)
let mirrors_tests =
  let hall depth =
    case
      (Printf.sprintf
         "depth %d: two facing mirrors give a·(1 − ρ^%d) with %d reflected rays" depth
         depth (depth - 1))
      (fun () ->
        let rho = 0.9 and a = 0.5 in
        let m = mat ~color:(Color.v a a a) ~ambient:1. ~diffuse:0. ~reflection:rho () in
        let sc =
          Scene.make_exn
            ~settings:
              {
                Settings.default with
                width = 1;
                height = 1;
                depth;
                background = Color.white;
              }
            ~lights:[]
            [
              prim m (Shape.plane ~normal:Vec3.z_axis ~offset:1.);
              prim m (Shape.plane ~normal:Vec3.z_axis ~offset:(-1.));
            ]
        in
        let st = Task.create () in
        let got = Shade.trace sc st (Ray.make Vec3.zero Vec3.z_axis) 1 in
        let expected = a *. (1. -. Float.pow rho (Float.of_int depth)) in
        check_color ~eps:1e-12 "colour" (Color.v expected expected expected) got;
        Alcotest.(check int) "reflected rays" (depth - 1) st.reflected)
  in
  [ hall 1; hall 2; hall 64; hall 1000 ]

(* ---- NaN and infinite samples ---- *)

(* A floor filling the frame whose colour times the light's overflows: diffuse is +∞ and
   the specular term 0·∞ is NaN, in every sample. *)
let overflowing_scene ?(samples = 1) () =
  let settings =
    {
      Settings.default with
      width = 5;
      height = 4;
      samples;
      background = Color.v 0. 1. 0.;
    }
  in
  Scene.make_exn ~settings
    ~camera:
      (Camera.make ~position:(v 0. 1. 0.) ~look_at:Vec3.zero ~up:Vec3.z_axis ~fov:30. ())
    ~lights:
      [
        Light.directional ~intensity:1e300 ~color:(Color.v 1e300 1e300 1e300)
          (v 0. (-1.) 0.);
      ]
    [
      prim
        (mat ~color:(Color.v 1e300 1e300 1e300) ())
        (Shape.plane ~normal:Vec3.y_axis ~offset:0.);
    ]

let nan_tests =
  [
    case "every NaN or infinite sample is counted and replaced by the background"
      (fun () ->
        List.iter
          (fun samples ->
            let sc = overflowing_scene ~samples () in
            let fb, st = Render.render sc in
            Alcotest.(check int)
              (Printf.sprintf "bad samples at %d×%d" samples samples)
              (5 * 4 * samples * samples)
              st.bad_samples;
            Alcotest.(check bool)
              "a first bad pixel is named" true
              (match st.first_bad with
              | Some (i, j) -> i >= 0 && i < 5 && j >= 0 && j < 4
              | None -> false);
            for j = 0 to 3 do
              for i = 0 to 4 do
                check_color
                  (Printf.sprintf "pixel %d,%d" i j)
                  sc.settings.background (Framebuffer.get fb i j)
              done
            done)
          [ 1; 3 ]);
    case "the bad-sample count does not depend on the number of domains" (fun () ->
        let sc = overflowing_scene ~samples:2 () in
        let _, a = Render.render sc in
        let _, b = Render.with_pool 3 (fun pool -> Render.render ?pool sc) in
        Alcotest.(check int) "count" a.bad_samples b.bad_samples);
    case "an ordinary scene has no bad samples" (fun () ->
        (* Guards the two tests above against a counter that counts everything. *)
        let sc =
          Scene.make_exn
            ~settings:{ Settings.default with width = 5; height = 4 }
            ~camera:
              (Camera.make ~position:(v 0. 1. 0.) ~look_at:Vec3.zero ~up:Vec3.z_axis
                 ~fov:30. ())
            ~lights:[ Light.directional (v 0. (-1.) 0.) ]
            [ prim (mat ()) (Shape.plane ~normal:Vec3.y_axis ~offset:0.) ]
        in
        let _, st = Render.render sc in
        Alcotest.(check int) "none" 0 st.bad_samples);
  ]

let () =
  Alcotest.run "extremes"
    [
      ("grazing", grazing_tests);
      ("spheres", sphere_tests);
      ("depth", mirrors_tests);
      ("samples", nan_tests);
    ]
