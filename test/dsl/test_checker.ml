(* The type checker on whole programs: mistakes in code that does not run (a branch not
   taken, a macro or function never called, a loop that runs zero times, an included
   file) are reported with the evaluation's message and location; a mistake is reported
   once, by the checker or by the evaluation, at the place the evaluation would report
   it; what the checker cannot know (a parameter, what a function returns, what
   operators make of those) it leaves to the evaluation; and no scene of scenes/ is
   refused. *)

open Lancer_dsl

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

let test_lists_and_strings () =
  check_errors "an index that is not a number, len of a number, a string plus a number"
    "let a = [1, 2][\"a\"]\nlet b = len(3)\nlet c = \"a\" + 1\n"
    [
      "test.rts:1:16: a list index must be a number, got a string";
      "test.rts:2:13: argument 1 of `len` must be a list, got a number";
      "test.rts:3:9: `+` cannot combine a string and a number";
    ];
  check_errors "in code that does not run: elements of two types, indexing a number"
    "if false { let d = [1, (1, 2, 3)]\nlet e = d[0]\nlet k = (1, 2, 3)[0] }\n"
    [
      "test.rts:1:24: the elements of a list must be of one type: element 2 is a vector, \
       the first a number";
      "test.rts:3:9: `[…]` takes an element of a list, got a vector";
    ];
  check_errors "a loop over a number; a list's element has its type"
    "for p in 3 { }\nfor q in [1, 2] { sphere { center: q, radius: 1 } }\n"
    [
      "test.rts:1:10: `for NAME in` goes over a list (`for p in [a, b] { … }`) or a \
       range (`for i in A to B { … }`), got a number";
      "test.rts:2:36: `center` must be a vector (x, y, z), got a number";
    ];
  check_errors "an element of unknown type is the evaluation's to check"
    "fn f(x) = [x, 2][0]\nlet y = f(\"s\")\n"
    [
      "test.rts:1:15: the elements of a list must be of one type: element 2 is a number, \
       the first a string";
    ]

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
    [ "test.rts:1:20: unknown field `colr` in material; did you mean `color`?" ];
  check_errors "a value of the wrong type is not evaluated: its type is its mistake"
    "sphere { center: sqrt(-1), radius: 1 }\n"
    [ "test.rts:1:18: `center` must be a vector (x, y, z), got a number" ]

(* An operand whose type only a run knows is not guessed: what the operator makes of it is
   not known either, and the run says what is wrong, once, where it is wrong. *)
let test_unknown_operands () =
  check_errors "a parameter plus a number, given a vector"
    "fn m(c) { sphere { center: c + 1, radius: 1 } }\nm((1, 2, 3))\n"
    [ "test.rts:1:28: `+` cannot combine a vector and a number" ];
  check_errors "... given a number: the field says it"
    "fn m(c) { sphere { center: c + 1, radius: 1 } }\nm(1)\n"
    [ "test.rts:1:28: `center` must be a vector (x, y, z), got a number" ];
  check_errors "... never called: nothing is known to be wrong"
    "fn m(c) { sphere { center: c + 1, radius: 1 } }\n" [];
  check_errors "a built-in of an unknown argument"
    "fn m(c) { sphere { center: sin(c), radius: 1 } }\nm((1, 2, 3))\nm(2)\n"
    [
      "test.rts:1:28: `center` must be a vector (x, y, z), got a number";
      "test.rts:1:32: argument 1 of `sin` must be a number, got a vector";
    ];
  check_errors "what a function returns"
    "fn f(x) = x * 2\nsphere { center: f(1), radius: f((1, 1, 1)) }\n"
    [
      "test.rts:2:18: `center` must be a vector (x, y, z), got a number";
      "test.rts:2:32: `radius` must be a number, got a vector";
    ];
  check_errors "a closure's captured value, called in a loop"
    "for i in 0 to 1 {\n\
     fn c(x) = x + i\n\
     sphere { center: c((0, 0, 1)), radius: c(1) }\n\
     }\n"
    [ "test.rts:2:11: `+` cannot combine a vector and a number" ];
  check_errors "a known mistake beside an unknown operand is the checker's"
    "fn m(c) { sphere { center: (c, 0, 0), radius: c + \"r\" * 2 } }\n"
    [ "test.rts:1:51: `*` cannot combine a string and a number" ]

(* The checker's and the evaluation's mistakes, apart. *)
let static_errors text = snd (Pipeline.checked text)
let key (e : Error.t) = Printf.sprintf "%d:%d: %s" e.line e.col e.message

(* Mistakes in code that runs: each one the checker reports, an evaluation that checks
   every type as it runs reports too, with the same text at the same place. *)
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
    "let a = (1, 2, 3) + 1\nlet b = sin(\"x\")\nlet c = if 1 then 2 else 3";
    "let d = (1, 2, 3).w\n\
     let e = (3).x\n\
     let f = not 1\n\
     let g = -\"x\"\n\
     let h = (1, true, 2)";
    "fn f(x) = x\nlet i = f(1, 2)\nlet j = pi(1)\nf(1)\nsin(2)\nlet q = 2\nq(1)";
    "fn m(a) { sphere { center: a, radius: 1 } }\nlet k = m(1)\nm(1, 2)";
    "for i in (1, 2, 3) to 2 { }\nif 2 { }\nlet l = 1 and true";
    "let cm = color_map((0, (1, 0, 0)), 3, (\"a\", 1))\nlet gr = gradient(1, 2)";
    "let a = [1, 2][\"a\"]\n\
     let b = len(3)\n\
     let c = \"a\" + 1\n\
     let d = [1, \"a\", (1, 2, 3)]";
    "let e = 3[0]\nfor p in 3 { }\nlet f = [[1], [\"a\"]]\nlet g = [1][true]";
  ]

let test_same_as_evaluator () =
  List.iter
    (fun text ->
      let static = List.map key (static_errors text) in
      let evaluated = List.map key (Pipeline.errors ~types:false text) in
      if static = [] then Alcotest.failf "the checker found nothing in:\n%s" text;
      List.iter
        (fun s ->
          if not (List.mem s evaluated) then
            Alcotest.failf "%s\nthe checker: %s\nthe evaluation:\n%s" text s
              (String.concat "\n" evaluated))
        static)
    same_as_evaluator

(* No scene that the evaluation accepts is refused: every scene of scenes/ (gallery,
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
      (* an operand of unknown type, whatever the other *)
      "fn m(c) { sphere { center: c + 1, radius: c * (1, 1, 1) } }";
      "fn m(c) { sphere { center: sin(c), radius: mix(c, c, 0.5) } }";
      "fn m(c, d) { sphere { center: if c then d else 1, radius: -c } }";
      "fn f(x) = x\nfn m(c) { sphere { center: f(c) + 1, radius: f(c).x } }";
      "fn m(a) { let b = a + 1\nsphere { center: b * 2, radius: b } }";
    ]

(* ------------------------------------------------------------------------------------ *)
(* The checker and the evaluation agree, on random programs *)

(* Programs whose code all runs: every function and macro is called (a macro twice, with
   arguments of different types), loops run, no branch is left out. Their values fail
   only for their types (or a number out of a field's range), never for a value (no
   division, no square root …): each expression has at most one place where a run can
   stop. Names of every type; parameters of unknown type in arithmetic, in built-in
   calls, in conditions and given to fields; functions whose results are unknown;
   closures over a loop's variable; macros building every block kind. *)
module Gen = struct
  open QCheck.Gen

  let literals =
    [|
      "1";
      "0.5";
      "2";
      "-1";
      "(1, 2, 3)";
      "(0, 1, 0)";
      "\"srgb\"";
      "\"fisheye\"";
      "true";
      "false";
      "material { }";
      "checker((1, 1, 1), (0, 0, 0), 1)";
      "noise(1, 0.1)";
      "fog((1, 1, 1), 2)";
      "gradient((1, 1, 1), (0, 0, 1))";
      "color_map((0, (1, 0, 0)))";
      "(0.5, (1, 0, 0))";
      "pi";
    |]

  let names = [| "n"; "v"; "s"; "b"; "m"; "t"; "sin" |]

  (* A value that cannot fail: the arguments of calls, so that every body runs. *)
  let safe = oneof [ oneofa literals; oneofa names ]
  let ops = [| "+"; "-"; "*"; "<"; "=="; "and" |]
  let builtins = [| "sin"; "abs"; "floor"; "length"; "rgb"; "dot"; "mix"; "cross" |]

  (* An atom: it fails only where its type is wrong, or where it names nothing. [params]
     are in scope. *)
  let atom params =
    frequency
      ([ (4, oneofa literals); (3, oneofa names); (1, return "undefined") ]
      @ if params = [] then [] else [ (5, oneofl params) ])

  let arity = function "rgb" | "mix" -> 3 | "dot" | "cross" -> 2 | _ -> 1

  (* An expression: an operation on atoms, or a call of a function ([fns], of one
     parameter) as a whole, so that every call a program writes runs. *)
  let expr params fns =
    let a = atom params in
    frequency
      ((if fns = [] then []
        else
          [
            ( 2,
              let* f = oneofl fns and* x = safe in
              return (Printf.sprintf "%s(%s)" f x) );
          ])
      @ [
          (3, a);
          ( 4,
            let* x = a and* op = oneofa ops and* y = a in
            return (Printf.sprintf "%s %s %s" x op y) );
          ( 2,
            let* f = oneofa builtins in
            let* args = list_repeat (arity f) a in
            return (Printf.sprintf "%s(%s)" f (String.concat ", " args)) );
          ( 1,
            let* c = a and* x = a and* y = a in
            return (Printf.sprintf "if %s then %s else %s" c x y) );
          ( 1,
            let* x = a and* f = oneofl [ "x"; "y"; "position" ] in
            return (Printf.sprintf "(%s).%s" x f) );
          ( 1,
            let* x = a and* y = a and* z = a in
            return (Printf.sprintf "(%s, %s, %s)" x y z) );
        ])

  let shapes =
    [|
      ("sphere", [ "center"; "radius"; "material"; "translate"; "scale" ]);
      ("box", [ "min"; "max"; "rotate"; "material" ]);
      ("cylinder", [ "base"; "top"; "radius"; "caps" ]);
      ("light", [ "color"; "intensity"; "point_at"; "inner" ]);
      ("group", [ "material"; "translate"; "scale" ]);
    |]

  let once =
    [|
      ("camera", [ "kind"; "position"; "fov"; "width"; "aperture" ]);
      ("settings", [ "width"; "background"; "gamma"; "fog"; "jitter" ]);
    |]

  (* A block: each field once, of a random value; a field the block does not take, of a
     value that cannot fail (the value of a field not taken is not run). *)
  let block kinds params fns =
    let* kind, fields = oneofa kinds in
    let* chosen = shuffle_l fields in
    let* k = int_range 1 (List.length fields) in
    let chosen = List.filteri (fun i _ -> i < k) chosen in
    let* values = list_repeat k (expr params fns) in
    let* bogus = frequency [ (9, return []); (1, return [ "bogus: 1" ]) ] in
    let items = List.map2 (Printf.sprintf "%s: %s") chosen values @ bogus in
    let items = if kind = "light" then "position: (0, 5, 0)" :: items else items in
    let inner =
      if kind = "group" then " sphere { center: (0, 0, 0), radius: 1 }" else ""
    in
    return (Printf.sprintf "%s { %s%s }" kind (String.concat ", " items) inner)

  let program =
    let* nf = int_range 0 2 in
    let fns = List.init nf (Printf.sprintf "f%d") in
    let* fdefs =
      flatten_l
        (List.map
           (fun f ->
             let* body = expr [ "p" ] [] in
             return (Printf.sprintf "fn %s(p) = %s" f body))
           fns)
    in
    let* nm = int_range 0 2 in
    let* macros =
      flatten_l
        (List.init nm (fun k ->
             let* body = list_size (int_range 1 2) (block shapes [ "p"; "q" ] fns) in
             let* calls =
               list_repeat 2
                 (let* x = safe and* y = safe in
                  return (Printf.sprintf "mk%d(%s, %s)" k x y))
             in
             return
               (Printf.sprintf "fn mk%d(p, q) { %s }\n%s" k (String.concat "\n" body)
                  (String.concat "\n" calls))))
    in
    let* closure =
      let* body = expr [ "x"; "i" ] [] and* arg = safe in
      let* centre = bool in
      return
        (Printf.sprintf "for i in 0 to 1 {\nfn c(x) = %s\nsphere { %s }\n}" body
           (if centre then Printf.sprintf "center: c(%s), radius: 1" arg
            else Printf.sprintf "center: (i, 0, 0), radius: c(%s)" arg))
    in
    let* top = list_size (int_range 1 3) (block shapes [] fns) in
    let* settings = list_size (int_range 0 1) (block once [] fns) in
    let* calls =
      flatten_l
        (List.map
           (fun f ->
             let* a = safe in
             return (Printf.sprintf "let u = %s(%s)" f a))
           fns)
    in
    let* lets =
      list_size (int_range 0 2)
        (let* e = expr [] fns in
         return ("let w = " ^ e))
    in
    return
      (String.concat "\n"
         ([
            "let n = 2";
            "let v = (1, 2, 3)";
            "let s = \"srgb\"";
            "let b = true";
            "let m = material { color: (1, 0, 0) }";
            "let t = checker((1, 1, 1), (0, 0, 0), 1)";
          ]
         @ fdefs @ calls @ lets @ macros @ [ closure ] @ top @ settings)
      ^ "\n")
end

let random_program = QCheck.make ~print:(fun s -> s) Gen.program

(* The expressions a program's statements and fields hold, each as a span (a run of one
   stops at its first failure); and the spans of their parts that a run may leave out (a
   branch of `if … then … else`, the right operand of `and` and `or`). *)
let roots text =
  let acc = ref [] and maybe = ref [] in
  let rec expr (e : Ast.expr) =
    match e.e with
    | Num _ | Str _ | Bool _ | Var _ -> ()
    | Binop ((And | Or), a, b) ->
        expr a;
        maybe := b.loc :: !maybe
    | If (c, a, b) ->
        expr c;
        maybe := a.loc :: b.loc :: !maybe
    | Vec (a, b, c) -> List.iter expr [ a; b; c ]
    | Pair (a, b) | Binop (_, a, b) | Index (a, b) -> List.iter expr [ a; b ]
    | Unop (_, a) | Dot (a, _) -> expr a
    | Call (_, args) | List args -> List.iter expr args
    | Material items ->
        List.iter (function Ast.Field (_, e) -> expr e | Stmt _ -> ()) items
  in
  let root (e : Ast.expr) =
    acc := e.loc :: !acc;
    expr e
  in
  let rec stmt (s : Ast.stmt) =
    match s.s with
    | Let (_, e) | Fn (_, _, e) -> root e
    | Macro (_, _, b) | Included (_, b) -> List.iter stmt b
    | For (_, a, b, st, body) ->
        List.iter root (a :: b :: Option.to_list st);
        List.iter stmt body
    | For_each (_, l, body) ->
        root l;
        List.iter stmt body
    | If_stmt (c, t, e) ->
        root c;
        List.iter stmt t;
        List.iter stmt e
    | Block (_, its) | Body (_, its) ->
        List.iter (function Ast.Field (_, e) -> root e | Stmt s -> stmt s) its
    | Call_stmt (_, args) -> List.iter root args
    | Include _ -> ()
  in
  List.iter stmt (Pipeline.parse text);
  (!acc, !maybe)

let inside (l : Loc.t) (e : Error.t) =
  (e.line, e.col) >= (l.line, l.col) && (e.line, e.col) < (l.end_line, l.end_col)

(* Where the evaluation reports the checker's mistakes, and only there: with the checker's
   types, the evaluation reports none of its own at a place the checker reported one
   (each mistake once); without them (every type checked as the program runs), the same
   mistakes at the same places, and the same scene. A run of an expression stops at its
   first failure: where an expression holds a mistake of known types and one only a run
   finds (an unknown name, a value of the wrong type from a parameter), the checker
   reports the first and the run stops at the second, and either side reports its own.
   And a run leaves out the branch of a conditional not taken, where the checker reports
   what it knows to be wrong. *)
let agree text =
  let _, static = Pipeline.checked text in
  let run = Pipeline.run_errors text in
  let at (e : Error.t) = (e.line, e.col) in
  List.iter
    (fun (e : Error.t) ->
      if List.exists (fun s -> at s = at e) static then
        QCheck.Test.fail_reportf "reported twice at %d:%d:\nthe checker: %s\nthe run: %s"
          e.line e.col
          (String.concat "; " (List.map key (List.filter (fun s -> at s = at e) static)))
          e.message)
    run;
  let untyped = Pipeline.errors ~types:false text in
  let typed = static @ run in
  let missing es (e : Error.t) = not (List.exists (fun x -> key x = key e) es) in
  let only_typed = List.filter (missing untyped) typed in
  let only_untyped = List.filter (missing typed) untyped in
  let roots, maybe = roots text in
  (* A mistake one side alone reports is explained by another in the same expression
     where the other side stopped (the checker's mistakes are not run). *)
  let explained ~stops (e : Error.t) =
    List.exists
      (fun r -> inside r e && List.exists (fun x -> inside r x && x != e) stops)
      roots
  in
  let unexplained =
    List.filter
      (fun e ->
        not (explained ~stops:untyped e || List.exists (fun r -> inside r e) maybe))
      only_typed
  in
  let unexplained' =
    List.filter (fun e -> not (explained ~stops:static e)) only_untyped
  in
  if unexplained <> [] || unexplained' <> [] then
    QCheck.Test.fail_reportf "with types only:\n%s\nwithout types only:\n%s"
      (String.concat "\n" (List.map key unexplained))
      (String.concat "\n" (List.map key unexplained'));
  (match (Pipeline.run text, Pipeline.run ~types:false text) with
  | Ok a, Ok b when a <> b -> QCheck.Test.fail_report "the scenes differ"
  | Ok _, Error _ | Error _, Ok _ -> QCheck.Test.fail_report "one of the two fails"
  | _ -> ());
  true

let count =
  match Sys.getenv_opt "LANCER_FUZZ_COUNT" with Some n -> int_of_string n | None -> 3000

let props =
  let seed =
    match Sys.getenv_opt "LANCER_FUZZ_SEED" with
    | Some n -> int_of_string n
    | None -> 2026
  in
  let rand = Random.State.make [| seed |] in
  List.map
    (QCheck_alcotest.to_alcotest ~rand)
    [
      QCheck.Test.make
        ~name:
          "a mistake is reported once, where and as the evaluation reports it, operands \
           of unknown type included"
        ~count random_program agree;
    ]

(* ------------------------------------------------------------------------------------ *)
(* The tables the two phases share *)

(* The operators' types are what their values do: every pair of types an operator
   refuses is one its evaluation refuses with the same message, and it makes a value of
   the type the checker says. *)
let test_operators () =
  let values =
    Value.
      [
        VNum 2.;
        VBool true;
        VVec (Lancer_math.Vec3.v 1. 2. 3.);
        VStr "a";
        material Lancer_description.Description.default_material;
        VTex { tname = "checker"; targs = []; tloc = Lancer_diag.Loc.whole_file "t" };
        VPair (VNum 0.5, VVec (Lancer_math.Vec3.v 1. 0. 0.));
        VList [| VNum 1.; VNum 2. |];
        VList [||];
      ]
  in
  let loc = Lancer_diag.Loc.whole_file "t" in
  List.iter
    (fun op ->
      List.iter
        (fun a ->
          List.iter
            (fun b ->
              let name =
                Printf.sprintf "%s %s %s" (Value.type_name a) (Ast.binop_name op)
                  (Value.type_name b)
              in
              match
                (Ops.binop_type op (Value.ty a) (Value.ty b), Ops.binop loc op loc a b)
              with
              | Some t, v -> Alcotest.(check bool) name true (Ty.equal t (Value.ty v))
              | None, _ ->
                  Alcotest.failf "%s: the checker refuses it, the evaluation does not"
                    name
              | exception Value.Fail (_, m) -> (
                  match Ops.binop_type op (Value.ty a) (Value.ty b) with
                  | None ->
                      Alcotest.(check string)
                        name
                        (Msg.cannot_combine op (Value.ty a) (Value.ty b))
                        m
                  | Some _ -> Alcotest.failf "%s: the evaluation refuses it: %s" name m))
            values)
        values)
    Ast.[ Add; Sub; Mul; Div; Mod; Pow; Eq; Ne; Lt; Le; Gt; Ge ]

let () =
  Alcotest.run "checker"
    [
      ( "code that does not run",
        [
          Alcotest.test_case "a branch not taken" `Quick test_branch_not_taken;
          Alcotest.test_case "a macro never called" `Quick test_macro_never_called;
          Alcotest.test_case "functions" `Quick test_functions;
          Alcotest.test_case "loops" `Quick test_loops;
          Alcotest.test_case "groups and CSG" `Quick test_groups_and_csg;
          Alcotest.test_case "lists and strings" `Quick test_lists_and_strings;
          Alcotest.test_case "includes" `Quick test_includes;
        ] );
      ( "with the evaluation",
        [
          Alcotest.test_case "a mistake is reported once" `Quick test_reported_once;
          Alcotest.test_case "an operand of unknown type is the evaluation's to check"
            `Quick test_unknown_operands;
          Alcotest.test_case "the checker says what the evaluation says" `Quick
            test_same_as_evaluator;
          Alcotest.test_case "no false positives" `Quick test_no_false_positives;
          Alcotest.test_case "every scene in scenes/ passes" `Quick test_scenes_pass;
          Alcotest.test_case "the operators' types are what their values do" `Quick
            test_operators;
        ]
        @ props );
    ]
