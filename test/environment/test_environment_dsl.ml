(* The scene language's cameras, spot lights, background gradient, fog and colour maps:
   what each field builds, and the located message for each mistake. *)
open Lancer
module Dsl = Lancer_dsl.Dsl
module Error = Lancer_dsl.Error

let errors_text es = String.concat "" (List.map Error.to_string es)

let scene text =
  match Program.load_string ~filename:"test.rts" text with
  | Error es -> Alcotest.failf "unexpected errors:\n%s" (errors_text es)
  | Ok p -> (
      match Program.scene_at p ~time:0. ~frame:0 with
      | Ok s -> s
      | Error es -> Alcotest.failf "unexpected errors:\n%s" (errors_text es))

let contains s sub =
  let n = String.length sub and m = String.length s in
  let rec go i = i + n <= m && (String.sub s i n = sub || go (i + 1)) in
  go 0

(* Line and column (from 1) of the first occurrence of [marker] in [text]. *)
let place text marker =
  let n = String.length marker in
  let rec find i = if String.sub text i n = marker then i else find (i + 1) in
  let i = find 0 in
  let line = ref 1 and bol = ref 0 in
  String.iteri
    (fun k c ->
      if k < i && c = '\n' then (
        incr line;
        bol := k + 1))
    text;
  (!line, i - !bol + 1)

(* The error of [text] must contain [sub] and sit where [at] first occurs in [text]. *)
let check_err ?at text sub =
  let at = Option.map (place text) at in
  match Dsl.load_string ~filename:"test.rts" text with
  | Ok _ -> Alcotest.failf "expected an error for:\n%s" text
  | Error es -> (
      match List.find_opt (fun (e : Error.t) -> contains e.message sub) es with
      | None ->
          Alcotest.failf "expected an error containing %S, got:\n%s" sub (errors_text es)
      | Some e -> (
          match at with
          | Some (l, c) ->
              Alcotest.(check (pair int int))
                ("place of: " ^ e.message) (l, c) (e.line, e.col)
          | None -> ()))

let close msg a b = Alcotest.(check (float 1e-12)) msg a b

let color_eq (a : Color.t) (b : Color.t) =
  Float.abs (a.r -. b.r) <= 1e-9
  && Float.abs (a.g -. b.g) <= 1e-9
  && Float.abs (a.b -. b.b) <= 1e-9

let test_cameras () =
  let sc = scene {|camera { kind: "orthographic", width: 6, position: (0, 0, -5) }|} in
  (match sc.camera.kind with
  | Camera.Orthographic { width } -> close "width" 6. width
  | _ -> Alcotest.fail "not orthographic");
  let sc = scene {|camera { kind: "fisheye", fov: 270 }|} in
  Alcotest.(check string) "fisheye" "fisheye" (Camera.kind_name sc.camera.kind);
  close "fov" 270. sc.camera.fov;
  let sc = scene {|camera { aperture: 0.2, focal_distance: 4, lens_samples: 3 }|} in
  close "aperture" 0.2 sc.camera.aperture;
  close "focal distance" 4. sc.camera.focal_distance;
  Alcotest.(check int) "lens samples" 3 sc.camera.lens_samples;
  Alcotest.(check bool) "depth of field" true sc.features.depth_of_field;
  let sc = scene "camera { fov: 40 }" in
  Alcotest.(check bool)
    "a plain camera is the pinhole" true
    (Camera.pinhole_perspective sc.camera)

let test_camera_errors () =
  check_err ~at:{|"orthgraphic"|} {|camera { kind: "orthgraphic", width: 2 }|}
    {|unknown camera kind "orthgraphic"; did you mean "orthographic"?|};
  check_err ~at:"camera" {|camera { kind: "orthographic" }|}
    "an orthographic camera needs a `width`";
  check_err ~at:"30" {|camera { kind: "orthographic", width: 2, fov: 30 }|}
    "an orthographic camera has no `fov`";
  check_err ~at:"2" {|camera { width: 2 }|} "`width` is for an orthographic camera";
  check_err ~at:"400" {|camera { kind: "fisheye", fov: 400 }|}
    "a fisheye's `fov` must be in (0, 360] degrees, got 400";
  check_err ~at:"200" {|camera { fov: 200 }|} {|(a wider view needs kind: "fisheye")|};
  check_err ~at:"camera" {|camera { aperture: 0.1 }|} "needs a `focal_distance`";
  check_err ~at:"0 }" {|camera { aperture: 0.1, focal_distance: 2, lens_samples: 0 }|}
    "`lens_samples` must be a whole number in [1, 64]"

let test_spots () =
  let sc =
    scene
      "light { position: (0, 5, 0), point_at: (0, 0, 0), inner: 10, outer: 20, radius: \
       0.5, samples: 3 }"
  in
  (match sc.lights.(0) with
  | Light.Point { spot = Some sp; radius; samples; _ } ->
      close "inner" 10. sp.inner;
      close "outer" 20. sp.outer;
      Alcotest.(check bool)
        "axis straight down" true
        (Vec3.equal_f sp.axis (Vec3.v 0. (-1.) 0.));
      close "radius" 0.5 radius;
      Alcotest.(check int) "samples" 3 samples
  | _ -> Alcotest.fail "not a spot");
  let sc = scene "light { position: (0, 5, 0), point_at: (1, 0, 0) }" in
  (match sc.lights.(0) with
  | Light.Point { spot = Some sp; _ } ->
      close "default inner" 30. sp.inner;
      close "default outer" 45. sp.outer
  | _ -> Alcotest.fail "not a spot");
  Alcotest.(check bool) "feature" true sc.features.spot_lights;
  check_err ~at:"20 }"
    "light { position: (0, 5, 0), point_at: (0, 0, 0), inner: 30, outer: 20 }"
    "0 ≤ inner ≤ outer ≤ 180";
  check_err ~at:"(0, 5, 0) }" "light { position: (0, 5, 0), point_at: (0, 5, 0) }"
    "point_at must differ from its position";
  check_err ~at:"inner" "light { position: (0, 5, 0), inner: 10 }"
    "`inner` is for a spot light: give it a `point_at`";
  check_err "light { direction: (0, -1, 0), point_at: (0, 0, 0) }"
    "unknown field `point_at` in light"

let test_environment () =
  let sc =
    scene
      "settings { background: gradient((1, 0.5, 0), (0, 0, 1)), fog: fog((0.5, 0.5, \
       0.5), 20) }"
  in
  (match sc.settings.sky with
  | Some { horizon; zenith } ->
      Alcotest.(check bool) "horizon" true (color_eq horizon (Color.v 1. 0.5 0.));
      Alcotest.(check bool) "zenith" true (color_eq zenith (Color.v 0. 0. 1.))
  | None -> Alcotest.fail "no gradient");
  (match sc.settings.fog with
  | Some f -> close "fog distance" 20. f.distance
  | None -> Alcotest.fail "no fog");
  Alcotest.(check bool) "sky feature" true sc.features.sky;
  Alcotest.(check bool) "fog feature" true sc.features.fog;
  let sc = scene "settings { background: (0.1, 0.2, 0.3) }" in
  Alcotest.(check bool)
    "a flat background has no gradient" true
    (Option.is_none sc.settings.sky);
  check_err ~at:"checker"
    "settings { fog: fog((0.5, 0.5, 0.5), 10), background: checker((1, 1, 1), (0, 0, 0), \
     1) }"
    "`background` must be a colour (r, g, b) or gradient(HORIZON, ZENITH)";
  check_err ~at:"0) }" "settings { fog: fog((0.5, 0.5, 0.5), 0) }"
    "the distance of `fog` must be in (0, 1e150], got 0";
  check_err ~at:"(0.5" "settings { fog: (0.5, 0.5, 0.5) }"
    "`fog` must be fog(COLOR, DISTANCE), got a vector"

let test_color_maps () =
  let sc =
    scene
      "sphere { center: (0, 0, 0), radius: 1, material: material { texture: gradient((0, \
       1, 0), color_map((0, (1, 0, 0)), (0.5, (0, 1, 0)), (1, (0, 0, 1)))) } }"
  in
  (match sc.objects.(0).material.texture with
  | Some (Description.Gradient { axis; map }) ->
      Alcotest.(check bool) "axis" true (Vec3.equal_f axis Vec3.y_axis);
      Alcotest.(check int) "three entries" 3 (Array.length map.ts);
      Alcotest.(check bool)
        "a quarter" true
        (color_eq (Texture.lookup map 0.25) (Color.v 0.5 0.5 0.))
  | _ -> Alcotest.fail "not a gradient");
  Alcotest.(check bool) "feature" true sc.features.color_maps;
  let sc =
    scene
      "let m = color_map((0, (1, 1, 1)), (1, (0, 0, 0)))\n\
       let t = gradient((1, 0, 0), m)\n\
       plane { normal: (0, 1, 0), material: material { texture: t } }"
  in
  Alcotest.(check bool)
    "through let" true
    (match sc.objects.(0).material.texture with
    | Some (Description.Gradient _) -> true
    | _ -> false);
  let sc =
    scene
      "let m = color_map((0, (1, 1, 1)), (0.5, (0.2, 0.4, 0.1)), (1, (0, 0, 0)))\n\
       sphere { center: (0, 0, 0), radius: 1, material: material { texture: marble(m, \
       0.5) } }\n\
       sphere { center: (3, 0, 0), radius: 1, material: material { texture: wood(m, 0.2) \
       } }\n\
       sphere { center: (6, 0, 0), radius: 1, material: material { texture: noise(m, 1) \
       } }"
  in
  List.iteri
    (fun i want ->
      match sc.objects.(i).material.texture with
      | Some (Description.Mapped { pattern; _ }) ->
          Alcotest.(check bool) ("pattern " ^ string_of_int i) true (pattern = want)
      | _ -> Alcotest.fail "not a mapped texture")
    [
      Description.Marble_pattern 0.5;
      Description.Wood_pattern 0.2;
      Description.Noise_pattern 1.;
    ];
  Alcotest.(check bool) "mapped textures count as colour maps" true sc.features.color_maps;
  check_err
    "let m = color_map((0, (1, 1, 1)))\n\
     sphere { center: (0, 0, 0), radius: 1, material: material { texture: marble(m) } }"
    "`marble` takes 3 arguments (c1, c2, scale), or 2 (color_map(…), scale); got 1";
  check_err
    "sphere { center: (0, 0, 0), radius: 1, material: material { texture: wood((1, 1, \
     1), 2) } }"
    "wood takes (c1, c2, scale) or (color_map(…), scale)";
  check_err ~at:"(0.2" "let m = color_map((0.5, (1, 1, 1)), (0.2, (0, 0, 0)))"
    "entry 2 of `color_map` has t = 0.2, below the 0.5 before it";
  check_err ~at:"(2," "let m = color_map((2, (1, 1, 1)))"
    "entry 1 of `color_map` has t = 2; t must be in [0, 1]";
  check_err ~at:"((1" "let m = color_map(((1, 1, 1), 0))"
    "must be (t, colour) with t a number";
  check_err ~at:"0.5" "let m = color_map(0.5)" "must be a pair (t, colour)";
  check_err ~at:"color_map"
    "sphere { center: (0, 0, 0), radius: 1, material: material { texture: color_map((0, \
     (1, 1, 1))) } }"
    "write gradient(AXIS, color_map(…))";
  check_err "sphere { center: (1, 2), radius: 1 }"
    "`center` must be a vector (x, y, z), got a pair (t, colour)";
  check_err "let v = (1, }"
    "after `(x,`, expected the second component of the vector (or of the colour-map \
     entry (t, colour))";
  check_err "let v = (1, 2 }" "or `)` to close a colour-map entry (t, colour)"

let test_json_and_summary () =
  let text =
    {|settings { background: gradient((1, 1, 1), (0, 0, 1)), fog: fog((1, 1, 1), 5) }
camera { kind: "orthographic", width: 3, aperture: 0.1, focal_distance: 2 }
light { position: (0, 5, 0), point_at: (0, 0, 0), inner: 10, outer: 20 }
sphere { center: (0, 0, 0), radius: 1, material: material { texture: gradient((0, 1, 0), color_map((0, (1, 0, 0)), (1, (0, 0, 1)))) } }|}
  in
  let p =
    match Program.load_string ~filename:"test.rts" text with
    | Ok p -> p
    | Error es -> Alcotest.fail (errors_text es)
  in
  let sc =
    match Program.scene_at p ~time:0. ~frame:0 with
    | Ok s -> s
    | Error es -> Alcotest.fail (errors_text es)
  in
  let summary = Program.summary p sc in
  List.iter
    (fun sub -> Alcotest.(check bool) ("summary says " ^ sub) true (contains summary sub))
    [
      "camera: orthographic, 3 wide, depth of field (aperture 0.1, focused at 2, 1×1 \
       lens samples)";
      "lights: 1 (spot 1)";
      "renderer uses: shadows, textures, orthographic, depth of field, spot lights, sky, \
       fog, color maps";
      "renderer skips: soft shadows, reflection, refraction, bump, supersampling, bvh, \
       fisheye, bodies";
    ];
  let j = Program.to_json p sc in
  let open Yojson.Safe.Util in
  Alcotest.(check string)
    "camera kind" "orthographic"
    (j |> member "camera" |> member "kind" |> to_string);
  Alcotest.(check string)
    "light kind" "spot"
    (j |> member "lights" |> index 0 |> member "kind" |> to_string);
  Alcotest.(check string)
    "background" "gradient"
    (j |> member "settings" |> member "background" |> member "kind" |> to_string);
  close "fog" 5. (j |> member "settings" |> member "fog" |> member "distance" |> to_number);
  Alcotest.(check string)
    "texture" "gradient"
    (j |> member "objects" |> index 0 |> member "material" |> member "texture"
   |> member "kind" |> to_string)

let () =
  Alcotest.run "environment language"
    [
      ( "language",
        [
          Alcotest.test_case "camera kinds and depth of field take their fields" `Quick
            test_cameras;
          Alcotest.test_case "each camera mistake is located and says what was expected"
            `Quick test_camera_errors;
          Alcotest.test_case
            "point_at, inner and outer make a spot light, soft with a radius" `Quick
            test_spots;
          Alcotest.test_case "background: gradient(…) and fog: fog(…) set the environment"
            `Quick test_environment;
          Alcotest.test_case
            "gradient(AXIS, color_map(…)) is a texture; bad entries are located" `Quick
            test_color_maps;
          Alcotest.test_case
            "check and --json describe cameras, spots, sky, fog and colour maps" `Quick
            test_json_and_summary;
        ] );
    ]
