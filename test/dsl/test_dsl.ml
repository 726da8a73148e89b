(* The scene language: every construct evaluates as doc/reference/language.md says, every scene of scenes/
   loads, and no input makes the language raise (qcheck, fixed seeds). *)

open Lancer
module Dsl = Lancer_dsl.Dsl
module Error = Lancer_dsl.Error

let errors_text es = String.concat "" (List.map Error.to_string es)

let load text =
  match Program.load_string ~filename:"test.rts" text with
  | Ok p -> p
  | Error es -> Alcotest.failf "unexpected errors:\n%s" (errors_text es)

let scene_of ?(frame = 0) p ~time =
  match Program.scene_at p ~time ~frame with
  | Ok s -> s
  | Error es -> Alcotest.failf "unexpected errors:\n%s" (errors_text es)

let scene ?(time = 0.) ?(frame = 0) text =
  match Program.scene_at (load text) ~time ~frame with
  | Ok s -> s
  | Error es -> Alcotest.failf "unexpected errors:\n%s" (errors_text es)

(* The value of expression [e]: the radius of a sphere whose radius is [e]. *)
let num e =
  let s = scene (Printf.sprintf "sphere { center: (0, 0, 0), radius: %s }" e) in
  match s.objects.(0).shape with
  | Shape.Sphere { radius; _ } -> radius
  | _ -> Alcotest.fail "not a sphere"

(* The value of vector expression [e]: the centre of a sphere. *)
let vec e =
  let s = scene (Printf.sprintf "sphere { center: %s, radius: 1 }" e) in
  match s.objects.(0).shape with
  | Shape.Sphere { center; _ } -> center
  | _ -> Alcotest.fail "not a sphere"

let errs text =
  match Dsl.load_string ~filename:"test.rts" text with
  | Ok _ -> Alcotest.failf "expected an error for:\n%s" text
  | Error es -> List.map (fun (e : Error.t) -> e.message) es

let contains s sub =
  let n = String.length sub and m = String.length s in
  let rec go i = i + n <= m && (String.sub s i n = sub || go (i + 1)) in
  go 0

let check_err text sub =
  let ms = errs text in
  if not (List.exists (fun m -> contains m sub) ms) then
    Alcotest.failf "expected an error containing %S, got:\n%s" sub (String.concat "\n" ms)

let feq = Alcotest.(check (float 1e-9))
let veq msg a b = Alcotest.(check bool) msg true (Vec3.equal_f ~eps:1e-9 a b)

(* The world centre and radius of a compiled sphere, whether it kept its transform or
   was compiled as the sphere its transform makes of it (moved, turned, scaled alike on
   every axis). *)
let sphere_placed (o : Primitive.t) =
  match o.shape with
  | Shape.Sphere { center; radius } ->
      ( Transform.point o.transform center,
        radius *. Option.value ~default:1. (Transform.similarity o.transform) )
  | _ -> Alcotest.fail "not a sphere"

let centre o = fst (sphere_placed o)

let test_precedence () =
  feq "* before +" 7. (num "1 + 2 * 3");
  feq "unary minus below ^" 7. (num "11 + -2 ^ 2");
  feq "^ is right-associative" 512. (num "2 ^ 3 ^ 2");
  feq "parentheses group" 9. (num "(1 + 2) * 3");
  feq "% is the remainder" 1. (num "7 % 3");
  feq "- is left-associative" 1. (num "6 - 3 - 2");
  feq "/ is left-associative" 1. (num "12 / 3 / 4");
  feq "not below comparisons" 1. (num "if not 1 > 2 then 1 else 2");
  feq "and before or" 1. (num "if true or false and false then 1 else 2");
  feq "numbers .5 and 1e-3" 0.501 (num ".5 + 1e-3")

let test_vectors () =
  veq "vector sum" (Vec3.v 5. 7. 9.) (vec "(1, 2, 3) + (4, 5, 6)");
  veq "scalar times vector" (Vec3.v 2. 4. 6.) (vec "2 * (1, 2, 3)");
  veq "vector times scalar" (Vec3.v 2. 4. 6.) (vec "(1, 2, 3) * 2");
  veq "component-wise product" (Vec3.v 4. 10. 18.) (vec "(1, 2, 3) * (4, 5, 6)");
  veq "vector over scalar" (Vec3.v 0.5 1. 1.5) (vec "(1, 2, 3) / 2");
  veq "negation" (Vec3.v (-1.) (-2.) (-3.)) (vec "-(1, 2, 3)");
  feq "components" 6. (num "(1, 2, 3).x + (1, 2, 3).y + (1, 2, 3).z");
  veq "parentheses around one expression only group" (Vec3.v 3. 0. 0.)
    (vec "((1 + 2), 0, 0)")

let test_builtins () =
  feq "sin" 1. (num "sin(pi / 2) + 0.0");
  feq "radians" (Float.pi /. 2.) (num "radians(90)");
  feq "degrees" 180. (num "degrees(pi)");
  feq "atan2" (Float.pi /. 4.) (num "atan2(1, 1)");
  feq "sqrt abs floor ceil round"
    (3. +. 2. +. 1. +. 2. +. 3.)
    (num "sqrt(9) + abs(-2) + floor(1.7) + ceil(1.2) + round(2.6)");
  feq "min max" 5. (num "min(3, 1, 2) + max(1, 4)");
  feq "pow exp log" 9. (num "pow(2, 3) + exp(0) + log(1)");
  feq "clamp" 1. (num "clamp(5, 0, 1)");
  feq "mix" 2.5 (num "mix(2, 3, 0.5)");
  feq "dot" 32. (num "dot((1, 2, 3), (4, 5, 6))");
  veq "cross" (Vec3.v 0. 0. 1.) (vec "cross((1, 0, 0), (0, 1, 0))");
  feq "length" 5. (num "length((3, 4, 0))");
  veq "normalize" (Vec3.v 0.6 0.8 0.) (vec "normalize((3, 4, 0))");
  veq "rgb" (Vec3.v 0.1 0.2 0.3) (vec "rgb(0.1, 0.2, 0.3)");
  veq "hsv red" (Vec3.v 1. 0. 0.) (vec "hsv(0, 1, 1)");
  veq "hsv green" (Vec3.v 0. 1. 0.) (vec "hsv(1 / 3, 1, 1)");
  feq "rand is Hash.of_float" (Hash.of_float 42. +. 1.) (num "rand(42) + 1");
  feq "rand is deterministic" 0. (num "rand(7) - rand(7) + 1" -. 1.)

let test_let_fn_scoping () =
  feq "let" 3. (num "3\nlet z = 1");
  let s =
    scene "let r = 2\nfn twice(x) = 2 * x\nsphere { center: (0,0,0), radius: twice(r) }"
  in
  (match s.objects.(0).shape with
  | Shape.Sphere { radius; _ } -> feq "fn" 4. radius
  | _ -> Alcotest.fail "expected a sphere");
  let s =
    scene
      "let r = 1\nfor i in 1 to 1 { let r = 5 }\nsphere { center: (0,0,0), radius: r }"
  in
  (match s.objects.(0).shape with
  | Shape.Sphere { radius; _ } -> feq "a let in a loop is local" 1. radius
  | _ -> Alcotest.fail "expected a sphere");
  let s =
    scene
      "let k = 3\nfn f(x) = x * k\nlet k = 100\nsphere { center: (0,0,0), radius: f(1) }"
  in
  (match s.objects.(0).shape with
  | Shape.Sphere { radius; _ } -> feq "functions are lexically scoped" 3. radius
  | _ -> Alcotest.fail "expected a sphere");
  let s =
    scene
      "fn fact(n) = if n <= 1 then 1 else n * fact(n - 1)\n\
       sphere { center: (0,0,0), radius: fact(5) }"
  in
  match s.objects.(0).shape with
  | Shape.Sphere { radius; _ } -> feq "recursion" 120. radius
  | _ -> Alcotest.fail "expected a sphere"

let count text = Array.length (scene text).objects

(* Lists: literals, indexing from 0, len, iteration in order; strings joined by +. *)
let test_lists_and_strings () =
  Alcotest.(check int)
    "for p in a list" 3
    (count
       "let pts = [(0, 0, 0), (1, 0, 0), (2, 0, 0)]\n\
        for p in pts { sphere { center: p, radius: 0.1 } }");
  veq "iteration in order, indexing from 0" (Vec3.v 2. 0. 0.)
    (vec "[(0, 0, 0), (1, 0, 0), (2, 0, 0)][2]");
  feq "len, nested lists, a comma after the last" 5.
    (num "len([[1, 2], [], [3],]) + [[1, 2], [3]][0][1]");
  feq "len of an empty list" 1. (num "len([]) + 1");
  Alcotest.(check int)
    "a loop over an empty list runs no time" 0
    (count "for p in [] { sphere { center: p, radius: 0.1 } }");
  feq "a list made from names and indexed by a computed number" 30.
    (num "(if true then [10, 20, 30] else [])[floor(2.5)]");
  feq "strings joined with +" 1.
    (num "if \"wood\" + \".\" + \"png\" == \"wood.png\" then 1 else 0");
  Alcotest.(check int)
    "a list of materials" 2
    (count
       "let ms = [material { color: (1, 0, 0) }, material { color: (0, 1, 0) }]\n\
        for m in ms { sphere { center: (0, 0, 0), radius: 1, material: m } }");
  check_err "let pts = [1, 2, 3]\nlet x = pts[3]"
    "index 3 is out of range: the list has 3 elements, indices 0 to 2"

let test_loops_and_macros () =
  Alcotest.(check int)
    "inclusive loop" 5
    (count "for i in 1 to 5 { sphere { center: (i, 0, 0), radius: 0.1 } }");
  Alcotest.(check int)
    "step" 3
    (count "for i in 0 to 1 step 0.5 { sphere { center: (i, 0, 0), radius: 0.1 } }");
  Alcotest.(check int)
    "negative step" 4
    (count "for i in 3 to 0 step -1 { sphere { center: (i, 0, 0), radius: 0.1 } }");
  Alcotest.(check int)
    "empty range" 0
    (count "for i in 1 to 0 { sphere { center: (i, 0, 0), radius: 0.1 } }");
  Alcotest.(check int)
    "macro called as a statement" 6
    (count
       "fn row(n) { for i in 1 to n { sphere { center: (i, 0, 0), radius: 0.1 } } }\n\
        row(2)\n\
        row(4)");
  Alcotest.(check int)
    "if statement" 1
    (count
       "if 1 < 2 { sphere { center: (0,0,0), radius: 1 } } else { plane { normal: \
        (0,1,0) } plane { normal: (0,1,0) } }");
  Alcotest.(check int)
    "else if" 2
    (count
       "if false { } else if true { plane { normal: (0,1,0) } plane { normal: (0,1,0) } }")

let test_groups_and_transforms () =
  let s =
    scene
      "let red = material { color: (1, 0, 0) }\n\
       group { translate: (10, 0, 0), material: red,\n\
      \  sphere { center: (0, 0, 0), radius: 1 }\n\
      \  sphere { center: (0, 0, 0), radius: 1, material: material { color: (0, 0, 1) } \
       } }"
  in
  let o0 = s.objects.(0) and o1 = s.objects.(1) in
  Alcotest.(check bool)
    "a member without a material takes the group's" true
    (o0.color = Color.v 1. 0. 0.);
  Alcotest.(check bool) "a member with its own keeps it" true (o1.color = Color.v 0. 0. 1.);
  veq "the group's transform applies" (Vec3.v 10. 0. 0.) (centre o0);
  let s =
    scene
      "sphere { center: (0,0,0), radius: 1, translate: (1, 0, 0), rotate: (0, 0, 90) }"
  in
  veq "translate then rotate" (Vec3.v 0. 1. 0.) (centre s.objects.(0));
  let s =
    scene
      "sphere { center: (0,0,0), radius: 1, rotate: (0, 0, 90), translate: (1, 0, 0) }"
  in
  veq "rotate then translate" (Vec3.v 1. 0. 0.) (centre s.objects.(0));
  let s = scene "sphere { center: (0,0,0), radius: 1, scale: 2, translate: (1, 0, 0) }" in
  let c, r = sphere_placed s.objects.(0) in
  veq "scale then translate" (Vec3.v 3. 0. 0.) (Vec3.add c (Vec3.v r 0. 0.))

let test_materials () =
  let s =
    scene
      "let glass = material { transparency: 0.9, ior: 1.5, color: (0.5, 0.5, 0.5) }\n\
       sphere { center: (0,0,0), radius: 1, material: material { base: glass, ior: 1.3 } }\n\
       plane { normal: (0, 1, 0), material: material { texture: checker((1,1,1), \
       (0,0,0), 2), bump: noise(1, 0.1) } }"
  in
  let m = s.objects.(0).material in
  feq "base copies" 0.9 m.transparency;
  feq "then overrides" 1.3 m.ior;
  feq "defaults stay" Material.default.diffuse m.diffuse;
  let p = s.objects.(1).material in
  Alcotest.(check bool)
    "checker texture" true
    (p.texture
    = Some (Description.Checker { c1 = Color.white; c2 = Color.black; size = 2. }));
  Alcotest.(check bool)
    "noise bump" true
    (p.bump = Some (Description.Noise_bump { scale = 1.; amount = 0.1 }));
  (* A material that writes its colour alone, as a base: its colour goes on, with the
     fields written over it. *)
  let s =
    scene
      "let red = material { color: (1, 0, 0) }\n\
       let shiny = material { base: red, specular: 0.5 }\n\
       let blue = material { base: shiny, color: (0, 0, 1) }\n\
       sphere { center: (0,0,0), radius: 1, material: red }\n\
       sphere { center: (3,0,0), radius: 1, material: shiny }\n\
       sphere { center: (6,0,0), radius: 1, material: blue }\n\
       sphere { center: (9,0,0), radius: 1, material: material { base: blue } }"
  in
  let colour_spec k = (s.objects.(k).color, s.objects.(k).material.specular) in
  List.iteri
    (fun k (c, sp) ->
      let c', sp' = colour_spec k in
      Alcotest.(check bool) (Printf.sprintf "object %d's colour" k) true (c' = c);
      feq (Printf.sprintf "object %d's specular" k) sp sp')
    [
      (Color.v 1. 0. 0., Material.default.specular);
      (Color.v 1. 0. 0., 0.5);
      (Color.v 0. 0. 1., 0.5);
      (Color.v 0. 0. 1., 0.5);
    ]

(* Equal materials are one record in the scene, and a loop that colours each object makes
   no material per object: the objects share one, each holding its own colour. *)
let test_materials_shared () =
  let s =
    scene
      "sphere { center: (0, 0, 0), radius: 1, material: material { color: (1, 0, 0), \
       specular: 0.5 } }\n\
       sphere { center: (3, 0, 0), radius: 1, material: material { specular: 0.5, color: \
       (1, 0, 0) } }"
  in
  Alcotest.(check bool)
    "two equal materials written apart compile to one" true
    (s.objects.(0).material == s.objects.(1).material);
  let n = 300 in
  let text =
    Printf.sprintf
      "let n = %d\n\
       let shiny = material { specular: 0.5, ior: 1.5 }\n\
       for i in 0 to n - 1 { for j in 0 to n - 1 { sphere { center: (i, 0, j), radius: \
       0.4, material: material { base: shiny, color: (i / n, j / n, 0.5) } } } }"
      n
  in
  let p = load text in
  (match Dsl.describe (Program.language p) ~time:0. ~frame:0 with
  | Ok d ->
      let first = (List.hd d.objects).material in
      Alcotest.(check bool)
        "the description's objects share the material they differ from in colour" true
        (List.for_all (fun (o : Description.obj) -> o.material == first) d.objects)
  | Error es -> Alcotest.failf "%s" (errors_text es));
  let s = scene_of p ~time:0. in
  Alcotest.(check int) "objects" (n * n) (Array.length s.objects);
  let m = s.objects.(0).material in
  Alcotest.(check bool)
    "the scene's objects share one material" true
    (Array.for_all (fun (o : Primitive.t) -> o.material == m) s.objects);
  feq "the base's fields" 0.5 m.specular;
  feq "the base's ior" 1.5 m.ior;
  (* Each object reads its own colour back, wherever the structure put it. *)
  let wrong = ref 0 in
  Array.iter
    (fun (o : Primitive.t) ->
      let c = centre o in
      let i = Float.round c.x and j = Float.round c.z in
      let f = Float.of_int n in
      if o.color <> Color.v (i /. f) (j /. f) 0.5 then incr wrong)
    s.objects;
  Alcotest.(check int) "objects whose colour is another's" 0 !wrong;
  (* A loop that computes another field from a few values (and a colour each) makes a
     record per value; one whose every value differs (past the table's 4096) a record
     each. Each object reads its own material back either way. *)
  let distinct_records (d : Description.t) =
    List.fold_left
      (fun seen (o : Description.obj) ->
        if List.exists (fun m -> m == o.material) seen then seen else o.material :: seen)
      [] d.objects
    |> List.length
  in
  List.iter
    (fun (n, specular, records) ->
      let text =
        Printf.sprintf
          "let n = %d\n\
          \           for i in 0 to n - 1 { for j in 0 to n - 1 { sphere { center: (i, \
           0, j),            radius: 0.4, material: material { color: (i / n, j / n, \
           0.5), specular: %s,            ior: 1.5 } } } }"
          n specular
      in
      let p = load text in
      match Dsl.describe (Program.language p) ~time:0. ~frame:0 with
      | Error es -> Alcotest.failf "%s" (errors_text es)
      | Ok d ->
          Alcotest.(check int)
            (Printf.sprintf "specular: %s, %d objects: material records" specular (n * n))
            records (distinct_records d);
          let wrong = ref 0 in
          List.iter
            (fun (o : Description.obj) ->
              let c =
                match o.shape with Sphere { center; _ } -> center | _ -> Vec3.zero
              in
              let i = c.x and j = c.z and f = Float.of_int n in
              let sp =
                if specular = "j % 4 / 4" then Float.rem j 4. /. 4.
                else ((i *. f) +. j) /. (f *. f)
              in
              match Description.object_material o with
              | Some m
                when m.color = Color.v (i /. f) (j /. f) 0.5
                     && m.specular = sp && m.ior = 1.5 ->
                  ()
              | _ -> incr wrong)
            d.objects;
          Alcotest.(check int)
            (Printf.sprintf "specular: %s: objects whose material is another's" specular)
            0 !wrong)
    [ (40, "j % 4 / 4", 4); (100, "(i * n + j) / (n * n)", 100 * 100) ];
  (* Each run shares its own records: a second frame makes its four again, and keeps
     none of the first's. (The loop reads [frame], so that each frame evaluates it, and
     no specular is the default's, whose option every run shares.) *)
  let p =
    load
      "animation { fps: 10, frames: 2 }\n\
       for i in 0 to 9 { for j in 0 to 9 { sphere { center: (i, 0, j), radius: 0.4 + 0 * \
       frame, material: material { color: (i / 10, j / 10, 0.5), specular: (j % 4 + 1) / \
       4 } } } }"
  in
  let run time frame =
    match Dsl.describe (Program.language p) ~time ~frame with
    | Ok d -> d
    | Error es -> Alcotest.failf "%s" (errors_text es)
  in
  let d0 = run 0. 0 and d1 = run 0.1 1 in
  Alcotest.(check int) "the second frame's records" 4 (distinct_records d1);
  Alcotest.(check bool)
    "none of them the first frame's" false
    (List.exists
       (fun (o : Description.obj) ->
         List.exists (fun (o0 : Description.obj) -> o0.material == o.material) d0.objects)
       d1.objects)

let test_settings_camera_lights () =
  let s =
    scene
      "settings { width: 320, height: 200, samples: 2, gamma: 2.2, background: (0.1, \
       0.2, 0.3), shadows: false }\n\
       camera { position: (0, 1, -3), fov: 40 }\n\
       light { position: (1, 2, 3), intensity: 2 }\n\
       light { direction: (0, -1, 0) }"
  in
  Alcotest.(check int) "width" 320 s.settings.width;
  Alcotest.(check int) "samples" 2 s.settings.samples;
  Alcotest.(check bool) "gamma number" true (s.settings.gamma = Settings.Power 2.2);
  Alcotest.(check bool) "shadows" false s.settings.shadows;
  feq "fov" 40. s.camera.fov;
  Alcotest.(check int) "two lights" 2 (Array.length s.lights);
  let d = scene "" in
  Alcotest.(check bool) "default settings" true (d.settings = Settings.default);
  feq "default camera" (-5.) d.camera.position.z

let test_animation_time () =
  let p =
    load
      "animation { fps: 10, frames: 20 }\nsphere { center: (time, frame, 0), radius: 1 }"
  in
  Alcotest.(check (option (pair (float 0.) int)))
    "animation"
    (Some (10., 20))
    (Program.animation p);
  (match Program.scene_at p ~time:1.5 ~frame:15 with
  | Ok s -> (
      match s.objects.(0).shape with
      | Shape.Sphere { center; _ } ->
          veq "time and frame are bound" (Vec3.v 1.5 15. 0.) center
      | _ -> Alcotest.fail "expected a sphere")
  | Error es -> Alcotest.fail (errors_text es));
  let p = load "animation { fps: 24, duration: 2 }" in
  Alcotest.(check (option (pair (float 0.) int)))
    "duration"
    (Some (24., 48))
    (Program.animation p);
  Alcotest.(check (option (pair (float 0.) int)))
    "defaults: 24 fps, 48 frames"
    (Some (24., 48))
    (Program.animation (load "animation { }"));
  Alcotest.(check (option (pair (float 0.) int)))
    "frames default to 48"
    (Some (12., 48))
    (Program.animation (load "animation { fps: 12 }"));
  Alcotest.(check (option (pair (float 0.) int)))
    "none" None
    (Program.animation (load ""))

let test_bodies () =
  let text =
    "physics { gravity: (0, -10, 0), method: \"verlet\" }\n\
     body ball { sphere { center: (0, 2, 0), radius: 0.5 } velocity: (1, 0, 0), mass: 2, \
     restitution: 0.5 }\n\
     camera { position: ball.position + (0, 0, -5), look_at: ball.position }\n\
     plane { normal: (0, 1, 0) }"
  in
  let p = load text in
  (match Program.bodies p with
  | [ b ] ->
      Alcotest.(check string) "name" "ball" b.name;
      veq "centre" (Vec3.v 0. 2. 0.) b.center;
      feq "mass" 2. b.mass;
      feq "restitution" 0.5 b.restitution
  | _ -> Alcotest.fail "one body");
  Alcotest.(check bool)
    "physics" true
    (match Dsl.physics (Program.language p) with
    | Some { method_ = Dsl.Verlet; gravity; _ } -> gravity.y = -10.
    | _ -> false);
  let hook name t =
    if name = "ball" then Some (Vec3.v t 7. 0., Vec3.v 1. 0. 0.) else None
  in
  match Program.scene_at ~body_state:hook p ~time:3. ~frame:0 with
  | Ok s ->
      veq "the camera follows the hook" (Vec3.v 3. 7. 0.) s.camera.look_at;
      let o = s.objects.(Array.length s.objects - 1) in
      veq "the body sphere is drawn at its position" (Vec3.v 3. 7. 0.)
        (Transform.point o.transform
           (match o.shape with Shape.Sphere { center; _ } -> center | _ -> Vec3.zero))
  | Error es -> Alcotest.fail (errors_text es)

(* Without a hook, bodies move by the engine among the scene's static planes,
   parallelograms and boxes: a drop in closed form until the impact, then a bounce, and at
   last rest on the floor. *)
let test_physics_wired () =
  let text =
    "animation { fps: 10, duration: 3 }\n\
     physics { gravity: (0, -10, 0), method: \"exact\" }\n\
     plane { normal: (0, 1, 0), offset: 0 }\n\
     body ball { sphere { center: (0, 2.5, 0), radius: 0.5 } restitution: 0.5 }\n\
     camera { position: (0, 1, -5), look_at: ball.position }"
  in
  let p = load text in
  let centre s =
    let o = (s : Scene.t).objects.(Array.length s.objects - 1) in
    Transform.point o.transform
      (match o.shape with Shape.Sphere { center; _ } -> center | _ -> Vec3.zero)
  in
  let at t = scene_of p ~time:t in
  (* Impact when the centre has fallen 2 m: t = sqrt(2·2/10). *)
  let t_hit = sqrt 0.4 in
  feq "free fall" (2.5 -. (5. *. 0.3 *. 0.3)) (centre (at 0.3)).y;
  feq "the camera looks at the moving ball" (centre (at 0.3)).y (at 0.3).camera.look_at.y;
  let v_up = 0.5 *. 10. *. t_hit in
  let dt = 0.1 in
  feq "after the bounce, the rebound in closed form"
    (0.5 +. (v_up *. dt) -. (5. *. dt *. dt))
    (centre (at (t_hit +. dt))).y;
  feq "at rest on the floor at the end" 0.5 (centre (at 3.)).y;
  (match Lancer.Program.colliders p with
  | [ Physics.Plane _ ] -> ()
  | _ -> Alcotest.fail "one plane collider");
  (* A rotated body keeps its radius; a body scaled unevenly is refused. *)
  (match
     Program.bodies
       (load
          "body b { sphere { center: (0, 2, 0), radius: 1, rotate: (0, 45, 0), scale: 2 \
           } }")
   with
  | [ b ] -> feq "radius under rotation and uniform scale" 2. b.radius
  | _ -> Alcotest.fail "one body");
  check_err "body b { sphere { center: (0, 2, 0), radius: 1, scale: (1, 2, 1) } }"
    "a body must stay a sphere";
  check_err "group { translate: (0, 10, 0) light { position: (0, 0, 0) } }"
    "`light` cannot be inside a group";
  (* A fixed step that would not fit in memory is refused, not attempted. *)
  (match
     Program.scene_at
       (load
          "animation { fps: 24, duration: 2 }\n\
           physics { method: \"verlet\", step: 1e-9 }\n\
           body b { sphere { center: (0, 2, 0), radius: 0.5 } }")
       ~time:1. ~frame:24
   with
  | Ok _ -> Alcotest.fail "a 2e9-step simulation was attempted"
  | Error es ->
      Alcotest.(check bool)
        (errors_text es) true
        (contains (errors_text es) "steps per body; the limit is 10000000"));
  (* An axis-aligned box is one collider; a rotated one is its six faces; spheres are none. *)
  let q =
    load
      "box { min: (0, 0, 0), max: (1, 1, 1), translate: (1, 0, 0) }\n\
       box { min: (0, 0, 0), max: (1, 1, 1), rotate: (0, 30, 0) }\n\
       sphere { center: (0, 5, 0), radius: 1 }\n\
       body b { sphere { center: (0, 3, 0), radius: 0.2 } }"
  in
  match Lancer.Program.colliders q with
  | Physics.Box { min; max } :: faces ->
      veq "translated box min" (Vec3.v 1. 0. 0.) min;
      veq "translated box max" (Vec3.v 2. 1. 1.) max;
      Alcotest.(check int) "six faces" 6 (List.length faces)
  | _ -> Alcotest.fail "a box, then faces"

let test_includes () =
  let dir =
    Filename.concat
      (Filename.get_temp_dir_name ())
      (Printf.sprintf "rts_inc_%d" (Unix.getpid ()))
  in
  (try Unix.mkdir dir 0o755 with _ -> ());
  let write f s =
    Out_channel.with_open_bin (Filename.concat dir f) (fun oc -> output_string oc s)
  in
  write "common.rts" "let r = 2\nsphere { center: (0, 0, 0), radius: r }";
  write "main.rts" "include \"common.rts\"\nsphere { center: (1, 0, 0), radius: r }";
  (match Program.load_file (Filename.concat dir "main.rts") with
  | Ok p -> (
      match Program.scene_at p ~time:0. ~frame:0 with
      | Ok s ->
          Alcotest.(check int) "included objects and names" 2 (Array.length s.objects)
      | Error es -> Alcotest.fail (errors_text es))
  | Error es -> Alcotest.fail (errors_text es));
  write "a.rts" "include \"b.rts\"";
  write "b.rts" "include \"a.rts\"";
  match Dsl.load_file (Filename.concat dir "a.rts") with
  | Ok _ -> Alcotest.fail "a cycle must fail"
  | Error es ->
      Alcotest.(check bool)
        "cycle" true
        (List.exists (fun (e : Error.t) -> contains e.message "include cycle") es)

(* Each POV-Ray directive is named in its own message, with what to write instead. *)
let test_directives () =
  List.iter
    (fun d ->
      let ms = errs (Printf.sprintf "#%s X\n" d) in
      if not (List.exists (fun m -> contains m (Printf.sprintf "`#%s` is not used" d)) ms)
      then Alcotest.failf "#%s: %s" d (String.concat "\n" ms))
    [
      "declare";
      "local";
      "undef";
      "include";
      "if";
      "ifdef";
      "ifndef";
      "else";
      "elseif";
      "switch";
      "case";
      "range";
      "break";
      "end";
      "for";
      "while";
      "macro";
      "version";
      "default";
      "debug";
      "warning";
      "error";
      "fopen";
    ];
  check_err "#for (I, 0, 9)" "write `for i in A to B step S { … }`";
  check_err "#while (I < 9)" "write `for i in A to B { … }`";
  check_err "#local R = 2" "write `let NAME = value`";
  check_err "#end" "closed by `}`";
  check_err "#else" "write `} else {`";
  check_err "#version 3.7;" "delete it"

(* A byte-order mark is skipped: the scene loads and columns count from what follows it;
   typographic quotes are named. *)
let test_bom_and_quotes () =
  let bom = "\xEF\xBB\xBF" in
  let s = scene (bom ^ "sphere { center: (0, 0, 0), radius: 2 }") in
  Alcotest.(check int) "one object" 1 (Array.length s.objects);
  (match Dsl.load_string ~filename:"test.rts" (bom ^ "let r = raduis") with
  | Error [ e ] -> Alcotest.(check (pair int int)) "line, column" (1, 9) (e.line, e.col)
  | _ -> Alcotest.fail "expected one error");
  List.iter
    (fun q ->
      check_err
        (Printf.sprintf "let t = image(%swood.png%s, 1)" q q)
        (Printf.sprintf "a typographic quote %s; write \"" q))
    [ "\xE2\x80\x9C"; "\xE2\x80\x98" ];
  check_err "let t = x\xE2\x80\x9D" "a typographic quote \xE2\x80\x9D";
  check_err "let t = x\xE2\x80\x99" "a typographic quote \xE2\x80\x99"

let test_errors () =
  check_err "sphere { center: (0,0,0), radiu: 1 }" "did you mean `radius`?";
  check_err "let radius = 1\nlet x = radis" "did you mean `radius`?";
  check_err "sphere { center: (0,0,0) }" "needs a `radius`";
  check_err "sphere { center: (0,0,0), radius: 0 }" "`radius` must be a length";
  check_err "sphere { center: (0,0,0), radius: 1e200 }" "`radius` must be a length";
  check_err "let m = material { ior: 0 }" "`ior` must be greater than 0";
  check_err "let m = material { reflection: 0.7, transparency: 0.7 }"
    "reflection + transparency";
  check_err "settings { width: 0 }" "`width`";
  check_err "let x = 1 / 0" "division by zero";
  check_err "let x = 1e300 * 1e300" "infinity";
  check_err "let x = (1, 2, 3) + 1" "cannot combine";
  check_err "for i in 0 to 1e12 { }" "loop would run";
  check_err "fn f(n) = f(n)\nlet x = f(1)" "nested more than";
  check_err "let x = 1 < 2 < 3" "comparisons do not chain";
  check_err
    "sphere { center: (0,0,0), radius: 1 } sphere { center: (0,0,0), radius: 1, radius: \
     2 }"
    "given twice";
  check_err "settings { }\nsettings { }" "settings is given twice";
  check_err "let x = \"unterminated" "not closed";
  check_err "/* open" "not closed";
  check_err "let x = 1 && 2" "write `and`";
  check_err "let a = \"x\000y\"" "not a text file";
  check_err "body b { plane { normal: (0, 1, 0) } }" "exactly one sphere";
  check_err "physics { method: \"eular\" }" "did you mean `euler`?";
  Alcotest.(check int)
    "independent errors are all reported" 3
    (List.length
       (errs "let a = 1 / 0\nlet b = nope\nsphere { center: (0,0,0), radius: -1 }"));
  Alcotest.(check int)
    "a failed let is not reported again where it is used" 1
    (List.length
       (errs "let a = 1 / 0\nlet b = a + 1\nsphere { center: (0,0,0), radius: a }"))

let test_error_display () =
  match
    Dsl.load_string ~filename:"x.rts" "sphere {\n  center: (0, 0, 0)\n  radiu: 2\n}"
  with
  | Ok _ -> Alcotest.fail "expected an error"
  | Error [ e ] ->
      Alcotest.(check string)
        "file:line:col, source line, caret"
        "x.rts:3:3: unknown field `radiu` in sphere; did you mean `radius`?\n\
        \  radiu: 2\n\
        \  ^^^^^\n"
        (Error.to_string e)
  | Error es -> Alcotest.failf "one error expected, got:\n%s" (errors_text es)

(* A 200 000-character line is shown as a window around the column, caret under it. *)
let test_long_line () =
  let text = "let x = " ^ String.concat "" (List.init 50_000 (fun _ -> "1 + ")) ^ "y" in
  match Dsl.load_string ~filename:"x.rts" text with
  | Ok _ -> Alcotest.fail "expected an error"
  | Error [ e ] -> (
      let lines = String.split_on_char '\n' (Error.to_string e) in
      match lines with
      | [ head; src; caret; "" ] ->
          Alcotest.(check bool) head true (contains head "unknown name `y`");
          Alcotest.(check bool) "short" true (String.length src < 200);
          Alcotest.(check bool) "marked as cut" true (String.sub src 0 3 = "\xe2\x80\xa6");
          Alcotest.(check int)
            "caret under the y"
            (String.index src 'y' - 2)
            (String.index caret '^')
      | _ -> Alcotest.failf "unexpected display:\n%s" (Error.to_string e))
  | Error es -> Alcotest.failf "one error expected, got:\n%s" (errors_text es)

(* Every scene of scenes/ (not bad/) loads and evaluates. *)
let scenes_dir = "../../scenes"

let test_scenes () =
  let files =
    Sys.readdir scenes_dir |> Array.to_list
    |> List.filter (fun f -> Filename.check_suffix f ".rts")
  in
  Alcotest.(check bool) "there are scenes" true (List.length files >= 6);
  List.iter
    (fun f ->
      let path = Filename.concat scenes_dir f in
      match Program.load_file path with
      | Ok p -> (
          match Program.scene_at p ~time:0. ~frame:0 with
          | Ok s ->
              ignore (Program.summary p s);
              ignore (Yojson.Safe.to_string (Program.to_json p s))
          | Error es -> Alcotest.failf "%s:\n%s" f (errors_text es))
      | Error es -> Alcotest.failf "%s:\n%s" f (errors_text es))
    files

(* A load that hands its objects over as it makes them ([emit]) hands over a
   description's objects, in order, and keeps none; a program that writes anything that
   could make it move (an animation, physics, a body, a shutter) hands over nothing and
   keeps them. Every scene of scenes/ and its folders (groups, CSG, macros, meshes,
   animations, bodies), and a program that nests what builds objects. *)
let test_emitted () =
  let files =
    Run_lancer.scene_files scenes_dir [ "."; "gallery"; "materials"; "bench" ]
  in
  let dir = Run_lancer.tmpdir "lancer-emitted" in
  let nested = Filename.concat dir "nested.rts" in
  Run_lancer.write_file nested
    {|fn pair(x) { sphere { center: (x, 0, 0), radius: 0.5 } box { min: (x, 1, 0), max: (x + 1, 2, 1) } }
light { position: (0, 5, -5) }
group {
  pair(1)
  group { pair(3) sphere { center: (0, 4, 0), radius: 1, material: material { color: (0.2, 0.4, 0.6) } } rotate: (0, 30, 0) }
  translate: (0, 1, 0)
}
for x in [5, 7] { if x > 6 { pair(x) } else { difference { box { min: (x, 0, 0), max: (x + 1, 1, 1) } sphere { center: (x, 1, 0), radius: 0.5 } } } }
union { group { pair(9) } sphere { center: (11, 0, 0), radius: 1 } }
|};
  let emitted = ref 0 and kept = ref 0 in
  List.iter
    (fun path ->
      match Dsl.load_file path with
      | Error es -> Alcotest.failf "%s:\n%s" path (errors_text es)
      | Ok whole -> (
          let objects = (Dsl.first whole).objects in
          let got = ref [] in
          match Dsl.load_file ~emit:(fun o -> got := o :: !got) path with
          | Error es -> Alcotest.failf "%s, emitted:\n%s" path (errors_text es)
          | Ok p ->
              let d = Dsl.first p in
              if Dsl.emitted p then (
                incr emitted;
                Alcotest.(check int) (path ^ ": none kept") 0 (List.length d.objects);
                Alcotest.(check bool) (path ^ ": released") true (Dsl.released p);
                Alcotest.(check int)
                  (path ^ ": every object handed over")
                  (List.length objects) (List.length !got);
                Alcotest.(check bool)
                  (path ^ ": the description's objects, in order")
                  true
                  (compare (List.rev !got) objects = 0))
              else (
                incr kept;
                Alcotest.(check int) (path ^ ": nothing handed over") 0 (List.length !got);
                Alcotest.(check bool)
                  (path ^ ": kept whole") true
                  (compare d.objects objects = 0);
                Alcotest.(check bool)
                  (path ^ ": it could move") true
                  (d.animation <> None || d.physics <> None || d.bodies <> []
                  || d.camera.shutter <> (0., 0.)))))
    (nested :: files);
  Sys.remove nested;
  Unix.rmdir dir;
  Alcotest.(check bool) "most scenes handed over" true (!emitted > 50);
  Alcotest.(check bool) "animations and bodies kept" true (!kept > 5)

let test_json () =
  let p =
    load
      "sphere { center: (1, 2, 3), radius: 4, translate: (1, 0, 0) }\n\
       light { position: (0, 5, 0) }"
  in
  match Program.scene_at p ~time:0. ~frame:0 with
  | Error es -> Alcotest.fail (errors_text es)
  | Ok s ->
      let j = Program.to_json p s in
      let open Yojson.Safe.Util in
      let o = List.hd (to_list (member "objects" j)) in
      Alcotest.(check string) "kind" "sphere" (to_string (member "kind" o));
      Alcotest.(check (float 0.)) "radius" 4. (to_number (member "radius" o));
      Alcotest.(check int) "lights" 1 (List.length (to_list (member "lights" j)))

(* ---------------------------------------------------------------------------------- *)
(* Robustness: no input makes the language raise. *)

let count =
  match Sys.getenv_opt "LANCER_FUZZ_COUNT" with Some n -> int_of_string n | None -> 2000

(* The boundary turns any exception into an "internal error": that is a crash too. *)
let no_crash text es =
  match List.find_opt (fun (e : Error.t) -> contains e.message "internal error") es with
  | Some e -> QCheck.Test.fail_reportf "crashed (%s) on:\n%s" e.message text
  | None -> true

let no_exception text =
  match Program.load_string ~filename:"fuzz.rts" text with
  | Ok p -> (
      match Program.scene_at p ~time:0.5 ~frame:1 with
      | Ok s ->
          ignore (Program.to_json p s);
          true
      | Error es -> no_crash text es)
  | Error es ->
      List.iter (fun e -> ignore (Error.to_string e)) es;
      no_crash text es
  | exception e ->
      QCheck.Test.fail_reportf "raised %s on:\n%s" (Printexc.to_string e) text

let tokens = Fuzz_gen.dsl_tokens

let token_seq =
  QCheck.make
    ~print:(fun s -> s)
    QCheck.Gen.(
      map
        (fun l -> String.concat " " l)
        (list_size (int_range 0 40)
           (map (fun i -> tokens.(i)) (int_bound (Array.length tokens - 1)))))

let valid =
  [|
    In_channel.with_open_bin
      (Filename.concat scenes_dir "showcase.rts")
      In_channel.input_all;
    "fn row(n) { for i in 0 to n { sphere { center: (i, 0, 0), radius: 0.5 } } }\n\
     row(3)\n\
     group { scale: 2, material: material { color: (1, 0, 0) }, plane { normal: (0, 1, \
     0) } }\n\
     body b { sphere { center: (0, 1, 0), radius: 1 } velocity: (0, 1, 0) }\n\
     camera { position: b.position + (0, 0, -4) }\n\
     animation { fps: 4, frames: 3 }\n\
     let x = if frame > 1 then sin(time) else hsv(0.5, 1, 1).x";
  |]

(* A valid scene with a few random edits: a character deleted, replaced or duplicated. *)
let mutated =
  let gen =
    QCheck.Gen.(
      let* base = oneofl (Array.to_list valid) in
      let* edits =
        list_size (int_range 1 4)
          (triple (int_bound 2) nat
             (oneofl
                [ "("; ")"; "{"; "}"; ","; "0"; "-"; "/"; "x"; ":"; "\""; "1e999"; " " ]))
      in
      return
        (List.fold_left
           (fun s (kind, pos, ins) ->
             let n = String.length s in
             if n = 0 then s
             else
               let p = pos mod n in
               match kind with
               | 0 -> String.sub s 0 p ^ String.sub s (p + 1) (n - p - 1)
               | 1 -> String.sub s 0 p ^ ins ^ String.sub s (p + 1) (n - p - 1)
               | _ -> String.sub s 0 p ^ ins ^ String.sub s p (n - p))
           base edits))
  in
  QCheck.make ~print:(fun s -> s) gen

(* The reader and the grammar read the same tree (locations included) wherever the
   reader reads one; where it does not, the grammar says why. *)
let same_tree text =
  match Lancer_dsl.Reader.program ~file:"fuzz.rts" text with
  | None -> true
  | Some (stmts, _) -> (
      match Lancer_dsl.Syntax.grammar ~file:"fuzz.rts" text with
      | Ok stmts' when stmts = stmts' -> true
      | Ok _ -> QCheck.Test.fail_reportf "the reader reads another tree in:\n%s" text
      | Error e ->
          QCheck.Test.fail_reportf "the reader reads what the grammar refuses (%s):\n%s"
            e.message text)

let rec scene_files dir =
  Sys.readdir dir |> Array.to_list |> List.sort compare
  |> List.concat_map (fun f ->
         let p = Filename.concat dir f in
         if Sys.is_directory p then scene_files p
         else if Filename.check_suffix f ".rts" then [ p ]
         else [])

let test_reader () =
  let files = scene_files scenes_dir @ scene_files "../../dsl/lancer" in
  Alcotest.(check bool) "the scenes are found" true (List.length files >= 40);
  List.iter
    (fun path ->
      let text = In_channel.with_open_bin path In_channel.input_all in
      match Lancer_dsl.Syntax.grammar ~file:path text with
      | Error _ -> ()
      | Ok stmts ->
          Alcotest.(check bool)
            (path ^ ": the reader reads what the grammar reads")
            true
            (Option.map fst (Lancer_dsl.Reader.program ~file:path text) = Some stmts))
    files;
  List.iter
    (fun text ->
      Alcotest.(check bool)
        (text ^ ": left to the grammar")
        true
        (Lancer_dsl.Reader.program ~file:"t.rts" text = None))
    [
      "let x = 1 < 2 < 3";
      "let x = 1 + if a then b else c";
      "let x = (1, 2, 3, 4)";
      "sphere { a: 1,, b: 2 }";
      "let x = 3.x";
      "let x = 1e999";
      "let x = \"open";
      "/* open";
      "let x = 1 && 2";
      "let é = 1";
      "f(1,)";
    ]

(* Expressions of every level of the precedence, nested: [let x = …]. *)
let expression =
  let gen =
    QCheck.Gen.(
      sized
      @@ fix (fun self n ->
             let atom =
               oneofl [ "1"; "2.5"; "x"; "v.y"; "f(1, y)"; "(1, 2, 3)"; "true"; "\"s\"" ]
             in
             if n <= 0 then atom
             else
               let sub = self (n / 2) in
               frequency
                 [
                   (2, atom);
                   ( 6,
                     let* a = sub and* b = sub in
                     let* op =
                       oneofl
                         [
                           "+";
                           "-";
                           "*";
                           "/";
                           "%";
                           "^";
                           "==";
                           "!=";
                           "<";
                           "<=";
                           ">";
                           ">=";
                           "and";
                           "or";
                         ]
                     in
                     return (a ^ " " ^ op ^ " " ^ b) );
                   (1, map (fun a -> "-" ^ a) sub);
                   (1, map (fun a -> "not " ^ a) sub);
                   (1, map (fun a -> "(" ^ a ^ ")") sub);
                   ( 1,
                     let* c = sub and* a = sub and* b = sub in
                     return ("if " ^ c ^ " then " ^ a ^ " else " ^ b) );
                   (1, map (fun a -> "(" ^ a ^ ").x") sub);
                 ]))
  in
  QCheck.make ~print:(fun s -> s) (QCheck.Gen.map (fun e -> "let x = " ^ e) gen)

(* Numerals as scenes write them: doubles printed in the usual formats, and strings of
   digits with a point and perhaps an exponent; each followed by what may follow a number
   in a scene. *)
let numeral =
  let gen =
    QCheck.Gen.(
      let double =
        let* bits = map Int64.of_int (int_bound max_int) in
        let* bits =
          map
            (fun b -> Int64.logor (Int64.shift_left bits 1) b)
            (map Int64.of_int (int_bound 1))
        in
        let x = Float.abs (Int64.float_of_bits bits) in
        let* fmt = oneofl [ "%.17g"; "%.16g"; "%.15g"; "%g"; "%.3f"; "%.6e"; "%.20e" ] in
        return
          (if Float.is_finite x then Printf.sprintf (Scanf.format_from_string fmt "%f") x
           else "1")
      and digits =
        let* d = string_size ~gen:numeral (int_range 1 24) in
        let* p = int_bound (String.length d) in
        let* e = opt (int_range (-400) 400) in
        return
          ((if p = 0 then "0" else String.sub d 0 p)
          ^ "."
          ^ String.sub d p (String.length d - p)
          ^ match e with Some e -> Printf.sprintf "e%d" e | None -> "")
      in
      pair (oneof [ double; digits ]) (oneofl [ ""; ")"; ","; " "; "}"; "x" ]))
  in
  QCheck.make ~print:(fun (n, tail) -> n ^ tail) gen

let decimal_reads (n, tail) =
  let c = { Lancer_dsl.Decimal.at = 0 } in
  let x = Lancer_dsl.Decimal.scan (n ^ tail) 0 c in
  let y = float_of_string n in
  if Int64.bits_of_float x <> Int64.bits_of_float y then
    QCheck.Test.fail_reportf "%s reads as %h, float_of_string as %h" n x y
  else if c.at <> String.length n then
    QCheck.Test.fail_reportf "%s ends at %d, not %d" (n ^ tail) c.at (String.length n)
  else true

let props =
  let rand = Random.State.make [| 2024 |] in
  List.map
    (QCheck_alcotest.to_alcotest ~rand)
    [
      QCheck.Test.make ~name:"numerals read as the double float_of_string gives"
        ~count:(20 * count) numeral decimal_reads;
      QCheck.Test.make ~name:"the reader reads random expressions as the grammar does"
        ~count expression same_tree;
      QCheck.Test.make ~name:"the reader reads random token sequences as the grammar does"
        ~count token_seq same_tree;
      QCheck.Test.make ~name:"the reader reads mutated valid scenes as the grammar does"
        ~count mutated same_tree;
      QCheck.Test.make
        ~name:
          "random token sequences give Ok or Error, never an exception nor an internal \
           error"
        ~count token_seq no_exception;
      QCheck.Test.make
        ~name:
          "mutated valid scenes give Ok or Error, never an exception nor an internal \
           error"
        ~count mutated no_exception;
    ]

(* ---------------------------------------------------------------------------------- *)
(* The description between the language and the renderer *)

module D = Description

(* A still is evaluated once: the description at time 0, frame 0 is the load's own. *)
let test_described_once () =
  let p = load "sphere { center: (0, 0, 0), radius: 1 }\nlight { position: (0, 5, 0) }" in
  (match Dsl.describe (Program.language p) ~time:0. ~frame:0 with
  | Ok d ->
      Alcotest.(check bool)
        "the load's description" true
        (d == Dsl.first (Program.language p))
  | Error es -> Alcotest.failf "%s" (errors_text es));
  match Dsl.describe (Program.language p) ~time:1. ~frame:24 with
  | Ok d ->
      Alcotest.(check bool)
        "another instant is evaluated" false
        (d == Dsl.first (Program.language p));
      Alcotest.(check (float 0.)) "its time" 1. d.time;
      Alcotest.(check int) "its frame" 24 d.frame
  | Error es -> Alcotest.failf "%s" (errors_text es)

(* A program's static part is the objects of the statements no instant changes, by
   position; an evaluation gives a static statement as its position, unless it starts
   with another count of objects than at the load (it is then evaluated again). *)
let test_static_parts () =
  let p =
    Program.language
      (load
         "settings { width: 4, height: 3 }\n\
         \          sphere { center: (0, 0, 0), radius: 1 }\n\
         \          sphere { center: (time, 0, 0), radius: 1 }\n\
         \          for i in 0 to floor(time * 3) { sphere { center: (i, 2, 0), radius: \
          0.5 } }\n\
         \          box { min: (0, 0, 0), max: (1, 1, 1) }\n")
  in
  let kinds objs = List.map (fun (o : D.obj) -> o.kind) objs in
  Alcotest.(check (list (pair int (list string))))
    "statements 1 and 4"
    [ (1, [ "sphere" ]); (4, [ "box" ]) ]
    (List.map (fun (i, objs) -> (i, kinds objs)) (Dsl.static p));
  let parts time =
    match Dsl.describe_parts p ~time ~frame:1 with
    | Ok (d, ps) ->
        Alcotest.(check int) "the description without objects" 0 (List.length d.objects);
        List.map
          (function
            | D.Static i -> Printf.sprintf "static %d" i
            | D.Built objs -> String.concat " " (kinds objs))
          ps
    | Error es -> Alcotest.failf "%s" (errors_text es)
  in
  Alcotest.(check (list string))
    "the loop builds as many as at the load"
    [ "static 1"; "sphere sphere"; "static 4" ]
    (parts 0.1);
  Alcotest.(check (list string))
    "the loop builds one more: the box is evaluated again"
    [ "static 1"; "sphere sphere sphere box" ]
    (parts 0.5)

(* The language names files and reads none: a scene whose image and mesh do not exist
   loads; the description holds the names as written and resolved, and where they were
   written; the renderer reports them there. *)
let test_files_by_name () =
  let text =
    "let m = material { texture: image(\"wood.png\", 2), bump: noise(0.5, 0.1) }\n\
     sphere { center: (0, 0, 0), radius: 1, material: m }\n\
     mesh { file: \"sub/teapot.obj\", smooth: false }\n"
  in
  let p =
    match Dsl.load_string ~filename:"dir/test.rts" text with
    | Ok p -> p
    | Error es -> Alcotest.failf "the language read a file:\n%s" (errors_text es)
  in
  let d = Dsl.first p in
  Alcotest.(check (list string))
    "the files named"
    [ "dir/sub/teapot.obj"; "dir/wood.png" ]
    d.files;
  (match d.objects with
  | [
   {
     kind = "sphere";
     material = Some { texture = Some (Image { image; scale }); bump; _ };
     _;
   };
   { kind = "mesh"; shape = Mesh { file; path; smooth; at }; _ };
  ] ->
      Alcotest.(check string) "as written" "wood.png" image.written;
      Alcotest.(check string) "resolved" "dir/wood.png" image.path;
      Alcotest.(check (pair int int))
        "at the image(…) call" (1, 29) (image.at.line, image.at.col);
      Alcotest.(check (float 0.)) "scale" 2. scale;
      Alcotest.(check bool)
        "the noise bump" true
        (bump = Some (D.Noise_bump { scale = 0.5; amount = 0.1 }));
      Alcotest.(check string) "the mesh as written" "sub/teapot.obj" file;
      Alcotest.(check string) "resolved" "dir/sub/teapot.obj" path;
      Alcotest.(check bool) "flat" false smooth;
      Alcotest.(check (pair int int)) "at its file field" (3, 14) (at.line, at.col)
  | _ -> Alcotest.fail "not the sphere and the mesh");
  match Compile.compile ~source:(Dsl.source p) (Compile.assets ()) d with
  | Ok _ -> Alcotest.fail "compiled without the files"
  | Error es ->
      Alcotest.(check (list (pair int int)))
        "the renderer reports each file where it was named"
        [ (1, 29); (3, 14) ]
        (List.map (fun (e : Error.t) -> (e.line, e.col)) es);
      Alcotest.(check bool)
        "as the language would" true
        (String.starts_with ~prefix:"cannot read the image \"wood.png\": no such file"
           (List.hd es).message)

(* A description made by hand (no language) compiles into a scene, transforms baked. *)
let test_compile_by_hand () =
  let obj shape kind : D.obj =
    {
      kind;
      shape;
      transform = Transform.translate (Vec3.v 0. 1. 0.);
      steps = [ Translate (Vec3.v 0. 1. 0.) ];
      material = Some { D.default_material with color = Color.v 1. 0. 0. };
      color = Color.v 1. 0. 0.;
      loc = Loc.whole_file "hand";
      body = None;
    }
  in
  let d : D.t =
    {
      file = "hand";
      time = 0.;
      frame = 0;
      settings = Settings.default;
      camera = Camera.default;
      lights = [];
      objects = [ obj (Sphere { center = Vec3.zero; radius = 2. }) "sphere" ];
      animation = None;
      physics = None;
      physics_loc = None;
      bodies = [];
      warnings = [];
      files = [];
    }
  in
  match Compile.compile (Compile.assets ()) d with
  | Error es -> Alcotest.failf "%s" (errors_text es)
  | Ok sc ->
      let o = sc.objects.(0) in
      Alcotest.(check bool) "red" true (o.color = Color.v 1. 0. 0.);
      Alcotest.(check bool)
        "placed by its transform" true
        (Vec3.equal_f (centre o) (Vec3.v 0. 1. 0.))

(* One missing file named two ways (from an include and from the main file): each place
   is told of it as it wrote it, though the file is looked for once. *)
let test_file_spellings () =
  let at line = { (Loc.whole_file "main.rts") with line; col = 1 } in
  let mesh file line : D.obj =
    {
      kind = "mesh";
      shape = Mesh { file; path = "sub/gone.obj"; smooth = false; at = at line };
      transform = Transform.identity;
      steps = [];
      material = None;
      color = D.default_material.color;
      loc = at line;
      body = None;
    }
  in
  let d : D.t =
    {
      file = "main.rts";
      time = 0.;
      frame = 0;
      settings = Settings.default;
      camera = Camera.default;
      lights = [];
      objects = [ mesh "gone.obj" 1; mesh "sub/gone.obj" 2 ];
      animation = None;
      physics = None;
      physics_loc = None;
      bodies = [];
      warnings = [];
      files = [];
    }
  in
  match Compile.compile (Compile.assets ()) d with
  | Ok _ -> Alcotest.fail "compiled without the file"
  | Error es ->
      Alcotest.(check (list string))
        "each as written"
        [
          "cannot read the mesh \"gone.obj\": no such file (looked for sub/gone.obj)";
          "cannot read the mesh \"sub/gone.obj\": no such file";
        ]
        (List.map (fun (e : Error.t) -> e.message) es)

(* Obstacles come from the description's shapes. *)
let test_colliders_of_description () =
  let p =
    load
      "plane { normal: (0, 2, 0), offset: 0 }\n\
       box { min: (-1, 0, -1), max: (1, 1, 1), rotate: (0, 45, 0) }\n\
       sphere { center: (0, 3, 0), radius: 1 }\n\
       difference { box { min: (-1, 0, -1), max: (1, 1, 1) } sphere { center: (0, 1, 0), \
       radius: 0.5 } }"
  in
  let objects = (Dsl.first (Program.language p)).objects in
  (match Physics.colliders (List.filteri (fun i _ -> i < 3) objects) with
  | Ok [ Physics.Plane { normal; offset }; _; _; _; _; _; _ ] ->
      Alcotest.(check bool)
        "the plane's unit normal" true
        (Vec3.equal_f normal Vec3.y_axis);
      Alcotest.(check (float 0.)) "offset" 0. offset
  | Ok cs -> Alcotest.failf "%d colliders" (List.length cs)
  | Error _ -> Alcotest.fail "refused");
  match Physics.colliders objects with
  | Error o -> Alcotest.(check string) "the difference is refused" "difference" o.kind
  | Ok _ -> Alcotest.fail "a difference collides"

let () =
  Alcotest.run "dsl"
    [
      ( "expressions",
        [
          Alcotest.test_case
            "operators follow the precedence of doc/reference/language.md" `Quick
            test_precedence;
          Alcotest.test_case
            "lists are made, indexed, counted and gone over; strings joined" `Quick
            test_lists_and_strings;
          Alcotest.test_case "vector arithmetic and components work component-wise" `Quick
            test_vectors;
          Alcotest.test_case "every built-in computes what its name says" `Quick
            test_builtins;
          Alcotest.test_case "let and fn are lexically scoped, and fn may recurse" `Quick
            test_let_fn_scoping;
        ] );
      ( "statements",
        [
          Alcotest.test_case
            "loops are inclusive, steps may be negative, macros add objects" `Quick
            test_loops_and_macros;
          Alcotest.test_case
            "groups pass transforms and material; transforms apply in written order"
            `Quick test_groups_and_transforms;
          Alcotest.test_case
            "a material copies its base, then overrides; textures and bumps evaluate"
            `Quick test_materials;
          Alcotest.test_case
            "equal materials are shared; a loop's colours are kept per object" `Quick
            test_materials_shared;
          Alcotest.test_case "settings, camera and lights take their fields and defaults"
            `Quick test_settings_camera_lights;
          Alcotest.test_case
            "time and frame are bound and animation reports fps and frames" `Quick
            test_animation_time;
          Alcotest.test_case
            "bodies and physics are evaluated and positions come from the hook" `Quick
            test_bodies;
          Alcotest.test_case
            "bodies fall, bounce and rest among the scene's static objects" `Quick
            test_physics_wired;
          Alcotest.test_case "includes are relative to the including file and cycles fail"
            `Quick test_includes;
        ] );
      ( "errors",
        [
          Alcotest.test_case "each kind of mistake gets its located message" `Quick
            test_errors;
          Alcotest.test_case "an error prints file:line:col, the line and a caret" `Quick
            test_error_display;
          Alcotest.test_case "each POV-Ray directive gets a hint of its own" `Quick
            test_directives;
          Alcotest.test_case "a byte-order mark is skipped and typographic quotes named"
            `Quick test_bom_and_quotes;
          Alcotest.test_case "a very long line is shown as a window around the error"
            `Quick test_long_line;
        ] );
      ( "description",
        [
          Alcotest.test_case
            "a still is evaluated once: at frame 0 the load's description" `Quick
            test_described_once;
          Alcotest.test_case "the static part, by position" `Quick test_static_parts;
          Alcotest.test_case
            "the language names images and meshes and reads none; the renderer reports \
             them where they were named"
            `Quick test_files_by_name;
          Alcotest.test_case "a description made by hand compiles" `Quick
            test_compile_by_hand;
          Alcotest.test_case "a file named two ways is reported as each place wrote it"
            `Quick test_file_spellings;
          Alcotest.test_case "colliders are the description's planes and boxes" `Quick
            test_colliders_of_description;
        ] );
      ( "scenes",
        [
          Alcotest.test_case "every scene in scenes/ loads and evaluates" `Quick
            test_scenes;
          Alcotest.test_case "objects handed over as they are made are the description's"
            `Quick test_emitted;
          Alcotest.test_case "the reader reads every scene as the grammar does" `Quick
            test_reader;
          Alcotest.test_case "to_json lists objects with their fields, and lights" `Quick
            test_json;
        ] );
      ("robustness", props);
    ]
