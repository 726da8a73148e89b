(* The compiled program as it runs: how names are found (slots, closures, shadowing), the
   limits, poisoned names, and the messages of mistakes (the checker's and the run's, in
   source order). *)

open Lancer_dsl
module D = Lancer_description.Description

let eval ?(time = 0.) ?(frame = 0) text = Pipeline.run ~time ~frame text

let objects text =
  match eval text with
  | Ok d -> d.objects
  | Error es ->
      Alcotest.failf "unexpected errors:\n%s"
        (String.concat "" (List.map Error.to_string es))

(* Every error as file:line:col: message, in source order. *)
let errors text =
  match eval text with
  | Ok _ -> Alcotest.failf "expected errors for:\n%s" text
  | Error es ->
      List.map (fun (e : Error.t) -> Printf.sprintf "%d:%d: %s" e.line e.col e.message) es

let check_errors msg text expected =
  Alcotest.(check (list string)) msg expected (errors text)

let spheres text =
  List.map
    (fun (o : D.obj) ->
      match o.shape with
      | D.Sphere { center; radius } -> (center.x, center.y, center.z, radius)
      | _ -> Alcotest.fail "not a sphere")
    (objects text)

let xs text = List.map (fun (x, _, _, _) -> x) (spheres text)
let radii text = List.map (fun (_, _, _, r) -> r) (spheres text)
let floats = Alcotest.(list (float 1e-12))

let test_closures () =
  Alcotest.check floats "a function defined in a loop sees that iteration's names"
    [ 10.; 20.; 30. ]
    (xs
       "for i in 1 to 3 {\n\
        let a = i * 10\n\
        fn g() = a\n\
        let a = 0\n\
        sphere { center: (g(), 0, 0), radius: 1 }\n\
        }");
  Alcotest.check floats "a recursive function defined in a loop" [ 0.; 1.; 2.; 3. ]
    (xs
       "for i in 0 to 3 {\n\
        fn f(n) = if n <= 0 then i else f(n - 1)\n\
        sphere { center: (f(3), 0, 0), radius: 1 }\n\
        }");
  Alcotest.check floats "a macro sees the names of its definition, not of its call" [ 2. ]
    (radii
       "let s = 2\n\
        fn put(x) { sphere { center: (x, 0, 0), radius: s } }\n\
        let s = 5\n\
        put(1)");
  Alcotest.check floats "a macro inside a macro reads its parameters" [ 5.; 5. ]
    (xs
       "fn outer(a) {\n\
        fn inner(b) { sphere { center: (a, b, 0), radius: b } }\n\
        inner(1)\n\
        inner(2)\n\
        }\n\
        outer(5)");
  Alcotest.check floats "...with each its own value" [ 1.; 2. ]
    (radii
       "fn outer(a) {\n\
        fn inner(b) { sphere { center: (a, b, 0), radius: b } }\n\
        inner(1)\n\
        inner(2)\n\
        }\n\
        outer(5)");
  Alcotest.check floats "a macro calls itself" [ 3.; 2.; 1. ]
    (xs "fn m(n) { if n > 0 { sphere { center: (n, 0, 0), radius: 1 }\nm(n - 1) } }\nm(3)")

let test_shadowing () =
  Alcotest.check floats "built-ins can be shadowed" [ 7. ]
    (radii
       "let sin = 3\n\
        fn cos(x) = x * 2\n\
        sphere { center: (0, 0, 0), radius: sin + cos(2) }");
  Alcotest.check floats "a loop's variable and its lets end with it" [ 100.; 7. ]
    (radii
       "let i = 100\n\
        let k = 7\n\
        for i in 1 to 2 { let k = i }\n\
        sphere { center: (0, 0, 0), radius: i }\n\
        sphere { center: (0, 0, 0), radius: k }");
  Alcotest.check floats "a let inside a block is seen by the fields after it only"
    [ 2.; 3. ]
    (radii
       "let r = 3\n\
        sphere { center: (0, 0, 0), let r = 2\n\
        radius: r }\n\
        sphere { center: (0, 0, 0), radius: r }");
  Alcotest.check floats "a parameter hides a name of the definition" [ 4. ]
    (radii "let x = 10\nfn f(x) = x * 2\nsphere { center: (0, 0, 0), radius: f(2) }");
  Alcotest.check floats "time and frame" [ 2.5 ]
    (match eval ~time:0.5 ~frame:2 "sphere { center: (0,0,0), radius: time + frame }" with
    | Ok d ->
        List.map
          (fun (o : D.obj) ->
            match o.shape with D.Sphere { radius; _ } -> radius | _ -> 0.)
          d.objects
    | Error _ -> Alcotest.fail "time and frame")

let test_limits () =
  check_errors "runaway recursion stops at the depth limit"
    "fn f(n) = f(n + 1)\nsphere { center: (0, 0, 0), radius: f(1) }"
    [ "1:11: calls are nested more than 1000 deep (runaway recursion?)" ];
  Alcotest.check floats "a recursion within the depth limit" [ 899. ]
    (radii
       "fn f(n) = if n <= 0 then 0 else 1 + f(n - 1)\n\
        sphere { center: (0, 0, 0), radius: f(899) }");
  check_errors "a loop in a macro called in a loop counts the loops around it"
    "fn row() { for j in 1 to 5000 { } }\nfor i in 1 to 5000 { row() }"
    [
      "1:12: this loop would run 5000 times inside loops that have 5000 iterations left \
       (25000000 in all); a scene may take at most 20000000 loop iterations and calls, \
       and build at most 10000000 objects";
    ];
  check_errors "calls count as steps"
    "fn f(n) = if n <= 0 then 0 else 1 + f(n - 1)\nfor i in 1 to 5000000 { let x = f(3) }"
    [
      "2:1: this scene takes more than 20000000 evaluation steps (loop iterations and \
       calls); that is the limit";
    ]

let test_poison () =
  check_errors "a failed definition is reported once, its uses are quiet"
    "let a = 1 / 0\n\
     let b = a + 1\n\
     sphere { center: (0, 0, 0), radius: b }\n\
     fn f(x) = x + a\n\
     sphere { center: (0, 0, 0), radius: f(1) }"
    [ "1:13: division by zero" ];
  check_errors "a definition that reads itself fails once"
    "let a = 1\nlet a = a + nope\nsphere { center: (0, 0, 0), radius: a }"
    [ "2:13: unknown name `nope`" ];
  check_errors "a function with a parameter named twice is poisoned"
    "fn f(a, a) = 1\nsphere { center: (0, 0, 0), radius: f(1, 2) }"
    [ "1:6: parameter `a` is named twice" ];
  check_errors "a body that fails leaves its name undefined"
    "body b { sphere { center: (0,0,0), radius: 1 } sphere { center: (0,0,0), radius: 1 \
     } }\n\
     sphere { center: b.position, radius: 1 }"
    [ "1:6: a body holds exactly one sphere { … }"; "2:18: unknown name `b`" ];
  check_errors "... or to what it named before"
    "let b = 2\n\
     body b { sphere { center: (0,0,0), radius: 1 } sphere { center: (0,0,0), radius: 1 \
     } }\n\
     sphere { center: b, radius: 1 }"
    [
      "2:6: a body holds exactly one sphere { … }";
      "3:18: `center` must be a vector (x, y, z), got a number";
    ];
  check_errors "... also when one of its fields failed"
    "let b = 2\n\
     body b { sphere { center: (0,0,0), radius: 1 } mass: nope }\n\
     sphere { center: b, radius: 1 }"
    [
      "2:54: unknown name `nope`";
      "3:18: `center` must be a vector (x, y, z), got a number";
    ]

let test_names () =
  check_errors "an unknown name with a hint from the names in scope"
    "let width = 2\nfn f(x) = x * widht\nsphere { center: (0, 0, 0), radius: f(1) }"
    [ "2:15: unknown name `widht`; did you mean `width`?" ];
  check_errors "an unknown name in a block"
    "let radius = 1\nsphere { center: (0,0,0), radius: radiu }"
    [ "2:35: unknown name `radiu`; did you mean `radius`?" ];
  Alcotest.(check int)
    "an unknown name in code that does not run is no error" 1
    (List.length
       (objects
          "if false { sphere { center: (0,0,0), radius: nope } }\n\
           fn h() = nope2\n\
           sphere { center: (0,0,0), radius: 1 }"));
  match errors "sphere { center: (0,0,0), radius: r }\nlet r = 1" with
  | [ m ] ->
      Alcotest.(check bool)
        "a name defined further down is said to be" true
        (String.length m > 30 && String.sub m 0 24 = "1:35: unknown name `r`: ")
  | ms -> Alcotest.failf "one error expected, got %d" (List.length ms)

let test_values () =
  Alcotest.check floats "vectors, components, pairs" [ 2.; 6.; 2.5 ]
    (radii
       "let v = (1, 2, 3) * 2\n\
        sphere { center: (v.x, v.y, v.z), radius: (1, 2, 3).y }\n\
        sphere { center: (0, 0, 0), radius: v.z }\n\
        sphere { center: (0, 0, 0), radius: max(1, 2.5) }");
  check_errors "what does not combine"
    "let p = (0.5, (1, 0, 0))\n\
     let a = p.x\n\
     let b = (1, 2, 3).w\n\
     let c = (1, 2, 3) + 1\n\
     let d = 2 / (1 - 1)\n\
     let e = 1 % 0\n\
     let f = (1, 2, 3) / 0\n\
     let g = 1e300 * 1e300\n\
     let h = sin((1, 2, 3))\n\
     let i = sqrt(-1)\n\
     let j = sin(1, 2)\n\
     let k = (-8) ^ (1 / 3)"
    [
      "2:11: `.x` needs a vector or a body, got a pair (t, colour)";
      "3:19: a vector has components `x`, `y` and `z`, not `w`";
      "4:9: `+` cannot combine a vector and a number";
      "5:13: division by zero";
      "6:13: modulo by zero";
      "7:21: division by zero";
      "8:9: this expression overflows to infinity";
      "9:13: argument 1 of `sin` must be a number, got a vector";
      "10:9: `sqrt` needs a value ≥ 0, got -1";
      "11:9: `sin` takes 1 argument, got 2";
      "12:9: -8 ^ 0.333333 is not a real number";
    ]

let test_calls () =
  check_errors "what is not called as it is defined"
    "fn m(x) { sphere { center: (x, 0, 0), radius: 1 } }\n\
     let a = m(1)\n\
     fn e(x) = x\n\
     e(1)\n\
     sin(2)\n\
     let q = 3\n\
     q(1)\n\
     let b = q(1)\n\
     let c = e(1, 2)\n\
     m(1, 2)"
    [
      "2:9: `m` is a scene macro (fn m(…) { … }): call it as a statement, not in an \
       expression";
      "4:1: `e` is an expression function (fn e(…) = …): use it in an expression, e.g. \
       let x = e(…)";
      "5:1: `sin` is a built-in function: use it in an expression";
      "7:1: `q` is a number, not a scene macro";
      "8:9: `q` is a number, not a function";
      "9:9: `e` takes 1 argument, got 2";
      "10:1: `m` takes 1 argument, got 2";
    ]

(* The blocks of many objects take a short path; their mistakes read as any block's. *)
let test_sphere_blocks () =
  check_errors "a sphere's mistakes"
    "sphere { center: (0,0,0), radius: (1,2,3) }\n\
     sphere { center: 1, radius: 2 }\n\
     sphere { center: (0,0,0), radius: -1 }\n\
     sphere { center: (0,0,1e200), radius: 1 }\n\
     sphere { radius: 1 }\n\
     sphere { center: (0,0,0), radius: 1, radius: 2 }\n\
     sphere { center: (0,0,0), radiu: 1 }\n\
     sphere { center: (0,0,0), radius: 1, material: 3 }\n\
     sphere { center: (0, 1 / 0, 0), radius: nope }"
    [
      "1:35: `radius` must be a number, got a vector";
      "2:18: `center` must be a vector (x, y, z), got a number";
      "3:35: `radius` must be a length in [1e-150, 1e150], got -1";
      "4:18: the coordinates of `center` must be within ±1e150";
      "5:1: sphere needs a `center` field";
      "6:38: `radius` is given twice in this sphere (first at line 6)";
      "7:27: unknown field `radiu` in sphere; did you mean `radius`?";
      "8:48: `material` must be a material (material { … }), got a number";
      "9:26: division by zero";
      "9:41: unknown name `nope`";
    ];
  match
    objects
      "let m = material { color: (1, 0, 0) }\n\
       sphere { material: m, radius: 2, center: (1, 2, 3) }"
  with
  | [ ({ shape = D.Sphere { center; radius }; material = Some _; steps = []; _ } as o) ]
    ->
      Alcotest.(check (list (float 0.)))
        "fields in any order" [ 1.; 2.; 3.; 2.; 1. ]
        [ center.x; center.y; center.z; radius; o.color.r ]
  | _ -> Alcotest.fail "one sphere with its material"

let test_other_blocks () =
  check_errors "other shapes' mistakes"
    "box { min: (1,1,1), max: (0,0,0) }\n\
     box { min: (0,0,0), max: (1,1,1), translate: 3 }\n\
     box { min: (0,0,0), max: (1,1,1), scale: 0 }\n\
     box { min: (0,0,0) }\n\
     triangle { a: (0,0,0), b: (1,1,1), c: (2,2,2) }\n\
     torus { center: (0,0,0), major: 1, minor: 0.2, axis: (0,0,0) }\n\
     plane { normal: (0,1,0), offset: true }\n\
     box { min: (0,0,0), max: (1,1,1), mass: 1 }"
    [
      "1:1: a box needs min < max on every axis";
      "2:46: `translate` must be a vector (x, y, z), got a number";
      "3:42: `scale` factors must be non-zero, with magnitudes in [1e-150, 1e150]";
      "4:1: box needs a `max` field";
      "5:1: the corners of a triangle must not be in a line";
      "6:54: `axis` must be a non-zero vector";
      "7:34: `offset` must be a number, got a boolean";
      "8:35: unknown field `mass` in box";
    ];
  match
    objects
      "box { min: (0, 0, 0), max: (1, 1, 1), translate: (1, 0, 0), rotate: (0, 90, 0), \
       translate: (0, 2, 0) }"
  with
  | [ { shape = D.Box _; steps = [ Translate a; Rotate _; Translate b ]; _ } ] ->
      Alcotest.(check (list (float 0.)))
        "transforms in the order written" [ 1.; 2. ] [ a.x; b.y ]
  | _ -> Alcotest.fail "one box with three steps"

(* A material block in a loop: each iteration's mistakes read as any material's, once
   each; right values make the material they say, and a site whose values do not change
   makes one material. *)
let test_material_blocks () =
  check_errors "a material's mistakes, in a loop"
    "for i in 0 to 3 {\n\
     sphere { center: (i, 0, 0), radius: 1, material: material {\n\
     color: if i == 1 then 3 else (1, 1, 1), ambient: if i == 2 then -1 else 0.1,\n\
     color: (1, 1, 1) } }\n\
     sphere { center: (i, 0, 0), radius: 1, material: material { color: (1, 1 - i, 0),\n\
     reflection: i / 2, transparency: 0.6 } }\n\
     sphere { center: (i, 0, 0), radius: 1, material: material { colr: (1, 1, 1),\n\
     ior: i, specular: 1 / (i - 2), fresnel: i } }\n\
     }"
    [
      "3:8: `color` must be a vector (x, y, z), got a number";
      "3:50: `ambient` must be in [0, 1e150], got -1";
      "4:1: `color` is given twice in this material (first at line 3)";
      "5:68: a colour has no negative component; `color` is (1, -1, 0)";
      "5:68: a colour has no negative component; `color` is (1, -2, 0)";
      "6:13: `reflection` must be in [0, 1], got 1.5";
      "6:34: reflection + transparency must be at most 1, got 0.5 + 0.6 = 1.1";
      "7:61: unknown field `colr` in material; did you mean `color`?";
      "8:6: `ior` must be greater than 0, got 0";
      "8:19: `specular` must be in [0, 1e150], got -0.5";
      "8:19: `specular` must be in [0, 1e150], got -1";
      "8:23: division by zero";
      "8:41: `fresnel` must be true or false, got a number";
    ];
  let materials text =
    List.map
      (fun (o : D.obj) ->
        match D.object_material o with Some m -> m | None -> Alcotest.fail "no material")
      (objects text)
  in
  let ms =
    materials
      "let a = (1, 0, 0)\n\
       let b = (0, 0, 1)\n\
       for i in 0 to 3 {\n\
       sphere { center: (i, 0, 0), radius: 1,\n\
       material: material { color: if i % 2 == 0 then a else b, specular: i / 2,\n\
       fresnel: i >= 2, ior: 1.5 } }\n\
       }"
  in
  Alcotest.(check (list (list (float 0.))))
    "each iteration's values"
    [
      [ 1.; 0.; 0.; 0.; 0.; 1.5; 0.1; 0.9 ];
      [ 0.; 0.; 1.; 0.5; 0.; 1.5; 0.1; 0.9 ];
      [ 1.; 0.; 0.; 1.; 1.; 1.5; 0.1; 0.9 ];
      [ 0.; 0.; 1.; 1.5; 1.; 1.5; 0.1; 0.9 ];
    ]
    (List.map
       (fun (m : D.material) ->
         [
           m.color.r;
           m.color.g;
           m.color.b;
           m.specular;
           (if m.fresnel then 1. else 0.);
           m.ior;
           m.ambient;
           m.diffuse;
         ])
       ms);
  match
    materials
      "for i in 0 to 2 {\n\
       sphere { center: (i, 0, 0), radius: 1,\n\
       material: material { color: (0.9, 0.5, 0.2), specular: 0.5, shininess: 40 } }\n\
       }"
  with
  | [ m0; m1; m2 ] ->
      Alcotest.(check bool)
        "one material for a site of constants" true
        (m0 == m1 && m1 == m2);
      Alcotest.(check (list (float 0.)))
        "its values" [ 0.9; 0.5; 0.2; 0.5; 40. ]
        [ m0.color.r; m0.color.g; m0.color.b; m0.specular; m0.shininess ]
  | _ -> Alcotest.fail "three spheres"

(* Transformed objects and groups in a loop: each iteration's mistakes read as any
   block's; right ones give the transforms written, in order, groups' after. *)
let test_transformed_blocks () =
  check_errors "transforms' mistakes, in a loop"
    "for i in 0 to 2 {\n\
     sphere { center: (0, 0, 0), radius: 1, translate: if i == 1 then 2 else (i, 0, 0),\n\
     scale: i }\n\
     box { min: (0, 0, 0), max: (1, 1, i), rotate: (0, 1e200 * i, 0) }\n\
     group { rotate: (0, 90, 1 / (i - 1)), sphere { center: (0, 0, 0), radius: 1 } }\n\
     group { sphere { center: (0, 0, 0), radius: 1 }, material: i, scale: (1, 0, i) }\n\
     torus { center: (0, 0, 0), major: 1, minor: 0.2, axis: (0, 1, 0), scale: (1, i, 1) }\n\
     }"
    [
      "2:51: `translate` must be a vector (x, y, z), got a number";
      "3:8: `scale` factors must be non-zero, with magnitudes in [1e-150, 1e150]";
      "4:1: a box needs min < max on every axis";
      "4:47: the coordinates of `rotate` must be within ±1e150";
      "5:29: division by zero";
      "6:60: `material` must be a material (material { … }), got a number";
      "6:70: `scale` factors must be non-zero, with magnitudes in [1e-150, 1e150]";
      "7:74: `scale` factors must be non-zero, with magnitudes in [1e-150, 1e150]";
    ];
  let objs =
    objects
      "let m = material { color: (1, 0, 0) }\n\
       for i in 0 to 1 {\n\
       group { translate: (10 * i, 0, 0), material: m,\n\
       sphere { center: (1, 0, 0), radius: 1, scale: 2, translate: (0, i, 0) }\n\
       box { min: (0, 0, 0), max: (1, 1, 1), rotate: (0, 90, 0),\n\
       material: material { ambient: 0.5 } }\n\
       group { torus { center: (0, 0, 0), major: 1, minor: 0.2, axis: (0, 1, 0) } }\n\
       }\n\
       }"
  in
  let step = function
    | D.Translate v -> Printf.sprintf "t(%g,%g,%g)" v.x v.y v.z
    | D.Rotate v -> Printf.sprintf "r(%g,%g,%g)" v.x v.y v.z
    | D.Scale v -> Printf.sprintf "s(%g,%g,%g)" v.x v.y v.z
  in
  Alcotest.(check (list string))
    "each object's steps, where its origin goes, its material"
    [
      "sphere s(2,2,2) t(0,0,0) t(0,0,0) (0,0,0) 1";
      "box r(0,90,0) t(0,0,0) (0,0,0) 0.5";
      "torus t(0,0,0) (0,0,0) 1";
      "sphere s(2,2,2) t(0,1,0) t(10,0,0) (10,1,0) 1";
      "box r(0,90,0) t(10,0,0) (10,0,0) 0.5";
      "torus t(10,0,0) (10,0,0) 1";
    ]
    (List.map
       (fun (o : D.obj) ->
         let p = Lancer_math.Transform.point o.transform (Lancer_math.Vec3.v 0. 0. 0.) in
         Printf.sprintf "%s %s (%g,%g,%g) %g" o.kind
           (String.concat " " (List.map step o.steps))
           p.x p.y p.z
           (match D.object_material o with
           | Some m -> if m.ambient = 0.5 then 0.5 else m.color.r
           | None -> -1.))
       objs)

let test_includes () =
  let dir =
    Filename.concat
      (Filename.get_temp_dir_name ())
      (Printf.sprintf "rts_interp_%d" (Unix.getpid ()))
  in
  (try Unix.mkdir dir 0o755 with _ -> ());
  let write f s =
    Out_channel.with_open_bin (Filename.concat dir f) (fun oc -> output_string oc s)
  in
  write "lib.rts"
    "let k = 3\n\
     fn scaled(x) = x * k\n\
     fn put(x) { sphere { center: (x, 0, 0), radius: k } }";
  write "main.rts"
    "include \"lib.rts\"\n\
     let k = 10\n\
     put(scaled(2))\n\
     sphere { center: (0, 0, 0), radius: k }";
  match Dsl.load_file (Filename.concat dir "main.rts") with
  | Error es -> Alcotest.fail (String.concat "" (List.map Error.to_string es))
  | Ok p -> (
      match Dsl.describe p ~time:0. ~frame:0 with
      | Error es -> Alcotest.fail (String.concat "" (List.map Error.to_string es))
      | Ok d ->
          Alcotest.check floats "an include's names, and the names after it"
            [ 6.; 3.; 0.; 10. ]
            (List.concat_map
               (fun (o : D.obj) ->
                 match o.shape with
                 | D.Sphere { center; radius } -> [ center.x; radius ]
                 | _ -> [])
               d.objects))

let () =
  Alcotest.run "interpreter"
    [
      ( "names",
        [
          Alcotest.test_case "functions and macros keep the names of their definition"
            `Quick test_closures;
          Alcotest.test_case "a name hides another for the code after it" `Quick
            test_shadowing;
          Alcotest.test_case "an unknown name, and its hint, when its code runs" `Quick
            test_names;
          Alcotest.test_case "an include's names are the program's after it" `Quick
            test_includes;
        ] );
      ( "running",
        [
          Alcotest.test_case "the depth and step limits" `Quick test_limits;
          Alcotest.test_case "a failed definition is reported once" `Quick test_poison;
          Alcotest.test_case "values and what does not combine" `Quick test_values;
          Alcotest.test_case "calls of what is not a function or not a macro" `Quick
            test_calls;
          Alcotest.test_case "sphere blocks, right and wrong" `Quick test_sphere_blocks;
          Alcotest.test_case "other object blocks, right and wrong" `Quick
            test_other_blocks;
          Alcotest.test_case "material blocks in a loop, right and wrong" `Quick
            test_material_blocks;
          Alcotest.test_case "transformed blocks and groups in a loop, right and wrong"
            `Quick test_transformed_blocks;
        ] );
    ]
