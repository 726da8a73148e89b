(* The golden registry: every scene in scenes/*.rts, scenes/gallery/*.rts,
   scenes/gallery/maps/*.rts and scenes/materials/*.rts, rendered at 96×72 and compared with test/golden/ID.png.

   A failure writes ID.actual.png and ID.diff.png beside the golden and says where. After
   an intended change to the renderer or a scene, look at those images, then accept the new
   renders with `make golden-update` (LANCER_UPDATE_GOLDEN=1) and review them in the commit.
   A new scene fails the "registry" checks until it has an entry below and a golden. *)

let width = 96
let height = 72

(* Tests run in _build/default/test/golden; scenes are named from the project root. *)
let root = "../.."

(* id (the golden is ID.png), scene, and what to look at in the image. *)
let registry =
  [
    ( "billiards",
      "scenes/billiards.rts",
      "five balls inside a box seen from above, at time 0" );
    ( "bounce",
      "scenes/bounce.rts",
      "the ball high above the checkered floor at time 0, camera following it" );
    ( "glass",
      "scenes/glass.rts",
      "the scene behind seen upside down through the glass sphere" );
    ( "macro_grid",
      "scenes/macro_grid.rts",
      "24 rows of macro-built spheres in hsv/rand colours" );
    ( "plane_paraboloid",
      "scenes/plane_paraboloid.rts",
      "an orange cup on a plane, inside and outside shaded differently" );
    ( "showcase",
      "scenes/showcase.rts",
      "mirror and glass spheres among coloured ones on a checkered floor" );
    ( "specular",
      "scenes/specular.rts",
      "highlights from broad to tight, left to right; weights from 0 to 1 behind" );
    ( "spheres",
      "scenes/spheres.rts",
      "Lambert shading and distance attenuation; shadows on the floor and each other" );
    ( "texture",
      "scenes/texture.rts",
      "checkered floor; checkered and (rotated) striped spheres" );
    ( "gallery_box",
      "scenes/gallery/box.rts",
      "a slab, a cube on it, a cube rotated about two axes, a stretched box" );
    ( "gallery_bump_image",
      "scenes/gallery/bump_image.rts",
      "raised bricks on a flat wall and a box from the bricks height map" );
    ( "gallery_bump_noise",
      "scenes/gallery/bump_noise.rts",
      "smooth, gently bumped and strongly bumped spheres; round silhouettes" );
    ( "gallery_checker",
      "scenes/gallery/checker.rts",
      "whole cells on the floor; sphere and rotated box cut through the 3-D pattern" );
    ( "gallery_cylinder",
      "scenes/gallery/cylinder.rts",
      "a capped cylinder, an open tube on its side, a slanted open tube" );
    ( "gallery_depth_of_field",
      "scenes/gallery/depth_of_field.rts",
      "the middle sphere sharp, the near red one and the far blue one blurred" );
    ( "gallery_disk",
      "scenes/gallery/disk.rts",
      "disks flat on the floor, facing the camera and tilted, with their shadows" );
    ( "gallery_fisheye",
      "scenes/gallery/fisheye.rts",
      "looking up inside a ring of columns: sky, spokes and a sun in a circle; zenith \
       colour outside it" );
    ( "gallery_fog",
      "scenes/gallery/fog.rts",
      "two rows of columns fading into grey haze with distance; a fogged reflection" );
    ( "gallery_gradient",
      "scenes/gallery/gradient.rts",
      "a rainbow along y, bands along a tilted axis, hard-stepped bands on a box, floor \
       stripes, a blue-gold marble in front" );
    ( "gallery_group",
      "scenes/gallery/group.rts",
      "three macro-built trees: crowns take the group material, trunks stay brown" );
    ( "gallery_image",
      "scenes/gallery/image.rts",
      "the smiley upright on a panel, wrapped on a sphere, twice per box face" );
    ( "gallery_marble",
      "scenes/gallery/marble.rts",
      "veined marble sphere, green marble block, grey marble floor" );
    ( "gallery_mesh",
      "scenes/gallery/mesh.rts",
      "the torus OBJ, smooth-shaded on the left and faceted on the right" );
    ( "gallery_motion_blur",
      "scenes/gallery/motion_blur.rts",
      "a red ball smeared from its drop to the floor and back up, a blue one smeared \
       sideways, the green one between them sharp" );
    ( "gallery_noise",
      "scenes/gallery/noise.rts",
      "noise at three scales, fine to coarse, left to right" );
    ( "gallery_orthographic",
      "scenes/gallery/orthographic.rts",
      "four equal cubes in a row going away, all drawn the same size" );
    ( "gallery_paraboloid",
      "scenes/gallery/paraboloid.rts",
      "an upright open cup and a tilted one seen into" );
    ( "gallery_parallelogram",
      "scenes/gallery/parallelogram.rts",
      "a tile on the floor, a standing rhombus, a rotated rectangle" );
    ( "gallery_plane",
      "scenes/gallery/plane.rts",
      "floor, back wall and a leaning plane meeting the floor in a line" );
    ( "gallery_sphere",
      "scenes/gallery/sphere.rts",
      "a sphere, a squashed ellipsoid and a tall tilted one, with shadows" );
    ( "gallery_sky",
      "scenes/gallery/sky.rts",
      "warm horizon to blue zenith behind; the mirror sphere reflects the sky" );
    ( "gallery_spot",
      "scenes/gallery/spot.rts",
      "three pools of light: hard-edged, soft-edged, and with a soft shadow" );
    ( "gallery_stripes",
      "scenes/gallery/stripes.rts",
      "stripes along x; on the rotated sphere they turn with it" );
    ( "gallery_triangle",
      "scenes/gallery/triangle.rts",
      "a tetrahedron of four triangles and a lone triangle" );
    ( "gallery_wood",
      "scenes/gallery/wood.rts",
      "long grain on a log, a plank and a post (the pattern stretched along y)" );
    ( "gallery_lens",
      "scenes/gallery/lens.rts",
      "a glass lens (two spheres intersected) magnifying the checkered wall; a merged \
       pair of tinted spheres" );
    ( "gallery_dice",
      "scenes/gallery/dice.rts",
      "two rounded dice with dark pips carved in three faces, the red one turned" );
    ( "gallery_pipe",
      "scenes/gallery/pipe.rts",
      "a pipe seen into its bore, a hollow cone funnel, a solid pointed cone" );
    ( "gallery_torus",
      "scenes/gallery/torus.rts",
      "a trefoil knot of 60 small rainbow tori above a large flat torus" );
    ( "gallery_tint",
      "scenes/gallery/tint.rts",
      "left untinted gold and red glass (beige, colourless), right the library's: a gold \
       mirror and a red glass" );
    ( "gallery_terrain",
      "scenes/gallery/terrain.rts",
      "green islands of a noise height field in a reflecting sea" );
    ( "maps_terrain",
      "scenes/gallery/maps/terrain.rts",
      "grey noise, the terrain's height map, stretched to 4:3" );
    ( "maps_bricks",
      "scenes/gallery/maps/bricks.rts",
      "white bricks in dark mortar (the height map), stretched to 4:3" );
    ( "maps_smiley",
      "scenes/gallery/maps/smiley.rts",
      "the smiley image map, green mark top left, stretched to 4:3" );
    ( "materials_chrome",
      "scenes/materials/chrome.rts",
      "a grey mirror-like sphere reflecting floor and sky, slightly darkened" );
    ( "materials_colors",
      "scenes/materials/colors.rts",
      "33 flat discs in the named colours, black to steel_blue, in rows of 11" );
    ( "materials_copper",
      "scenes/materials/copper.rts",
      "a copper mirror: floor and sky reflected in pinkish copper" );
    ( "materials_diamond",
      "scenes/materials/diamond.rts",
      "a clear sphere, strongly reflective at the rim, the floor refracted inside" );
    ( "materials_blue_glass",
      "scenes/materials/blue_glass.rts",
      "a blue glass sphere: the floor seen through it upside down and blue" );
    ( "materials_green_glass",
      "scenes/materials/green_glass.rts",
      "a green glass sphere: the floor seen through it upside down and green" );
    ( "materials_red_glass",
      "scenes/materials/red_glass.rts",
      "a red glass sphere: the floor seen through it upside down and red, a white rim" );
    ( "materials_glass",
      "scenes/materials/glass.rts",
      "a clear sphere showing the floor upside down, bright rim" );
    ( "materials_gold",
      "scenes/materials/gold.rts",
      "a gold mirror: floor and sky reflected in gold, a gold highlight" );
    ("materials_ice", "scenes/materials/ice.rts", "a slightly cloudy clear sphere");
    ("materials_mirror", "scenes/materials/mirror.rts", "a near-perfect mirror sphere");
    ( "materials_oak",
      "scenes/materials/oak.rts",
      "a wood-ringed sphere with a faint sheen" );
    ( "materials_plastic",
      "scenes/materials/plastic.rts",
      "a white glossy sphere with a highlight" );
    ( "materials_rubber",
      "scenes/materials/rubber.rts",
      "a black sphere with a broad dim highlight" );
    ( "materials_silver",
      "scenes/materials/silver.rts",
      "a bright mirror sphere, slightly warm" );
    ( "materials_water",
      "scenes/materials/water.rts",
      "a clear sphere like glass but refracting less" );
    ( "materials_white_marble",
      "scenes/materials/white_marble.rts",
      "a white sphere with grey veins" );
  ]

let scene_dirs = [ "scenes"; "scenes/gallery"; "scenes/gallery/maps"; "scenes/materials" ]
let in_root p = Filename.concat root p

(* Directory listings come from the source tree, so that a scene added there and not yet
   registered (or a golden left behind) is caught. *)
let list_dir dir suffix =
  let d = Lancer_alcotest.source_path (in_root dir) in
  Sys.readdir d |> Array.to_list
  |> List.filter (fun f -> Filename.check_suffix f suffix)
  |> List.sort compare

let scenes_on_disk () =
  List.concat_map
    (fun dir -> List.map (fun f -> dir ^ "/" ^ f) (list_dir dir ".rts"))
    scene_dirs

let goldens_on_disk () =
  List.filter
    (fun f ->
      not (Filename.check_suffix f ".actual.png" || Filename.check_suffix f ".diff.png"))
    (list_dir "test/golden" ".png")

let missing_from ~have want = List.filter (fun x -> not (List.mem x have)) want

let test_every_scene_registered () =
  let registered = List.map (fun (_, s, _) -> s) registry in
  match missing_from ~have:registered (scenes_on_disk ()) with
  | [] -> ()
  | l ->
      Alcotest.failf
        "scenes without a golden entry in test/golden/test_golden.ml: %s (add them, then \
         make golden-update)"
        (String.concat ", " l)

let test_registry_consistent () =
  let ids = List.map (fun (id, _, _) -> id) registry in
  let dups =
    List.filter (fun id -> List.length (List.filter (String.equal id) ids) > 1) ids
  in
  Alcotest.(check (list string)) "duplicate ids" [] (List.sort_uniq compare dups);
  let gone =
    List.filter
      (fun (_, s, _) -> not (Sys.file_exists (Lancer_alcotest.source_path (in_root s))))
      registry
  in
  Alcotest.(check (list string))
    "registered scenes that do not exist" []
    (List.map (fun (_, s, _) -> s) gone);
  if not (Lancer_alcotest.updating ()) then
    Alcotest.(check (list string))
      "goldens with no registry entry" []
      (missing_from ~have:(List.map (fun id -> id ^ ".png") ids) (goldens_on_disk ()))

let golden_case (id, scene, _what) =
  Lancer_alcotest.test_case id ~width ~height ~scene:(in_root scene) ~golden:(id ^ ".png")
    ()

(* The image maps the gallery uses are the renders of their scenes at full size: the
   committed PNG can always be made again from its scene. *)
let test_map_reproducible name () =
  let scene = in_root (Printf.sprintf "scenes/gallery/maps/%s.rts" name) in
  let png = in_root (Printf.sprintf "scenes/gallery/maps/%s.png" name) in
  match Lancer_alcotest.render_scene (Lancer_alcotest.source_path scene) with
  | Error m -> Alcotest.fail m
  | Ok actual -> (
      match Lancer.Image.read_rgb8 (Lancer_alcotest.source_path png) with
      | Error m -> Alcotest.fail m
      | Ok expected -> (
          match Lancer.Compare.compare expected actual with
          | Error m -> Alcotest.fail m
          | Ok c ->
              if not (Lancer.Compare.within c) then
                Alcotest.failf
                  "%s is not the render of %s (%a): lancer render %s.rts -o %s.png in \
                   scenes/gallery/maps"
                  png scene Lancer.Compare.pp c name name))

(* The comparison itself must catch a change. These run with updating switched off, since
   under LANCER_UPDATE_GOLDEN=1 every comparison rewrites its golden. *)
let without_update f =
  let saved = Sys.getenv_opt "LANCER_UPDATE_GOLDEN" in
  Unix.putenv "LANCER_UPDATE_GOLDEN" "0";
  Fun.protect f ~finally:(fun () ->
      Unix.putenv "LANCER_UPDATE_GOLDEN" (Option.value saved ~default:"0"))

let temp_dir () =
  let d = Filename.temp_file "lancer_golden" "" in
  Sys.remove d;
  Sys.mkdir d 0o755;
  d

let render id =
  let _, scene, _ = List.find (fun (i, _, _) -> i = id) registry in
  match
    Lancer_alcotest.render_scene ~width ~height
      (Lancer_alcotest.source_path (in_root scene))
  with
  | Ok img -> img
  | Error m -> Alcotest.fail m

let copy_golden id dir =
  let src = Lancer_alcotest.source_path (id ^ ".png") in
  let dst = Filename.concat dir "golden.png" in
  (match Lancer.Image.read_rgb8 src with
  | Ok (w, h, b) -> (
      match Lancer.Image.write_rgb8 dst w h b with
      | Ok () -> ()
      | Error m -> Alcotest.fail m)
  | Error m -> Alcotest.failf "%s (run make golden-update first)" m);
  dst

let test_detects_difference () =
  without_update @@ fun () ->
  let dir = temp_dir () in
  (* the sphere scene's render against the box scene's golden *)
  let golden = copy_golden "gallery_box" dir in
  match Lancer_alcotest.compare_golden ~golden (render "gallery_sphere") with
  | Ok (Lancer_alcotest.Different { figures; actual; diff }) ->
      Alcotest.(check bool) "actual image written" true (Sys.file_exists actual);
      Alcotest.(check bool) "diff image written" true (Sys.file_exists diff);
      Alcotest.(check string)
        "actual beside the golden"
        (Filename.concat dir "golden.actual.png")
        actual;
      Alcotest.(check string)
        "diff beside the golden"
        (Filename.concat dir "golden.diff.png")
        diff;
      Alcotest.(check bool)
        "many pixels over the tolerance" true
        (figures.Lancer.Compare.over_share > 0.05);
      (match Lancer.Image.read_rgb8 diff with
      | Ok (w, h, _) ->
          Alcotest.(check (pair int int)) "diff image size" (width, height) (w, h)
      | Error m -> Alcotest.fail m);
      (* and [check], what users call, fails with the paths in its message *)
      let scene = Lancer_alcotest.source_path (in_root "scenes/gallery/sphere.rts") in
      let msg =
        match Lancer_alcotest.check ~width ~height ~scene ~golden () with
        | () -> Alcotest.fail "check passed against another scene's golden"
        | exception e -> Printexc.to_string e
      in
      let contains sub =
        let n = String.length sub in
        let rec at i =
          i + n <= String.length msg && (String.sub msg i n = sub || at (i + 1))
        in
        at 0
      in
      Alcotest.(check bool) ("message names the diff image: " ^ msg) true (contains diff);
      Alcotest.(check bool)
        ("message says it differs: " ^ msg)
        true
        (contains "differs from its golden")
  | Ok (Same _) -> Alcotest.fail "a different scene compared the same"
  | Ok (Updated _) -> Alcotest.fail "the golden was rewritten"
  | Ok (Missing _) -> Alcotest.fail "the golden was reported missing"
  | Error m -> Alcotest.fail m

let test_accepts_same () =
  without_update @@ fun () ->
  let dir = temp_dir () in
  let golden = copy_golden "gallery_sphere" dir in
  match Lancer_alcotest.compare_golden ~golden (render "gallery_sphere") with
  | Ok (Same c) ->
      Alcotest.(check int) "no pixel over" 0 c.Lancer.Compare.over;
      Alcotest.(check bool)
        "no actual image written" false
        (Sys.file_exists (Filename.concat dir "golden.actual.png"))
  | Ok _ -> Alcotest.fail "the scene differs from a copy of its own golden"
  | Error m -> Alcotest.fail m

let test_reports_missing () =
  without_update @@ fun () ->
  let dir = temp_dir () in
  let golden = Filename.concat dir "none.png" in
  match Lancer_alcotest.compare_golden ~golden (render "gallery_disk") with
  | Ok (Missing { actual }) ->
      Alcotest.(check bool) "actual image written" true (Sys.file_exists actual);
      Alcotest.(check bool) "golden not created" false (Sys.file_exists golden)
  | Ok _ -> Alcotest.fail "a missing golden was not reported"
  | Error m -> Alcotest.fail m

let () =
  Alcotest.run "golden"
    [
      ( "registry",
        [
          Alcotest.test_case "every scene has an entry" `Quick test_every_scene_registered;
          Alcotest.test_case "entries and goldens agree" `Quick test_registry_consistent;
        ] );
      ("scenes", List.map golden_case registry);
      ( "maps",
        [
          Alcotest.test_case "smiley.png is its scene's render" `Quick
            (test_map_reproducible "smiley");
          Alcotest.test_case "bricks.png is its scene's render" `Quick
            (test_map_reproducible "bricks");
          Alcotest.test_case "terrain.png is its scene's render" `Quick
            (test_map_reproducible "terrain");
        ] );
      ( "comparison",
        [
          Alcotest.test_case "another scene's golden fails, with actual and diff" `Quick
            test_detects_difference;
          Alcotest.test_case "a copy of its own golden passes" `Quick test_accepts_same;
          Alcotest.test_case "a missing golden is reported" `Quick test_reports_missing;
        ] );
    ]
