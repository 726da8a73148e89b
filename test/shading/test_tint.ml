(* Tinted metals and coloured glass: lancer's render of one sphere under one light against
   the reference shader of Tint_ref, written from the formulas alone, byte for byte. *)

module R = Tint_ref

let plain = Lancer.Description.default_material

let scene material : R.scene =
  {
    width = 64;
    height = 48;
    depth = 4;
    horizon = R.v 0.9 0.85 0.8;
    zenith = R.v 0.15 0.3 0.85;
    eye = R.v 0. 1.6 (-4.);
    look_at = R.v 0. 1. 0.;
    fov = 45.;
    light = R.v (-3.) 5. (-4.);
    center = R.v 0. 1. 0.;
    radius = 1.;
    material;
  }

(* A gold-like metal, a red glass, and a surface that both reflects and refracts with
   partial tints, without Fresnel (so total internal reflection moves its weight inside). *)
let gold =
  {
    plain with
    color = Lancer.Color.v 1. 0.766 0.336;
    ambient = 0.05;
    diffuse = 0.75;
    specular = 0.8;
    shininess = 40.;
    reflection = 0.7;
    metallic = 1.;
  }

let red_glass =
  {
    plain with
    color = Lancer.Color.v 1. 0.2 0.15;
    ambient = 0.;
    diffuse = 0.;
    specular = 1.;
    shininess = 200.;
    transparency = 0.9;
    ior = 1.5168;
    fresnel = true;
    filter = 1.;
  }

let mixed =
  {
    plain with
    color = Lancer.Color.v 0.3 0.8 0.5;
    specular = 0.5;
    shininess = 20.;
    reflection = 0.3;
    transparency = 0.5;
    ior = 1.9;
    metallic = 0.4;
    filter = 0.6;
  }

let lancer (s : R.scene) =
  let text = R.rts s in
  match Lancer.Program.load_string ~filename:"tint.rts" text with
  | Error _ -> Alcotest.failf "the scene does not load:\n%s" text
  | Ok p -> (
      match Lancer.Program.scene_at p ~time:0. ~frame:0 with
      | Error _ -> Alcotest.failf "the scene does not evaluate:\n%s" text
      | Ok sc ->
          let fb, _ = Lancer.Render.render sc in
          Lancer.Image.to_bytes sc.settings.gamma fb)

(* Every byte equal; otherwise how many pixels differ, and the first few. *)
let same_image what (s : R.scene) expected actual =
  let bad = ref [] in
  for k = (s.width * s.height) - 1 downto 0 do
    let px b =
      ( Bytes.get_uint8 b (3 * k),
        Bytes.get_uint8 b ((3 * k) + 1),
        Bytes.get_uint8 b ((3 * k) + 2) )
    in
    if px expected <> px actual then bad := (k, px expected, px actual) :: !bad
  done;
  match !bad with
  | [] -> ()
  | l ->
      Alcotest.failf "%s: %d pixels differ from the reference, first %s" what
        (List.length l)
        (String.concat "; "
           (List.filteri
              (fun i _ -> i < 5)
              (List.map
                 (fun (k, (a, b, c), (x, y, z)) ->
                   Printf.sprintf "(%d, %d): expected (%d, %d, %d), got (%d, %d, %d)"
                     (k mod s.width) (k / s.width) a b c x y z)
                 l)))

let matches what material () =
  let s = scene material in
  same_image what s (R.render s) (lancer s)

(* The tints show: the same sphere with both fields 0 gives another image (so the
   comparisons above test them, not only what they leave alone). *)
let tints_show () =
  List.iter
    (fun (what, m) ->
      let s = scene m in
      let untinted = scene { m with Lancer.Description.metallic = 0.; filter = 0. } in
      if Bytes.equal (R.render s) (R.render untinted) then
        Alcotest.failf "%s: the tint changes nothing in the reference" what)
    [ ("gold", gold); ("red glass", red_glass); ("mixed", mixed) ]

let () =
  Alcotest.run "tint"
    [
      ( "metallic and filter as the shading model writes them",
        [
          Alcotest.test_case "a metal tints its highlight and reflection by its colour"
            `Quick (matches "gold" gold);
          Alcotest.test_case "a coloured glass filters what is seen through it" `Quick
            (matches "red glass" red_glass);
          Alcotest.test_case
            "partial tints on a surface that reflects and refracts, with total internal \
             reflection"
            `Quick (matches "mixed" mixed);
          Alcotest.test_case "with both at 0, the untinted model" `Quick
            (matches "untinted" { mixed with metallic = 0.; filter = 0. });
          Alcotest.test_case "each tint changes the image" `Quick tints_show;
        ] );
    ]
