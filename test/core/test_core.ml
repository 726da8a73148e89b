(* Unit and analytic tests of the Whitted core: answers known in closed form, checked
   before encoding where the shading model is concerned. *)
open Lancer

let v = Vec3.v

(* Float.Array.equal is OCaml 5.4 only; bitwise equality of two framebuffers. *)
let floats_equal a b =
  Float.Array.length a = Float.Array.length b
  &&
  let ok = ref true in
  Float.Array.iteri
    (fun i x -> if not (Float.equal x (Float.Array.get b i)) then ok := false)
    a;
  !ok

let close ?(eps = 1e-12) msg a b = Alcotest.(check (float eps)) msg a b

let check_color ?(eps = 1e-12) msg (a : Color.t) (b : Color.t) =
  close ~eps (msg ^ " (r)") a.r b.r;
  close ~eps (msg ^ " (g)") a.g b.g;
  close ~eps (msg ^ " (b)") a.b b.b

let check_vec ?(eps = 1e-12) msg (a : Vec3.t) (b : Vec3.t) =
  close ~eps (msg ^ " (x)") a.x b.x;
  close ~eps (msg ^ " (y)") a.y b.y;
  close ~eps (msg ^ " (z)") a.z b.z

let mat ?(color = Color.white) ?(ambient = 0.1) ?(diffuse = 0.9) ?(specular = 0.)
    ?(shininess = 50.) ?(reflection = 0.) ?(transparency = 0.) ?(ior = 1.)
    ?(fresnel = false) ?texture () =
  {
    Material.default with
    color;
    ambient;
    diffuse;
    specular;
    shininess;
    reflection;
    transparency;
    ior;
    fresnel;
    texture;
  }

let prim ?transform m s = Primitive.make ?transform m s

(* ---- vectors ---- *)

let vec_tests =
  [
    Alcotest.test_case
      "Floats.min and Floats.max are Float.min and Float.max, bit for bit" `Quick
      (fun () ->
        let st = Random.State.make [| 7 |] in
        let special =
          [
            0.;
            -0.;
            1.;
            -1.;
            Float.nan;
            -.Float.nan;
            Float.infinity;
            Float.neg_infinity;
            Float.min_float;
            Float.epsilon;
            1e-300;
            5e-324;
          ]
        in
        let randoms = List.init 200 (fun _ -> Random.State.float st 4. -. 2.) in
        let values = special @ randoms in
        let bits = Int64.bits_of_float in
        List.iter
          (fun x ->
            List.iter
              (fun y ->
                let same a b =
                  Int64.equal (bits a) (bits b) || (Float.is_nan a && Float.is_nan b)
                in
                if
                  not
                    (same (Floats.min x y) (Float.min x y)
                    && same (Floats.max x y) (Float.max x y))
                then Alcotest.failf "min/max of %h and %h" x y)
              values)
          values);
    Alcotest.test_case "Floats.above is succ or the float after it" `Quick (fun () ->
        let st = Random.State.make [| 11 |] in
        let bits = Int64.bits_of_float in
        let same a b =
          Int64.equal (bits a) (bits b) || (Float.is_nan a && Float.is_nan b)
        in
        let special =
          [
            0.;
            -0.;
            1.;
            2.;
            0.5;
            -1.;
            Float.nan;
            Float.infinity;
            Float.neg_infinity;
            Float.min_float;
            Float.pred Float.min_float;
            5e-324;
            Float.max_float;
            Float.pred Float.max_float;
            Float.pred 2.;
            Float.succ 1.;
          ]
        in
        let randoms =
          List.init 2000 (fun _ ->
              Float.ldexp
                (1. +. Random.State.float st 1.)
                (Random.State.int st 2000 - 1000))
        in
        List.iter
          (fun t ->
            let a = Floats.above t in
            let ok =
              if t > 0. && t >= Float.min_float && t < Float.infinity then
                a >= Float.succ t && (a <= Float.succ (Float.succ t) || a = Float.infinity)
              else same a (Float.succ t)
            in
            if not ok then Alcotest.failf "above %h is %h" t a)
          (special @ randoms));
    Alcotest.test_case "cross product follows x × y = z" `Quick (fun () ->
        check_vec "x×y" (Vec3.cross Vec3.x_axis Vec3.y_axis) Vec3.z_axis);
    Alcotest.test_case "normalize keeps the zero vector zero, never NaN" `Quick (fun () ->
        check_vec "zero" (Vec3.normalize Vec3.zero) Vec3.zero);
    Alcotest.test_case "length does not overflow at 1e200" `Quick (fun () ->
        close ~eps:1e188 "len" (Vec3.length (v 3e200 4e200 0.)) 5e200);
    Alcotest.test_case "length does not underflow at 1e-200" `Quick (fun () ->
        close ~eps:1e-212 "len" (Vec3.length (v 3e-200 4e-200 0.)) 5e-200);
  ]

(* ---- transforms ---- *)

let transform_tests =
  [
    Alcotest.test_case "rotating x by 90° about y gives −z (left-handed, as POV-Ray)"
      `Quick (fun () ->
        check_vec "p"
          (Transform.point (Transform.rotate (v 0. 90. 0.)) Vec3.x_axis)
          (v 0. 0. (-1.)));
    Alcotest.test_case "transforms apply in the order written" `Quick (fun () ->
        let t =
          Transform.then_
            (Transform.translate (v 1. 0. 0.))
            (Transform.scale (v 2. 2. 2.))
        in
        check_vec "p" (Transform.point t Vec3.zero) (v 2. 0. 0.));
    Alcotest.test_case "inverse undoes a composite transform" `Quick (fun () ->
        let t =
          Transform.then_
            (Transform.rotate (v 10. 20. 30.))
            (Transform.then_
               (Transform.scale (v 1. 2. 3.))
               (Transform.translate (v 4. 5. 6.)))
        in
        let p = v 0.3 (-1.2) 7. in
        check_vec ~eps:1e-12 "p" (Transform.inv_point t (Transform.point t p)) p);
    Alcotest.test_case "normals go through the inverse transpose" `Quick (fun () ->
        (* A plane y = x, squashed by 2 along x: the normal must stay perpendicular. *)
        let t = Transform.scale (v 2. 1. 1.) in
        let n = Transform.normal t (Vec3.normalize (v 1. (-1.) 0.)) in
        let tangent = Transform.vector t (v 1. 1. 0.) in
        close ~eps:1e-15 "n·t" (Vec3.dot n tangent) 0.);
  ]

(* ---- camera ---- *)

let camera_tests =
  [
    Alcotest.test_case "the centre of an odd image looks straight ahead" `Quick (fun () ->
        let c = Camera.make () in
        let r = Camera.ray c ~width:11 ~height:11 5.5 5.5 in
        check_vec "dir" (Ray.dir r) Vec3.z_axis);
    Alcotest.test_case "the top edge of the image is fov/2 above the axis" `Quick
      (fun () ->
        let c = Camera.make ~fov:90. () in
        let d = Ray.dir (Camera.ray c ~width:10 ~height:10 5. 0.) in
        close ~eps:1e-12 "45°" (Float.atan2 d.y d.z) (Float.pi /. 4.));
    Alcotest.test_case "image x grows to the right (+x) for the default camera" `Quick
      (fun () ->
        let c = Camera.make () in
        let d = Ray.dir (Camera.ray c ~width:640 ~height:480 640. 240.) in
        Alcotest.(check bool) "right" true (d.x > 0.);
        close ~eps:1e-12 "aspect" (d.x /. d.z) (Float.tan (Float.pi /. 6.) *. 640. /. 480.));
  ]

(* ---- encoding ---- *)

let encode_tests =
  let e = Image.encode_channel Settings.Srgb in
  [
    Alcotest.test_case "sRGB encodes the breakpoints of doc/reference/shading.md" `Quick
      (fun () ->
        Alcotest.(check int) "0" 0 (e 0.);
        Alcotest.(check int) "1" 255 (e 1.);
        (* 12.92 · 0.0031308 = 0.04045 → ⌊10.31 + 0.5⌋ *)
        Alcotest.(check int) "linear segment end" 10 (e 0.0031308);
        Alcotest.(check int) "just above" 10 (e 0.0031309);
        Alcotest.(check int) "0.5" 188 (e 0.5);
        Alcotest.(check int) "0.2140 → 127" 127 (e 0.2140);
        Alcotest.(check int) "0.2159 → 128" 128 (e 0.2159));
    Alcotest.test_case "values outside [0, 1] and NaN are clamped" `Quick (fun () ->
        Alcotest.(check int) "neg" 0 (e (-3.));
        Alcotest.(check int) "big" 255 (e 7.);
        Alcotest.(check int) "inf" 255 (e Float.infinity);
        Alcotest.(check int) "nan" 0 (e Float.nan));
    Alcotest.test_case "a numeric gamma encodes v^(1/g)" `Quick (fun () ->
        Alcotest.(check int)
          "0.5 at 2.2" 186
          (Image.encode_channel (Settings.Power 2.2) 0.5);
        Alcotest.(check int) "gamma 1" 128 (Image.encode_channel (Settings.Power 1.) 0.5));
  ]

(* ---- shading, in closed form ---- *)

(* Camera at (0,0,−5) looking at +z; an 11×11 image has its centre pixel on the axis. *)
let small = { Settings.default with width = 11; height = 11 }
let centre_ray () = Camera.ray Camera.default ~width:11 ~height:11 5.5 5.5

let lambert_tests =
  [
    Alcotest.test_case "a Lambert sphere under a head-on light matches the formula" `Quick
      (fun () ->
        let c = Color.v 1. 0.5 0.25 in
        let m = mat ~color:c ~ambient:0.1 ~diffuse:0.9 () in
        let light =
          Light.point ~intensity:2. ~attenuation:(v 1. 0.1 0.01) (v 0. 0. (-10.))
        in
        let sc =
          Scene.make_exn ~settings:small ~lights:[ light ]
            [ prim m (Shape.sphere ~center:Vec3.zero ~radius:1.) ]
        in
        let got = Shade.trace sc (Task.create ()) (centre_ray ()) 1 in
        (* P = (0,0,−1), N·L = 1, d = 9, att = 1/(1 + 0.9 + 0.81) *)
        let att = 1. /. (1. +. 0.9 +. 0.81) in
        let k = 0.1 +. (0.9 *. 2. *. att) in
        check_color ~eps:1e-12 "colour" got (Color.scale k c));
    Alcotest.test_case "light at an angle scales diffuse by the cosine" `Quick (fun () ->
        let m = mat ~ambient:0. ~diffuse:1. () in
        let sc =
          Scene.make_exn ~settings:small
            ~lights:[ Light.directional (v 1. 0. 1.) ]
            [ prim m (Shape.sphere ~center:Vec3.zero ~radius:1.) ]
        in
        let got = Shade.trace sc (Task.create ()) (centre_ray ()) 1 in
        check_color ~eps:1e-12 "cos 45°" got (Color.scale (Float.sqrt 0.5) Color.white));
    Alcotest.test_case "a light behind the surface contributes nothing" `Quick (fun () ->
        let m = mat ~ambient:0.2 () in
        let sc =
          Scene.make_exn ~settings:small
            ~lights:[ Light.point (v 0. 0. 10.) ]
            [ prim m (Shape.sphere ~center:Vec3.zero ~radius:1.) ]
        in
        check_color "ambient only"
          (Shade.trace sc (Task.create ()) (centre_ray ()) 1)
          (Color.scale 0.2 Color.white));
    Alcotest.test_case "Phong highlight adds specular · (R·V)^n · E, uncoloured" `Quick
      (fun () ->
        let m =
          mat ~color:(Color.v 1. 0. 0.) ~ambient:0. ~diffuse:0. ~specular:0.5
            ~shininess:10. ()
        in
        let sc =
          Scene.make_exn ~settings:small
            ~lights:[ Light.point (v 0. 0. (-10.)) ]
            [ prim m (Shape.sphere ~center:Vec3.zero ~radius:1.) ]
        in
        check_color ~eps:1e-12 "white highlight"
          (Shade.trace sc (Task.create ()) (centre_ray ()) 1)
          (Color.scale 0.5 Color.white));
    Alcotest.test_case
      "shininess 0: max(0, R·V)^0 = 1, so specular · E even where R·V < 0" `Quick
      (fun () ->
        (* A floor seen at 45° (V = (0, 1, −1)/√2), lit from in front of the camera
           (L = (0, 1, −3)/√10): R = (0, 1, 3)/√10 and R·V = −2/√20 < 0. *)
        let m = mat ~ambient:0. ~diffuse:0. ~specular:0.5 ~shininess:0. () in
        let camera = Camera.make ~position:(v 0. 1. (-1.)) ~look_at:Vec3.zero () in
        let sc =
          Scene.make_exn ~settings:small ~camera
            ~lights:[ Light.directional (v 0. (-1.) 3.) ]
            [ prim m (Shape.plane ~normal:(v 0. 1. 0.) ~offset:0.) ]
        in
        let ray = Camera.ray camera ~width:11 ~height:11 5.5 5.5 in
        check_color ~eps:1e-12 "specular · E"
          (Shade.trace sc (Task.create ()) ray 1)
          (Color.scale 0.5 Color.white));
    Alcotest.test_case "an opaque object between surface and light casts a full shadow"
      `Quick (fun () ->
        let m = mat ~ambient:0.1 () in
        let sc =
          Scene.make_exn ~settings:small
            ~lights:[ Light.point (v 0. 0. (-10.)) ]
            [
              prim m (Shape.sphere ~center:Vec3.zero ~radius:1.);
              prim m (Shape.sphere ~center:(v 0. 0. (-7.)) ~radius:0.5);
            ]
        in
        (* The camera at z = −5 is between the blocker (z = −7) and the sphere. *)
        check_color "ambient"
          (Shade.trace sc (Task.create ()) (centre_ray ()) 1)
          (Color.scale 0.1 Color.white));
    Alcotest.test_case "shadows: false ignores blockers" `Quick (fun () ->
        let m = mat ~ambient:0. ~diffuse:1. () in
        let sc =
          Scene.make_exn
            ~settings:{ small with shadows = false }
            ~lights:[ Light.point (v 0. 0. (-10.)) ]
            [
              prim m (Shape.sphere ~center:Vec3.zero ~radius:1.);
              prim m (Shape.sphere ~center:(v 0. 0. (-7.)) ~radius:0.5);
            ]
        in
        check_color "lit" (Shade.trace sc (Task.create ()) (centre_ray ()) 1) Color.white);
    Alcotest.test_case "a transparent blocker transmits (τ·C) once per surface crossed"
      `Quick (fun () ->
        let m = mat ~ambient:0. ~diffuse:1. () in
        let glass = mat ~color:(Color.v 1. 0.5 0.5) ~transparency:0.5 ~ior:1. () in
        let sc =
          Scene.make_exn ~settings:small
            ~lights:[ Light.point (v 0. 0. (-10.)) ]
            [
              prim m (Shape.sphere ~center:Vec3.zero ~radius:1.);
              prim glass (Shape.sphere ~center:(v 0. 0. (-7.)) ~radius:0.5);
            ]
        in
        (* Two crossings of the glass sphere: (0.5·C)² *)
        check_color ~eps:1e-12 "filtered"
          (Shade.trace sc (Task.create ()) (centre_ray ()) 1)
          (Color.v 0.25 0.0625 0.0625));
    Alcotest.test_case "a ray that hits nothing returns the background" `Quick (fun () ->
        let bg = Color.v 0.1 0.2 0.3 in
        let sc = Scene.make_exn ~settings:{ small with background = bg } ~lights:[] [] in
        check_color "bg" (Shade.trace sc (Task.create ()) (centre_ray ()) 1) bg);
  ]

let mirror_floor ?(depth = 5) ?(bg = Color.v 0.2 0.4 0.6) reflection =
  let m = mat ~ambient:1. ~diffuse:0. ~reflection () in
  Scene.make_exn
    ~settings:{ small with depth; background = bg }
    ~lights:[]
    [ prim m (Shape.plane ~normal:Vec3.y_axis ~offset:(-1.)) ]

let down_ray () = Ray.make (v 0. 0. 0.) (v 0. (-1.) 1.)

let reflection_tests =
  [
    Alcotest.test_case "a mirror mixes (1 − r)·local with r·(reflected colour)" `Quick
      (fun () ->
        let bg = Color.v 0.2 0.4 0.6 in
        let sc = mirror_floor 0.25 in
        let got = Shade.trace sc (Task.create ()) (down_ray ()) 1 in
        check_color ~eps:1e-12 "mix" got
          (Color.add (Color.scale 0.75 Color.white) (Color.scale 0.25 bg)));
    Alcotest.test_case "at the depth limit the reflection contributes black" `Quick
      (fun () ->
        let sc = mirror_floor ~depth:1 0.25 in
        check_color ~eps:1e-12 "no bounce"
          (Shade.trace sc (Task.create ()) (down_ray ()) 1)
          (Color.scale 0.75 Color.white));
    Alcotest.test_case "reflect mirrors the direction about the normal" `Quick (fun () ->
        check_vec "r" (Shade.reflect (v 1. (-1.) 0.) Vec3.y_axis) (v 1. 1. 0.));
  ]

let deg x = x *. Float.pi /. 180.

let refraction_tests =
  let dir_at a = v (Float.sin (deg a)) (-.Float.cos (deg a)) 0. in
  [
    Alcotest.test_case "a slab returns a ray parallel to the incident one" `Quick
      (fun () ->
        let d = dir_at 30. in
        let inside = Option.get (Shade.refract d Vec3.y_axis (1. /. 1.5)) in
        close ~eps:1e-12 "Snell" (Float.sin (deg 30.) /. inside.x) 1.5;
        let out = Option.get (Shade.refract inside Vec3.y_axis 1.5) in
        check_vec ~eps:1e-12 "out" out d);
    Alcotest.test_case "total internal reflection starts past 41.8103149° for ior 1.5"
      `Quick (fun () ->
        (* Leaving glass: the ray travels upward inside, normal faces it. *)
        let leaving a =
          Shade.refract (v (Float.sin (deg a)) (Float.cos (deg a)) 0.) (v 0. (-1.) 0.) 1.5
        in
        Alcotest.(check bool) "41.81° refracts" true (Option.is_some (leaving 41.81));
        Alcotest.(check bool) "41.811° reflects" true (Option.is_none (leaving 41.811)));
    Alcotest.test_case "past the critical angle transparency joins reflection" `Quick
      (fun () ->
        (* Inside a glass half-space y < 0 looking up at 60°: all light is reflected. *)
        let bg = Color.v 0.3 0.3 0.3 in
        let glass = mat ~ambient:0. ~diffuse:0. ~transparency:1. ~ior:1.5 () in
        let sc =
          Scene.make_exn
            ~settings:{ small with background = bg }
            ~lights:[]
            [ prim glass (Shape.plane ~normal:Vec3.y_axis ~offset:0.) ]
        in
        let r =
          Ray.make (v 0. (-1.) 0.) (v (Float.sin (deg 60.)) (Float.cos (deg 60.)) 0.)
        in
        let st = Task.create () in
        check_color ~eps:1e-12 "bg via reflection" (Shade.trace sc st r 1) bg;
        Alcotest.(check int) "no refracted ray" 0 st.refracted;
        Alcotest.(check int) "one reflected ray" 1 st.reflected);
    Alcotest.test_case "ior 1 neither bends nor darkens" `Quick (fun () ->
        let bg = Color.v 0.3 0.5 0.7 in
        let glass = mat ~ambient:0. ~diffuse:0. ~transparency:1. ~ior:1. () in
        let sc =
          Scene.make_exn
            ~settings:{ small with background = bg }
            ~lights:[]
            [ prim glass (Shape.sphere ~center:Vec3.zero ~radius:1.) ]
        in
        check_color ~eps:1e-12 "bg" (Shade.trace sc (Task.create ()) (centre_ray ()) 1) bg);
    Alcotest.test_case "Schlick Fresnel with ior 1.5 reflects F0 = 0.04 head-on" `Quick
      (fun () ->
        let bg = Color.v 1. 1. 1. in
        let black_floor = mat ~color:Color.black ~ambient:0. ~diffuse:0. () in
        let glass =
          mat ~ambient:0. ~diffuse:0. ~transparency:1. ~ior:1.5 ~fresnel:true ()
        in
        (* A glass plane at y = 0 above a black plane at y = −1: looking straight down,
           only the 4 % reflected towards the white sky comes back. *)
        let sc =
          Scene.make_exn
            ~settings:{ small with background = bg; depth = 2 }
            ~lights:[]
            [
              prim glass (Shape.plane ~normal:Vec3.y_axis ~offset:0.);
              prim black_floor (Shape.plane ~normal:Vec3.y_axis ~offset:(-1.));
            ]
        in
        let r = Ray.make (v 0. 1. 0.) (v 0. (-1.) 0.) in
        check_color ~eps:1e-12 "F0"
          (Shade.trace sc (Task.create ()) r 1)
          (Color.scale 0.04 Color.white));
  ]

(* ---- textures ---- *)

let texture_tests =
  [
    Alcotest.test_case "a floor lying on a checker boundary takes the cell below it"
      `Quick (fun () ->
        let c1 = Color.v 1. 0. 0. and c2 = Color.v 0. 0. 1. in
        let m =
          mat ~ambient:1. ~diffuse:0.
            ~texture:(Description.Checker { c1; c2; size = 1. })
            ()
        in
        let sc =
          Scene.make_exn ~settings:small ~lights:[]
            [ prim m (Shape.plane ~normal:Vec3.y_axis ~offset:0.) ]
        in
        (* Hit at (0.5, 0, 0.5): ⌊0.5⌋ + ⌊−δ⌋ + ⌊0.5⌋ = −1, odd → c2. *)
        let r = Ray.make (v 0.5 1. 0.5) (v 0. (-1.) 0.) in
        check_color "c2" (Shade.trace sc (Task.create ()) r 1) c2;
        let r = Ray.make (v 1.5 1. 0.5) (v 0. (-1.) 0.) in
        check_color "c1" (Shade.trace sc (Task.create ()) r 1) c1);
  ]

(* ---- images and files ---- *)

let tmpdir () =
  let d =
    Filename.concat
      (Filename.get_temp_dir_name ())
      (Printf.sprintf "lancer-test-%d-%d" (Unix.getpid ()) (Random.bits ()))
  in
  Unix.mkdir d 0o755;
  d

let gradient () =
  let fb = Framebuffer.create 7 5 in
  for j = 0 to 4 do
    for i = 0 to 6 do
      Framebuffer.set fb i j (Color.v (Float.of_int i /. 6.) (Float.of_int j /. 4.) 0.5)
    done
  done;
  fb

let file_tests =
  [
    Alcotest.test_case "PNG and PPM round-trip the encoded bytes" `Quick (fun () ->
        let d = tmpdir () in
        let fb = gradient () in
        let bytes = Image.to_bytes Settings.Srgb fb in
        List.iter
          (fun ext ->
            let p = Filename.concat d ("img" ^ ext) in
            Alcotest.(check (result unit string)) "write" (Ok ()) (Image.save p fb);
            match Image.read_rgb8 p with
            | Ok (w, h, b) ->
                Alcotest.(check (pair int int)) "size" (7, 5) (w, h);
                Alcotest.(check bool) ("bytes " ^ ext) true (Bytes.equal b bytes)
            | Error e -> Alcotest.fail e)
          [ ".png"; ".ppm" ]);
    Alcotest.test_case "an unwritable path is an error and leaves no file" `Quick
      (fun () ->
        let d = tmpdir () in
        let p = Filename.concat (Filename.concat d "missing-dir") "x.png" in
        (match Image.save p (gradient ()) with
        | Ok () -> Alcotest.fail "wrote"
        | Error _ -> ());
        Alcotest.(check (array string)) "nothing left" [||] (Sys.readdir d));
    Alcotest.test_case "an output path that is a directory is refused" `Quick (fun () ->
        let d = tmpdir () in
        let p = Filename.concat d "dir.png" in
        Unix.mkdir p 0o755;
        match Image.save p (gradient ()) with
        | Ok () -> Alcotest.fail "wrote"
        | Error _ -> ());
    Alcotest.test_case "a failed write leaves the previous file intact" `Quick (fun () ->
        let d = tmpdir () in
        let p = Filename.concat d "keep.ppm" in
        Alcotest.(check (result unit string)) "write" (Ok ()) (Image.save p (gradient ()));
        let before = In_channel.with_open_bin p In_channel.input_all in
        (match Image.write_atomic p (fun _ -> failwith "disk full") with
        | Ok () -> Alcotest.fail "ok"
        | Error _ -> ());
        Alcotest.(check string)
          "unchanged" before
          (In_channel.with_open_bin p In_channel.input_all);
        Alcotest.(check int) "no temp file" 1 (Array.length (Sys.readdir d)));
    Alcotest.test_case "unknown extensions are refused" `Quick (fun () ->
        Alcotest.(check bool) "jpg" true (Result.is_error (Image.format_of_path "a.jpg")));
  ]

(* ---- rendering ---- *)

let demo_scene ?(settings = { Settings.default with width = 64; height = 48 })
    ?(tinted = false) () =
  let floor =
    mat
      ~texture:
        (Description.Checker { c1 = Color.white; c2 = Color.v 0.2 0.2 0.2; size = 1. })
      ()
  in
  Scene.make_exn ~settings
    ~camera:(Camera.make ~position:(v 0. 2. (-6.)) ~look_at:(v 0. 0.5 0.) ())
    ~lights:
      [
        Light.point ~radius:0.5 ~samples:3 (v (-3.) 5. (-4.));
        Light.directional ~intensity:0.3 (v 1. (-1.) 1.);
      ]
    [
      prim floor (Shape.plane ~normal:Vec3.y_axis ~offset:0.);
      prim
        (mat ~color:(Color.v 0.9 0.2 0.2) ~specular:0.5 ())
        (Shape.sphere ~center:(v (-1.5) 1. 0.) ~radius:1.);
      prim
        (if tinted then
           {
             (mat ~color:(Color.v 1. 0.77 0.34) ~reflection:0.8 ~specular:0.8 ()) with
             metallic = 1.;
           }
         else mat ~reflection:0.8 ())
        (Shape.sphere ~center:(v 0.8 0.7 1.) ~radius:0.7);
      prim
        (if tinted then
           {
             (mat ~color:(Color.v 1. 0.2 0.15) ~transparency:0.9 ~ior:1.5 ~fresnel:true ())
             with
             filter = 1.;
           }
         else mat ~transparency:0.9 ~ior:1.5 ~fresnel:true ())
        (Shape.sphere ~center:(v 1. 0.5 (-1.5)) ~radius:0.5);
    ]

(* A scene with a bounding volume hierarchy (more than 8 bounded objects, some of them
   transformed), a sky, fog and a spot light: the other paths of the tracer. *)
let bvh_scene () =
  let spot =
    Result.get_ok
      (Light.spot ~position:(v 0. 6. (-2.)) ~point_at:Vec3.zero ~inner:20. ~outer:35.)
  in
  let shapes =
    List.init 12 (fun k ->
        let x = Float.of_int (k mod 4) -. 1.5 and z = Float.of_int (k / 4) in
        let c = v x 0.4 z in
        let m =
          match k mod 3 with
          | 0 -> mat ~specular:0.4 ~color:(Color.v 0.8 0.3 0.2) ()
          | 1 -> mat ~reflection:0.5 ()
          | _ -> mat ~transparency:0.7 ~ior:1.3 ()
        in
        if k mod 2 = 0 then prim m (Shape.sphere ~center:c ~radius:0.35)
        else
          prim
            ~transform:
              (Transform.then_ (Transform.rotate (v 0. 30. 0.)) (Transform.translate c))
            m
            (Shape.box ~min:(v (-0.3) (-0.3) (-0.3)) ~max:(v 0.3 0.3 0.3)))
  in
  Scene.make_exn
    ~settings:
      {
        Settings.default with
        width = 96;
        height = 72;
        sky = Some { horizon = Color.v 0.8 0.8 0.9; zenith = Color.v 0.2 0.3 0.7 };
        fog = Some { color = Color.v 0.5 0.5 0.5; distance = 30. };
      }
    ~camera:(Camera.make ~position:(v 0. 2. (-5.)) ~look_at:(v 0. 0.3 1.) ())
    ~lights:
      [ Light.point ~spot (v 0. 6. (-2.)); Light.point ~intensity:0.5 (v 3. 4. (-3.)) ]
    (prim (mat ()) (Shape.plane ~normal:Vec3.y_axis ~offset:0.) :: shapes)

(* Minor words per ray of a render on this domain (after one to warm the caches). *)
let words_per_ray sc =
  ignore (Render.render sc);
  let w0 = Gc.minor_words () in
  let _, st = Render.render sc in
  (Gc.minor_words () -. w0) /. Float.of_int (Counters.total_rays st)

let render_tests =
  [
    (* Glass spheres along a shadow ray, given in a shuffled order so that the hierarchy
       visits them in another: the product is that of their factors in the order of t,
       to the bit (floating-point products depend on their order), whether the ray
       crosses a few (20 crossings) or many (80). *)
    Alcotest.test_case "a shadow ray's transmittance multiplies its crossings in t order"
      `Quick (fun () ->
        List.iter
          (fun n ->
            let st = Random.State.make [| n |] in
            let spheres =
              List.init n (fun k ->
                  let c =
                    Color.v
                      (0.5 +. Random.State.float st 0.5)
                      (0.5 +. Random.State.float st 0.5)
                      (0.5 +. Random.State.float st 0.5)
                  in
                  (k, c, 0.6 +. Random.State.float st 0.4))
            in
            let shuffled =
              List.map snd
                (List.sort compare
                   (List.map (fun x -> (Random.State.bits st, x)) spheres))
            in
            let prims =
              List.map
                (fun (k, color, transparency) ->
                  prim
                    (mat ~color ~transparency ~ior:1.2 ())
                    (Shape.sphere
                       ~center:(Vec3.v 0. 0. (2. *. Float.of_int k))
                       ~radius:0.5))
                shuffled
            in
            let sc = Scene.make_exn ~lights:[ Light.point (Vec3.v 0. 0. 1e3) ] prims in
            let t =
              Shade.transmittance sc (Task.create ()) (Vec3.v 0. 0. (-5.)) Vec3.z_axis 1e3
            in
            (* Two crossings a sphere, the spheres in order of z. *)
            let expected =
              List.fold_left
                (fun (r, g, b) (_, (c : Color.t), tau) ->
                  let fr = tau *. c.r and fg = tau *. c.g and fb = tau *. c.b in
                  (r *. fr *. fr, g *. fg *. fg, b *. fb *. fb))
                (1., 1., 1.) spheres
            in
            let er, eg, eb = expected in
            let bits = Int64.bits_of_float in
            if
              not
                (Int64.equal (bits t.r) (bits er)
                && Int64.equal (bits t.g) (bits eg)
                && Int64.equal (bits t.b) (bits eb))
            then
              Alcotest.failf "%d spheres: (%h, %h, %h), expected (%h, %h, %h)" n t.r t.g
                t.b er eg eb)
          [ 10; 40 ]);
    (* The counters of the tiles are made side by side and two domains render neighbouring
       tiles: a record shorter than its counters plus two cache lines (128 bytes: processors fetch
       lines in pairs) would put
       two tiles' counters, written at every ray, in one line that the cores pass back
       and forth (two domains were then no faster than one on a mirror scene). *)
    Alcotest.test_case "a task's counters are a cache line apart from the next task's"
      `Quick (fun () ->
        let counters = 9 and lines = 128 / (Sys.word_size / 8) in
        Alcotest.(check bool)
          "counters, then two lines of padding" true
          (Obj.size (Obj.repr (Task.create ())) >= counters + lines));
    Alcotest.test_case
      "1, 2, 3 and 4 domains give identical framebuffers (jitter and soft shadows on)"
      `Slow (fun () ->
        let settings =
          { Settings.default with width = 70; height = 45; samples = 2; jitter = true }
        in
        let sc = demo_scene ~settings () in
        let reference, _ = Render.render sc in
        List.iter
          (fun n ->
            let fb, _ = Render.with_pool n (fun pool -> Render.render ?pool sc) in
            Alcotest.(check bool)
              (Printf.sprintf "%d domains" n)
              true
              (floats_equal fb.data reference.data))
          [ 1; 2; 3; 4 ]);
    Alcotest.test_case
      "one sample per k×k block: the full image's middle pixels, on any number of domains"
      `Quick (fun () ->
        let settings =
          { Settings.default with width = 70; height = 45; samples = 2; jitter = true }
        in
        let sc = demo_scene ~settings () in
        let full, _ = Render.render sc in
        List.iter
          (fun k ->
            let cw = (70 + k - 1) / k and ch = (45 + k - 1) / k in
            List.iter
              (fun n ->
                let fb, st =
                  Render.with_pool n (fun pool -> Render.render ?pool ~stride:k sc)
                in
                let name = Printf.sprintf "%d×%d blocks, %d domains" k k n in
                Alcotest.(check (pair int int)) name (cw, ch) (fb.width, fb.height);
                for j = 0 to ch - 1 do
                  for i = 0 to cw - 1 do
                    let x = min 69 ((i * k) + (k / 2))
                    and y = min 44 ((j * k) + (k / 2)) in
                    let a = Framebuffer.get fb i j and b = Framebuffer.get full x y in
                    if not (a.r = b.r && a.g = b.g && a.b = b.b) then
                      Alcotest.failf "%s: pixel %d,%d is not the image's %d,%d" name i j x
                        y
                  done
                done;
                Alcotest.(check int)
                  (name ^ ": one pixel's samples per block")
                  (cw * ch * 4)
                  st.primary)
              [ 1; 2 ])
          [ 1; 2; 8; 64 ]);
    Alcotest.test_case "ray counts do not depend on the number of domains" `Quick
      (fun () ->
        let sc = demo_scene () in
        let _, a = Render.render sc in
        let _, b = Render.with_pool 2 (fun pool -> Render.render ?pool sc) in
        Alcotest.(check int) "rays" (Counters.total_rays a) (Counters.total_rays b);
        Alcotest.(check int) "primary" (64 * 48) a.primary);
    Alcotest.test_case "n×n supersampling averages the sub-pixel centres" `Quick
      (fun () ->
        let sc =
          demo_scene
            ~settings:{ Settings.default with width = 8; height = 6; samples = 2 }
            ()
        in
        let st = Task.create () in
        let got = Render.pixel sc st 3 2 in
        let one x y =
          Shade.trace sc (Task.create ()) (Camera.ray sc.camera ~width:8 ~height:6 x y) 1
        in
        let expect =
          Color.scale 0.25
            (Color.add
               (Color.add (one 3.25 2.25) (one 3.75 2.25))
               (Color.add (one 3.25 2.75) (one 3.75 2.75)))
        in
        check_color ~eps:1e-15 "mean" got expect;
        Alcotest.(check int) "4 primary rays" 4 st.primary);
    Alcotest.test_case "adaptive sampling refines only where the 2×2 samples differ"
      `Quick (fun () ->
        let sc =
          demo_scene
            ~settings:{ Settings.default with width = 32; height = 24; adaptive = 0.2 }
            ()
        in
        let _, st = Render.render sc in
        Alcotest.(check bool)
          "more than 4 per pixel somewhere" true
          (st.primary > 4 * 32 * 24);
        (* 4 samples everywhere, 16 more in each refined pixel: fewer than half refine. *)
        Alcotest.(check bool) "most pixels stay at 4" true (st.primary < (4 + 8) * 32 * 24));
    Alcotest.test_case
      "tracing allocates next to nothing: a render's minor words are a fraction of its \
       rays"
      `Quick (fun () ->
        (* Every minor collection stops all domains: what a ray allocates is what limits
           many cores. What remains is per tile (counters, scratch), not per ray. *)
        List.iter
          (fun (name, sc) ->
            let w = words_per_ray sc in
            if not (w < 0.25) then Alcotest.failf "%s: %.2f minor words per ray" name w)
          [
            ( "reflection, refraction, soft shadows, adaptive sampling",
              demo_scene
                ~settings:
                  { Settings.default with width = 64; height = 48; adaptive = 0.1 }
                () );
            ("a hierarchy, transformed boxes, sky, fog and a spot", bvh_scene ());
            ("a tinted metal and a coloured glass", demo_scene ~tinted:true ());
          ]);
    Alcotest.test_case
      "a scene made only of opaque, matte objects casts no secondary rays" `Quick
      (fun () ->
        let sc =
          Scene.make_exn ~settings:small
            ~lights:[ Light.point (v 0. 5. (-5.)) ]
            [ prim (mat ()) (Shape.sphere ~center:Vec3.zero ~radius:1.) ]
        in
        Alcotest.(check bool) "no reflection feature" false sc.features.reflection;
        let _, st = Render.render sc in
        Alcotest.(check int) "reflected" 0 st.reflected;
        Alcotest.(check int) "refracted" 0 st.refracted);
  ]

let validation_tests =
  [
    Alcotest.test_case "reflection + transparency above 1 is refused" `Quick (fun () ->
        let m = mat ~reflection:0.6 ~transparency:0.6 () in
        Alcotest.(check bool)
          "error" true
          (Result.is_error
             (Scene.make ~lights:[]
                [ prim m (Shape.sphere ~center:Vec3.zero ~radius:1.) ])));
    Alcotest.test_case
      "the first invalid material is reported, after many sharing a valid one, and a CSG \
       leaf's too"
      `Quick (fun () ->
        let ok = mat () and bad_ior = mat ~ior:(-1.) () in
        let bad_sum = mat ~reflection:0.6 ~transparency:0.6 () in
        let ball m = prim m (Shape.sphere ~center:Vec3.zero ~radius:1.) in
        let error objs =
          match Scene.make ~lights:[] objs with Ok _ -> None | Error e -> Some e
        in
        let message m =
          match Description.validate_material m with Ok () -> "" | Error e -> e
        in
        Alcotest.(check (option string))
          "all valid" None
          (error (List.init 1000 (fun _ -> ball ok)));
        Alcotest.(check (option string))
          "the first of two invalid ones, after a thousand valid ones"
          (Some (message bad_ior))
          (error (List.init 1000 (fun _ -> ball ok) @ [ ball bad_ior; ball bad_sum ]));
        Alcotest.(check (option string))
          "a valid one equal to an invalid one is still checked"
          (Some (message bad_sum))
          (error [ ball ok; ball { ok with ior = 2. }; ball ok; ball bad_sum ]);
        let lens =
          Primitive.make ~leaf_materials:[| None; Some bad_sum |] ok
            (Shape.csg Intersection
               [
                 ( Shape.sphere ~center:(Vec3.v 0. 0. (-0.5)) ~radius:1.,
                   Transform.identity );
                 (Shape.sphere ~center:(Vec3.v 0. 0. 0.5) ~radius:1., Transform.identity);
               ])
        in
        Alcotest.(check (option string))
          "a CSG leaf's"
          (Some (message bad_sum))
          (error [ ball ok; lens; ball bad_ior ]));
    Alcotest.test_case "a camera looking at itself is refused" `Quick (fun () ->
        Alcotest.(check bool)
          "error" true
          (Result.is_error
             (Scene.make
                ~camera:(Camera.make ~position:Vec3.zero ~look_at:Vec3.zero ())
                ~lights:[] [])));
    Alcotest.test_case "an absurd image size is refused before allocating" `Quick
      (fun () ->
        Alcotest.(check bool)
          "error" true
          (Result.is_error
             (Scene.make
                ~settings:{ Settings.default with width = 100_000; height = 100_000 }
                ~lights:[] [])));
  ]

(* ---- scale invariance (doc/reference/numerics.md) ---- *)

(* The demo scene with every length multiplied by [k]: positions, radii, plane offsets,
   checker size, area-light radius; attenuation coefficients rescaled so that
   att(k·d) = att(d). *)
let scaled_parts ?(shift = Vec3.zero) k =
  let floor =
    mat
      ~texture:
        (Description.Checker { c1 = Color.white; c2 = Color.v 0.2 0.2 0.2; size = k })
      ()
  in
  let p x y z = Vec3.add shift (v (k *. x) (k *. y) (k *. z)) in
  ( Camera.make ~position:(p 0. 2. (-6.)) ~look_at:(p 0. 0.5 0.) (),
    [
      Light.point ~radius:(0.5 *. k) ~samples:3
        ~attenuation:(v 1. (0.05 /. k) (0.01 /. (k *. k)))
        (p (-3.) 5. (-4.));
      Light.directional ~intensity:0.3 (v 1. (-1.) 1.);
    ],
    [
      prim floor (Shape.plane ~normal:Vec3.y_axis ~offset:shift.y);
      prim
        (mat ~color:(Color.v 0.9 0.2 0.2) ~specular:0.5 ())
        (Shape.sphere ~center:(p (-1.5) 1. 0.) ~radius:k);
      prim (mat ~reflection:0.8 ())
        (Shape.sphere ~center:(p 0.8 0.7 1.) ~radius:(0.7 *. k));
      prim
        (mat ~transparency:0.9 ~ior:1.5 ~fresnel:true ())
        (Shape.sphere ~center:(p 1. 0.5 (-1.5)) ~radius:(0.5 *. k));
      prim
        (mat ~color:(Color.v 0.2 0.9 0.3) ())
        (Shape.sphere ~center:(p (-0.2) 0.25 (-1.2)) ~radius:(0.25 *. k));
    ] )

let scaled_scene ?shift k =
  let camera, lights, prims = scaled_parts ?shift k in
  Scene.make_exn
    ~settings:{ Settings.default with width = 64; height = 48 }
    ~camera ~lights prims

let encoded sc =
  let fb, _ = Render.render sc in
  Image.to_bytes Settings.Srgb fb

let scale_tests =
  let reference = lazy (encoded (scaled_scene 1.)) in
  let bit_identical k =
    Alcotest.test_case
      (Printf.sprintf "scaling the scene by %g gives a bit-identical framebuffer" k)
      `Quick (fun () ->
        let a, _ = Render.render (scaled_scene 1.)
        and b, _ = Render.render (scaled_scene k) in
        Alcotest.(check bool) "identical" true (floats_equal a.data b.data))
  in
  let within k =
    Alcotest.test_case
      (Printf.sprintf
         "scaling the scene by %g moves no pixel by more than 1/255 (but a few edge \
          pixels)"
         k) `Quick (fun () ->
        let a = Lazy.force reference and b = encoded (scaled_scene k) in
        match Compare.compare ~threshold:1 (64, 48, a) (64, 48, b) with
        | Error m -> Alcotest.fail m
        | Ok c ->
            Alcotest.(check bool) (Format.asprintf "%a" Compare.pp c) true (c.over <= 3))
  in
  let translated =
    Alcotest.test_case
      "translating the scene by 1e6 moves no pixel by more than 1/255 (but a few edge \
       pixels)"
      `Quick (fun () ->
        (* At 1e6 the offset δ is 1e-3 scene units: shadow and silhouette edges move by that
           much, which flips a handful of 1-sample edge pixels (8 of 3072 when measured). *)
        let a = Lazy.force reference
        and b = encoded (scaled_scene ~shift:(v 1e6 1e6 (-1e6)) 1.) in
        match Compare.compare ~threshold:1 (64, 48, a) (64, 48, b) with
        | Error m -> Alcotest.fail m
        | Ok c ->
            Alcotest.(check bool)
              (Format.asprintf "%a" Compare.pp c)
              true
              (c.over <= 12 && c.rmse < 1.))
  in
  [
    translated;
    bit_identical 0x1p20;
    bit_identical 0x1p-20;
    within 1e3;
    within 1e-3;
    within 1e6;
    within 1e-6;
  ]

(* The scene of [scaled_scene] with a transformed ellipsoid and box and a textured sphere
   besides, at 320×240, moved by [shift] as a whole. *)
let far_scene shift =
  let camera, lights, prims = scaled_parts ~shift 1. in
  let p x y z = Vec3.add shift (v x y z) in
  let extra =
    [
      prim
        ~transform:
          (Transform.then_
             (Transform.scale (v 0.6 0.3 0.4))
             (Transform.translate (p 1.9 0.3 0.2)))
        (mat ~color:(Color.v 0.3 0.3 0.9) ~specular:0.4 ())
        (Shape.sphere ~center:Vec3.zero ~radius:1.);
      prim
        ~transform:
          (Transform.then_
             (Transform.rotate (v 0. 35. 0.))
             (Transform.translate (p (-2.6) 0.4 1.5)))
        (mat
           ~texture:
             (Description.Stripes
                { c1 = Color.v 0.9 0.8 0.1; c2 = Color.v 0.1 0.3 0.6; size = 0.1 })
           ())
        (Shape.box ~min:(v (-0.4) (-0.4) (-0.4)) ~max:(v 0.4 0.4 0.4));
      prim
        (mat
           ~texture:
             (Description.Checker { c1 = Color.white; c2 = Color.black; size = 0.25 })
           ())
        (Shape.sphere ~center:(p 0.3 1.6 2.5) ~radius:0.6);
    ]
  in
  Scene.make_exn
    ~settings:{ Settings.default with width = 320; height = 240 }
    ~camera ~lights (prims @ extra)

let far_tests =
  let reference = lazy (encoded (far_scene Vec3.zero)) in
  let moved d share =
    Alcotest.test_case
      (Printf.sprintf "moved by %g, at most %g%% of the pixels differ by more than 2/255"
         d (100. *. share))
      `Quick
      (fun () ->
        let sc = far_scene (v d d (-.d)) in
        Alcotest.(check bool)
          "rendered near the camera" true
          (Vec3.max_abs sc.view.position < 1e5);
        let a = Lazy.force reference and b = encoded sc in
        match Compare.compare ~threshold:2 (320, 240, a) (320, 240, b) with
        | Error m -> Alcotest.fail m
        | Ok c ->
            Alcotest.(check bool)
              (Format.asprintf "%a" Compare.pp c)
              true (c.over_share <= share))
  in
  [
    moved 1e6 1e-4;
    moved 1e9 1e-3;
    Alcotest.test_case "moved by 1e9, the alpha channel is the one at the origin" `Quick
      (fun () ->
        let alpha sc =
          let a = Float.Array.make (320 * 240) 0. in
          ignore (Render.render ~alpha:a sc);
          a
        in
        let a = alpha (far_scene Vec3.zero)
        and b = alpha (far_scene (v 1e9 1e9 (-1e9))) in
        let differ = ref 0 in
        Float.Array.iteri
          (fun k x -> if Float.abs (x -. Float.Array.get b k) > 0.01 then incr differ)
          a;
        if !differ > 8 then
          Alcotest.failf "%d of %d pixels have another alpha" !differ (320 * 240));
    Alcotest.test_case "a camera near the origin moves nothing" `Quick (fun () ->
        let sc = far_scene (v 300. (-500.) 1000.) in
        Alcotest.(check bool) "origin" true (Vec3.max_abs sc.origin = 0.));
  ]

(* A lancer-mpi rank renders an image unit by unit, thousands of calls of a few tiles:
   each must cost about its pixels, not a new list of every tile of the image (a rank of a
   4096² still grew to 2.8 times the image from those lists). *)
let unit_tests =
  [
    Alcotest.test_case
      "rendering a few tiles of a large image allocates no list of all its tiles" `Quick
      (fun () ->
        let sc =
          Scene.make_exn
            ~settings:{ Settings.default with width = 4096; height = 4096 }
            ~lights:[] []
        in
        let fb = Framebuffer.create 64 64 in
        (* Tiles 0 and 1 lie inside a 64×64 framebuffer's first rows. *)
        ignore (Render.render_tiles sc fb [| 0; 1 |]);
        let before = (Gc.quick_stat ()).major_words in
        for _ = 1 to 10 do
          ignore (Render.render_tiles sc fb [| 0; 1 |])
        done;
        let per_call = ((Gc.quick_stat ()).major_words -. before) /. 10. in
        (* The tile list of a 4096² image is 16 384 tuples: about 98 000 words. *)
        Alcotest.(check bool)
          (Printf.sprintf "%.0f major words per call" per_call)
          true (per_call < 5000.));
    Alcotest.test_case
      "a tile found by arithmetic is the tile of the grid, clipped to the region" `Quick
      (fun () ->
        (* The definition: the 32×32 grid of the image (8×8 of a strided one), row-major,
           keeping the tiles that meet the region, clipped to it. *)
        let grid ?(t = 32) w h =
          List.concat
            (List.init
               ((h + t - 1) / t)
               (fun ty ->
                 List.init
                   ((w + t - 1) / t)
                   (fun tx ->
                     (tx * t, ty * t, min w ((tx + 1) * t), min h ((ty + 1) * t)))))
        in
        let expected w h (region : Image.region option) =
          match region with
          | None -> grid w h
          | Some r ->
              List.filter_map
                (fun (x0, y0, x1, y1) ->
                  let x0 = max x0 r.x0 and y0 = max y0 r.y0 in
                  let x1 = min x1 r.x1 and y1 = min y1 r.y1 in
                  if x0 < x1 && y0 < y1 then Some (x0, y0, x1, y1) else None)
                (grid w h)
        in
        List.iter
          (fun (w, h) ->
            let sc =
              Scene.make_exn
                ~settings:{ Settings.default with width = w; height = h }
                ~lights:[] []
            in
            let regions =
              None
              :: List.map
                   (fun (x0, y0, x1, y1) -> Some { Image.x0; y0; x1; y1 })
                   [
                     (0, 0, w, h);
                     (1, 1, 2, 2);
                     (31, 31, 33, 33);
                     (32, 0, min w 64, h);
                     (w / 3, h / 5, w - (w / 4), h);
                     (w - 1, h - 1, w, h);
                   ]
            in
            List.iter
              (fun region ->
                let want = expected w h region in
                let name = Printf.sprintf "%d×%d" w h in
                Alcotest.(check int)
                  (name ^ ": count") (List.length want)
                  (Render.tile_count ?region sc);
                Alcotest.(check (list (pair (pair int int) (pair int int))))
                  name
                  (List.map (fun (a, b, c, d) -> ((a, b), (c, d))) want)
                  (List.map
                     (fun (a, b, c, d) -> ((a, b), (c, d)))
                     (Array.to_list (Render.tiles ?region sc))))
              regions;
            (* Strided: the 8×8 grid of the ⌈w/k⌉×⌈h/k⌉ image. *)
            let k = 3 in
            let want = grid ~t:8 ((w + k - 1) / k) ((h + k - 1) / k) in
            Alcotest.(check int)
              (Printf.sprintf "%d×%d by %d" w h k)
              (List.length want)
              (Render.tile_count ~stride:k sc);
            Alcotest.(check (list (pair (pair int int) (pair int int))))
              (Printf.sprintf "%d×%d by %d: tiles" w h k)
              (List.map (fun (a, b, c, d) -> ((a, b), (c, d))) want)
              (List.map
                 (fun (a, b, c, d) -> ((a, b), (c, d)))
                 (Array.to_list (Render.tiles ~stride:k sc))))
          [ (1, 1); (31, 33); (32, 32); (33, 65); (100, 70); (640, 480) ]);
  ]

let () =
  Alcotest.run "core"
    [
      ("vec3", vec_tests);
      ("transform", transform_tests);
      ("camera", camera_tests);
      ("encode", encode_tests);
      ("lambert", lambert_tests);
      ("reflection", reflection_tests);
      ("refraction", refraction_tests);
      ("texture", texture_tests);
      ("files", file_tests);
      ("render", render_tests);
      ("validation", validation_tests);
      ("scale", scale_tests);
      ("far from the origin", far_tests);
      ("render units", unit_tests);
    ]
