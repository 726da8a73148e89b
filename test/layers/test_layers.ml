(* Reads the dune files of lancer's libraries and commands and checks that every
   dependency on a lancer library points down the layers (doc/explanation/design.md draws
   them). dune itself refuses a cycle; this catches a new arrow that would make no cycle
   but break the layering: the language using the renderer, the job layer using the
   language or physics, a library of lib/ using a command's. *)

let root = "../.."

let read path =
  let ic = open_in_bin path in
  Fun.protect
    ~finally:(fun () -> close_in ic)
    (fun () -> really_input_string ic (in_channel_length ic))

(* The names in the (libraries …) field of every stanza of a dune file: a dune file is
   s-expressions, and the field's words run to the first unbalanced ')'. *)
let libraries text =
  let re = Str.regexp "(libraries" in
  let rec from pos acc =
    match Str.search_forward re text pos with
    | exception Not_found -> List.rev acc
    | i ->
        let j = ref (i + String.length "(libraries") and depth = ref 0 in
        let b = Buffer.create 64 in
        while !depth >= 0 && !j < String.length text do
          (match text.[!j] with
          | '(' -> incr depth
          | ')' -> decr depth
          | c -> if !depth = 0 then Buffer.add_char b c);
          incr j
        done;
        let words =
          String.split_on_char ' '
            (String.map (function '\n' | '\t' -> ' ' | c -> c) (Buffer.contents b))
          |> List.filter (( <> ) "")
        in
        from !j (List.rev_append words acc)
  in
  from 0 []

(* The layers, bottom first, each with the folder of its dune file. Libraries of one
   rank do not use each other: physics and the language (both over the description). *)
let layers =
  [
    ("lancer_math", "lib/math", 0);
    ("lancer_diag", "lib/diag", 1);
    ("lancer_exr", "lib/exr", 1);
    ("lancer_exr_openexr", "lib/exr/openexr", 1);
    ("lancer_exr_absent", "lib/exr/absent", 1);
    ("lancer_image", "lib/image", 2);
    ("lancer_description", "lib/description", 3);
    ("lancer_physics", "lib/physics", 4);
    ("lancer_dsl", "dsl", 4);
    ("lancer_render", "lib/render", 5);
    ("lancer_job", "lib/job", 6);
    ("lancer_program", "lib/program", 7);
    ("lancer_mpi", "lib/mpi", 7);
    ("lancer_run", "lib/run", 8);
    ("lancer", "lib/lancer", 9);
    ("lancer_preview", "lib/preview", 10);
    ("lancer_measure", "lib/measure", 10);
    ("lancer_cli", "bin/common", 11);
    ("commands", "bin", 12);
    ("lancer-mpi", "bin/mpi", 12);
    ("lancer_benchmarks", "bench", 12);
  ]

(* What a layer may not use although it lies below: the job layer asks for scenes
   through Scenes.t and knows neither the language nor physics; the language knows
   nothing of images. *)
let forbidden =
  [
    ("lancer_job", [ "lancer_dsl"; "lancer_physics" ]); ("lancer_dsl", [ "lancer_image" ]);
  ]

(* A public name (lancer.job) is its library (lancer_job). *)
let canonical lib =
  match String.split_on_char '.' lib with
  | [ "lancer"; sub ] -> "lancer_" ^ sub
  | [ "lancer"; sub; impl ] -> "lancer_" ^ sub ^ "_" ^ impl
  | _ -> lib

let rank lib =
  List.find_map (fun (name, _, r) -> if name = canonical lib then Some r else None) layers

let test_layer (name, dir, r) () =
  let deps =
    List.map canonical (libraries (read (Filename.concat root (dir ^ "/dune"))))
  in
  List.iter
    (fun d ->
      match rank d with
      | Some rd when rd >= r && d <> name ->
          Alcotest.failf
            "%s (layer %d, %s) uses %s (layer %d): an arrow that does not point down" name
            r dir d rd
      | _ -> ())
    deps;
  List.iter
    (fun bad ->
      if List.mem bad deps then
        Alcotest.failf "%s (%s) uses %s, which it must not know" name dir bad)
    (Option.value (List.assoc_opt name forbidden) ~default:[])

let test_parser () =
  Alcotest.(check (list string))
    "a field over several lines, comments and nested forms" [ "a"; "b"; "c" ]
    (libraries "(library\n (name x)\n (libraries a\n  b (select y from (z -> y.ml)) c))")

let () =
  Alcotest.run "layers"
    [
      ( "layers",
        List.map
          (fun ((n, dir, _) as l) ->
            Alcotest.test_case
              (Printf.sprintf "%s (%s) uses only the layers under it" n dir)
              `Quick (test_layer l))
          layers );
      ("reader", [ Alcotest.test_case "reads a libraries field" `Quick test_parser ]);
    ]
