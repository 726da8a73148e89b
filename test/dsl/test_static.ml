(* The static check of a whole program: mistakes in code that does not run (a branch not
   taken, a macro or function never called, a loop that runs zero times, an included
   file) are reported with the evaluator's message and location, once; and no scene of
   scenes/ is refused. *)

module Dsl = Lancer_dsl.Dsl
module Error = Lancer_dsl.Error
module Eval = Lancer_dsl.Eval
module Syntax = Lancer_dsl.Syntax
module Static_check = Lancer_dsl.Static_check

let errors_text es = String.concat "" (List.map Error.to_string es)

(* The errors of a program loaded as "test.rts", as printed (first line of each). *)
let errors ?(filename = "test.rts") text =
  match Dsl.load_string ~filename text with
  | Ok _ -> []
  | Error es ->
      List.map (fun e -> List.hd (String.split_on_char '\n' (Error.to_string e))) es

let check_errors name text expected =
  Alcotest.(check (list string)) name expected (errors text)

let test_branch_not_taken () =
  check_errors "a misspelt field in a branch not taken"
    "if false { sphere { center: (0, 0, 0), radiu: 1 } }\n"
    [ "test.rts:1:40: unknown field `radiu` in sphere; did you mean `radius`?" ];
  check_errors "in the else branch of a condition that holds"
    "let n = 3\n\
     if n > 2 {\n\
    \  sphere { center: (0, 0, 0), radius: 1 }\n\
     } else {\n\
    \  box { min: (0, 0, 0), maxx: (1, 1, 1) }\n\
     }\n"
    [ "test.rts:5:25: unknown field `maxx` in box; did you mean `max`?" ];
  check_errors "an unknown block kind in a branch not taken"
    "if 1 > 2 { sphre { center: (0, 0, 0), radius: 1 } }\n"
    [ "test.rts:1:12: unknown block `sphre`; did you mean `sphere`?" ]

let test_macro_never_called () =
  check_errors "a number for a vector field in a macro never called"
    "fn post(x, h) {\n  sphere { center: 2, radius: h }\n}\n"
    [ "test.rts:2:20: `center` must be a vector (x, y, z), got a number" ];
  check_errors "types evident from operators and built-ins on literals"
    "fn m() {\n\
    \  sphere { center: 2 * 3 + 1, radius: (1, 2, 3) * 2 }\n\
    \  cylinder { base: (0, 0, 0), top: (0, 1, 0), radius: 1, caps: sin(1) }\n\
    \  box { min: (0, 0, 0), max: (1, 1, 1), material: rgb(1, 0, 0) }\n\
     }\n"
    [
      "test.rts:2:20: `center` must be a vector (x, y, z), got a number";
      "test.rts:2:39: `radius` must be a number, got a vector";
      "test.rts:3:64: `caps` must be true or false, got a number";
      "test.rts:4:51: `material` must be a material (material { … }), got a vector";
    ];
  check_errors "a name bound to a literal has its type"
    "let r = (1, 1, 1)\nfn m() { sphere { center: (0, 0, 0), radius: r } }\n"
    [ "test.rts:2:46: `radius` must be a number, got a vector" ]

let test_functions () =
  check_errors "a material in a function never called"
    "fn shiny(c) = material { colour: c, specular: 0.5 }\n"
    [ "test.rts:1:26: unknown field `colour` in material; did you mean `color`?" ];
  check_errors "a bump that cannot be one, in the branch not taken of a conditional"
    "fn f(x) = if x > 0 then material { bump: 0.3 } else material { }\n"
    [
      "test.rts:1:42: `bump` must be noise(scale, amount) or image(\"file.png\", \
       amount), got a number";
    ]

let test_loops () =
  check_errors "in a loop that runs zero times (a warning, not an error, by itself)"
    "for i in 0 to -1 { sphere { center: (i, 0, 0), radius: 1, translate: 1 } }\n"
    [ "test.rts:1:70: `translate` must be a vector (x, y, z), got a number" ];
  check_errors "a loop variable is a number"
    "if false { for i in 0 to 3 { sphere { center: i, radius: 1 } } }\n"
    [ "test.rts:1:47: `center` must be a vector (x, y, z), got a number" ]

let test_groups_and_csg () =
  check_errors "in nested groups and CSG blocks"
    "fn dice() {\n\
    \  group {\n\
    \    difference {\n\
    \      box { min: (-1, -1, -1), max: 1 }\n\
    \      union { sphere { center: (0, 1, 0), radius: 0.3 } scal: 2 }\n\
    \    }\n\
    \    rotate: (0, 30, 0), material: \"gold\"\n\
    \  }\n\
     }\n"
    [
      "test.rts:4:37: `max` must be a vector (x, y, z), got a number";
      "test.rts:5:57: unknown field `scal` in union; did you mean `scale`?";
      "test.rts:7:35: `material` must be a material (material { … }), got a string";
    ];
  check_errors "blocks that cannot be inside a group, and objects in a material"
    "if false {\n\
    \  group { light { position: (0, 1, 0) } }\n\
    \  let m = material { sphere { center: (0, 0, 0), radius: 1 } }\n\
     }\n"
    [
      "test.rts:2:11: `light` cannot be inside a group: a group's transforms and \
       material apply to objects only; write it at top level";
      "test.rts:3:22: a material holds only `field: value` pairs (and `let`); objects go \
       in a `group`";
    ];
  check_errors "fields that do not apply to the kind written"
    "if false {\n\
    \  light { position: (0, 5, 0), inner: 10 }\n\
    \  camera { kind: \"fisheye\", width: 2 }\n\
     }\n"
    [
      "test.rts:2:32: `inner` is for a spot light: give it a `point_at`";
      "test.rts:3:36: `width` is for an orthographic camera (kind: \"orthographic\")";
    ];
  check_errors "a field of the block's own does not stand for a missing one"
    "if false { triangle { a: (0, 0, 0), b: (1, 0, 0) } }\n"
    [ "test.rts:1:12: triangle needs a `c` field" ];
  check_errors "a missing required field and a field given twice"
    "if false { disk { center: (0, 0, 0), radius: 1, radius: 2 } }\n"
    [
      "test.rts:1:12: disk needs a `normal` field";
      "test.rts:1:49: `radius` is given twice in this disk (first at line 1)";
    ]

(* A scratch directory under the system's temporary directory, removed afterwards. *)
let with_dir f =
  let dir =
    Filename.concat
      (Filename.get_temp_dir_name ())
      (Printf.sprintf "lancer-static-%d-%d" (Unix.getpid ()) (Random.bits ()))
  in
  Unix.mkdir dir 0o700;
  Fun.protect
    ~finally:(fun () ->
      Array.iter (fun f -> Sys.remove (Filename.concat dir f)) (Sys.readdir dir);
      Unix.rmdir dir)
    (fun () -> f dir)

let write path text = Out_channel.with_open_bin path (fun oc -> output_string oc text)

let test_includes () =
  with_dir (fun dir ->
      write
        (Filename.concat dir "part.rts")
        "fn pillar(x) {\n\
        \  cylinder { base: (x, 0, 0), top: (x, 2, 0), radius: 0.2, cap: true }\n\
         }\n";
      let main = Filename.concat dir "main.rts" in
      write main "include \"part.rts\"\nif false { pillar(1) }\n";
      match Dsl.load_file main with
      | Ok _ -> Alcotest.fail "a mistake in an included macro was not reported"
      | Error [ e ] ->
          Alcotest.(check string)
            "located in the included file, with the include that brought it"
            (Printf.sprintf
               "%s:2:60: unknown field `cap` in cylinder; did you mean `caps`?\n\
               \  cylinder { base: (x, 0, 0), top: (x, 2, 0), radius: 0.2, cap: true }\n\
                %s^^^\n\
               \  included from %s:1:1\n"
               (Filename.concat dir "part.rts")
               (String.make 59 ' ') main)
            (Error.to_string e)
      | Error es -> Alcotest.failf "expected one error, got:\n%s" (errors_text es))

let test_reported_once () =
  check_errors "a mistake in code that runs is reported once"
    "sphere { center: (0, 0, 0), radius: (1, 1, 1), colr: 1 }\n"
    [
      "test.rts:1:37: `radius` must be a number, got a vector";
      "test.rts:1:48: unknown field `colr` in sphere";
    ];
  check_errors "a transform whose value failed is not reported again"
    "sphere { center: (0, 0, 0), radius: 1, translate: nope, scale: 1 / 0 }\n"
    [ "test.rts:1:51: unknown name `nope`"; "test.rts:1:68: division by zero" ];
  check_errors "a use of a value whose definition failed is not reported again"
    "let m = material { colr: (1, 0, 0) }\nif false { sphere { center: m, radius: 1 } }\n"
    [ "test.rts:1:20: unknown field `colr` in material; did you mean `color`?" ]

(* The evaluator's own errors for a program, without the static check. *)
let eval_errors text =
  match Syntax.parse ~file:"test.rts" text with
  | Error e -> Alcotest.failf "syntax error: %s" (Error.to_string e)
  | Ok stmts -> (
      let sources = Hashtbl.create 1 in
      Hashtbl.replace sources "test.rts" text;
      match Eval.run ~objects:false ~file:"test.rts" ~sources ~time:0. ~frame:0 stmts with
      | Ok _ -> []
      | Error es -> es)

let static_errors text =
  match Syntax.parse ~file:"test.rts" text with
  | Error e -> Alcotest.failf "syntax error: %s" (Error.to_string e)
  | Ok stmts ->
      let sources = Hashtbl.create 1 in
      Hashtbl.replace sources "test.rts" text;
      Static_check.run ~sources stmts

(* Mistakes in code that runs: each one the static check reports, the evaluator reports
   with the same text at the same place. *)
let same_as_evaluator =
  [
    "sphere { center: (0, 0, 0), radiu: 2 }";
    "settings { width: 640, heigth: 480, gamma: true, fog: (1, 1, 1) }";
    "settings { background: checker((1, 1, 1), (0, 0, 0), 1), jitter: 1 }";
    "camera { kind: 3, position: 1, fov: \"wide\" }";
    "camera { kind: \"orthographic\", width: true }";
    "light { position: (0, 1, 0), color: 1, intensity: (1, 1, 1), samples: false }";
    "light { position: (0, 1, 0), point_at: (0, 0, 0), inner: \"x\", outer: (1, 2, 3) }";
    "light { direction: 1, colour: (1, 1, 1) }";
    "light { color: (1, 1, 1) }";
    "light { position: (0, 1, 0), direction: (0, -1, 0), zzz: 1 }";
    "animation { fps: \"24\", frames: (1, 2, 3) }";
    "animation { fps: 24, duration: true }";
    "physics { gravity: 9.81, method: 1, step: (1, 1, 1) }";
    "sphere { center: (0, 0, 0), radius: 1, material: material { color: 1, texture: \
     true, bump: (1, 1, 1), base: 1, fresnel: 0, ior: \"1\" } }";
    "plane { normal: 1 } triangle { a: 1, b: (0, 1, 0) } box { min: true, max: (1, 1, \
     1), scale: \"x\", rotate: 1, translate: true }";
    "cone { base: (0, 0, 0), top: (0, 1, 0), base_radius: (1, 1, 1), top_radius: 0, \
     caps: 1 }";
    "mesh { file: 3 } height_field { file: \"h.png\", size: 1, origin: true }";
    "torus { center: (0, 0, 0), major: 1, minor: 0.2, axis: 0 } paraboloid { vertex: (0, \
     0, 0), radius: 1, height: (1, 1, 1) }";
    "group { sphere { center: (0, 0, 0), radius: 1 } material: 1, scal: 2 }";
    "union { sphere { center: (0, 0, 0), radius: 1 } rotate: 1 }";
    "body b { sphere { center: (0, 1, 0), radius: 1 } mass: (1, 1, 1), material: 1 }";
    "group { camera { } settings { width: 1 } }";
    "let m = material { sphere { center: (0, 0, 0), radius: 1 } }";
    "spher { center: (0, 0, 0) }";
    "disk { center: (0, 0, 0), normal: (0, 1, 0), radius: 1, radius: 2 }";
    "cylinder { base: (0, 0, 0), top: (0, 1, 0) }";
    "triangle { a: (0, 0, 0), b: (1, 0, 0), cc: (0, 1, 0) }";
    "group { body b { sphere { center: (0, 0, 0), radius: 1 } } }";
    "camera { kind: \"orthographic\", fov: 30 }";
    "camera { width: 2 } animation { frames: 10, duration: 2 }";
    "light { position: (0, 1, 0), inner: 10, outer: 20 }";
  ]

let test_same_as_evaluator () =
  List.iter
    (fun text ->
      let key (e : Error.t) = Printf.sprintf "%d:%d: %s" e.line e.col e.message in
      let static = List.map key (static_errors text) in
      let evaluated = List.map key (eval_errors text) in
      if static = [] then Alcotest.failf "the static check found nothing in:\n%s" text;
      List.iter
        (fun s ->
          if not (List.mem s evaluated) then
            Alcotest.failf "%s\nstatic check: %s\nevaluator:\n%s" text s
              (String.concat "\n" evaluated))
        static)
    same_as_evaluator

(* No scene that the evaluator accepts is refused: every scene of scenes/ (gallery,
   bench, materials …, not bad/) and the library loads. *)
let rec scene_files dir =
  Sys.readdir dir |> Array.to_list |> List.sort compare
  |> List.concat_map (fun f ->
         let p = Filename.concat dir f in
         if Sys.is_directory p then if f = "bad" then [] else scene_files p
         else if Filename.check_suffix f ".rts" then [ p ]
         else [])

let test_scenes_pass () =
  let files = scene_files "../../scenes" @ scene_files "../../dsl/lancer" in
  Alcotest.(check bool) "the scenes are found" true (List.length files >= 40);
  List.iter
    (fun path ->
      match Dsl.load_file path with
      | Ok _ -> ()
      | Error es -> Alcotest.failf "%s:\n%s" path (errors_text es))
    files

(* Conservative: what would not be an error if it ran is not reported. *)
let test_no_false_positives () =
  List.iter
    (fun text ->
      Alcotest.(check (list string))
        text []
        (List.map Error.to_string (static_errors text)))
    [
      "fn m(r, c) { sphere { center: c, radius: r } }";
      "let r = 1\nfn m(r) { sphere { center: r, radius: 1 } }";
      "fn f(x) = x\nif false { sphere { center: f(1), radius: f((1, 1, 1)) } }";
      "if false { sphere { center: (0, 0, 0), radius: 1, scale: 2 } sphere { center: (0, \
       0, 0), radius: 1, scale: (1, 2, 1), scale: 2, translate: (1, 0, 0), translate: \
       (0, 1, 0) } }";
      "if false { settings { gamma: 2.2, background: gradient((1, 1, 1), (0, 0, 1)), \
       fog: fog((1, 1, 1), 3) } }";
      "if false { let m = material { texture: (1, 0, 0), bump: noise(1, 0.2) } box { \
       min: (0, 0, 0), max: (1, 1, 1), material: m } }";
      "if false { camera { kind: \"orthographic\", width: 3 } }";
      "if false { let v = mix((0, 0, 0), (1, 1, 1), 0.5) sphere { center: v, radius: \
       mix(1, 2, 0.5) } }";
      "fn m(i) { for j in 0 to i { sphere { center: (j, 0, 0) * 2 - (0, i, 0), radius: j \
       / 2 + 1 } } }";
      "fn c(k) { camera { kind: k, width: 2, fov: 300 } }";
      "if false { camera { kind: \"fishey\", width: 2 } }";
      "if false { camera { kind: \"fisheye\", fov: 300 } animation { frames: 3 } light { \
       position: (0, 1, 0), point_at: (0, 0, 0), inner: 5 } camera { kind: \
       \"orthographic\", width: 3 } }";
      "let k = 1\n\
       if false { let k = (1, 1, 1) sphere { center: k, radius: 1 } }\n\
       sphere { center: (0, 0, 0), radius: k }";
      (* a built-in under another name has the type of the built-in it holds *)
      "let dot = cross\nsphere { center: dot((1, 0, 0), (0, 1, 0)), radius: 1 }";
      "let min = mix\nsphere { center: min((0, 0, 0), (1, 1, 1), 0.5), radius: 1 }";
    ]

(* Random programs of blocks whose code all runs (no condition, no macro): whatever
   the static check reports there, the evaluator reports too, with the same text at the
   same place. *)
module Schema = Lancer_dsl.Schema

let values =
  [
    "1";
    "0";
    "-1";
    "0.5";
    "2 * 3";
    "1e300";
    "(1, 2, 3)";
    "(0, 1, 0)";
    "-(1, 0, 0)";
    "(1, 2, 3) * 2";
    "\"srgb\"";
    "\"perspective\"";
    "\"orthographic\"";
    "\"fisheye\"";
    "\"exact\"";
    "\"x.obj\"";
    "true";
    "false";
    "1 < 2";
    "not true";
    "material { }";
    "material { color: (1, 0, 0) }";
    "material { colr: 1 }";
    "material { base: 1 }";
    "checker((1, 1, 1), (0, 0, 0), 1)";
    "noise(1, 0.1)";
    "fog((1, 1, 1), 2)";
    "gradient((1, 1, 1), (0, 0, 1))";
    "color_map((0, (1, 0, 0)))";
    "(0.5, (1, 0, 0))";
    "rgb(1, 0, 0)";
    "sin(1)";
    "if true then 1 else 2";
    "if true then 1 else (1, 1, 1)";
    "v";
    "n";
    "s";
    "m";
    "f";
    "undefined";
    "1 / 0";
    "(1, 2, 3) + 4";
    "sqrt(-1)";
    "mix(1, 2, 0.5)";
    "mix((0, 0, 0), (1, 1, 1), 0.5)";
    "(1, 2, 3).x";
    "pi";
    "f(2)";
  ]

let prelude =
  "let v = (1, 2, 3)\nlet n = 2\nlet s = \"srgb\"\nlet m = material { }\nfn f(x) = x\n"

let random_program =
  let open QCheck.Gen in
  let blocks = Array.of_list Schema.blocks in
  let counter = ref 0 in
  let rec block depth =
    let* b = oneofa blocks in
    let names = Schema.names_of b in
    let* fields =
      list_size (int_range 0 4)
        (pair
           (oneof
              [
                oneofl names;
                oneofl names;
                oneofl [ "bogus"; "colour"; "radiu" ];
                map (fun n -> n ^ "x") (oneofl names);
              ])
           (oneofl values))
    in
    let* inner =
      if b.holds_objects && depth < 2 then list_size (int_range 0 2) (block (depth + 1))
      else return []
    in
    let* chooser = bool in
    let fields =
      (match b.chosen_by with
      | Some c when chooser -> [ Printf.sprintf "%s: (0, 5, 0)" c ]
      | _ -> [])
      @ List.map (fun (n, v) -> Printf.sprintf "%s: %s" n v) fields
    in
    let body = String.concat ", " fields ^ " " ^ String.concat "\n" inner in
    incr counter;
    return
      (match b.keyword with
      | "material" -> Printf.sprintf "let mm = material { %s }" body
      | "body" ->
          Printf.sprintf "body b%d { sphere { center: (0, 1, 0), radius: 1 } %s }"
            !counter body
      | k -> Printf.sprintf "%s { %s }" k body)
  in
  QCheck.make
    ~print:(fun s -> s)
    (map
       (fun bs -> prelude ^ String.concat "\n" bs)
       (list_size (int_range 1 4) (block 0)))

(* How often [sub] occurs in [s]. *)
let occurrences s sub =
  let n = String.length sub in
  let rec go i acc =
    if i + n > String.length s then acc
    else go (i + 1) (if String.sub s i n = sub then acc + 1 else acc)
  in
  go 0 0

let static_subset_of_evaluation text =
  (* A second settings, camera, animation or physics block is refused as a whole: the
     evaluator does not look at its fields. *)
  QCheck.assume
    (List.for_all
       (fun k -> occurrences text (k ^ " {") < 2)
       [ "settings"; "camera"; "animation"; "physics" ]);
  let key (e : Error.t) = Printf.sprintf "%d:%d: %s" e.line e.col e.message in
  let es = eval_errors text in
  let evaluated = List.map key es in
  (* A value that fails to evaluate (1 / 0) is reported as that; the static check may
     see its type is wrong as well. *)
  let inside (e : Error.t) =
    List.exists
      (fun (x : Error.t) ->
        x.line = e.line && x.col >= e.col && x.col < e.end_col && x.message <> e.message)
      es
  in
  List.iter
    (fun e ->
      if not (List.mem (key e) evaluated || inside e) then
        QCheck.Test.fail_reportf "the static check says %s; the evaluator:\n%s" (key e)
          (String.concat "\n" evaluated))
    (static_errors text);
  true

let props =
  let rand = Random.State.make [| 2026 |] in
  List.map
    (QCheck_alcotest.to_alcotest ~rand)
    [
      QCheck.Test.make
        ~name:"in code that runs, the static check reports only what the evaluator does"
        ~count:3000 random_program static_subset_of_evaluation;
    ]

let () =
  Alcotest.run "static check"
    [
      ( "code that does not run",
        [
          Alcotest.test_case "a branch not taken" `Quick test_branch_not_taken;
          Alcotest.test_case "a macro never called" `Quick test_macro_never_called;
          Alcotest.test_case "functions" `Quick test_functions;
          Alcotest.test_case "loops" `Quick test_loops;
          Alcotest.test_case "groups and CSG" `Quick test_groups_and_csg;
          Alcotest.test_case "includes" `Quick test_includes;
        ] );
      ( "with the evaluator",
        [
          Alcotest.test_case "a mistake is reported once" `Quick test_reported_once;
          Alcotest.test_case "the static check says what the evaluator says" `Quick
            test_same_as_evaluator;
          Alcotest.test_case "no false positives" `Quick test_no_false_positives;
          Alcotest.test_case "every scene in scenes/ passes" `Quick test_scenes_pass;
        ]
        @ props );
    ]
