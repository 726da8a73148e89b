(* The scene language's evaluator, beside CPython on the same loop. *)

open Lancer
module Timing = Lancer_measure.Timing

let language_loop = "for i in 0 to 3000000 { let x = sin(i) * cos(i) }\n"

let language_python =
  "import math\nfor i in range(3000001):\n    x = math.sin(i) * math.cos(i)\n"

(* The camera, light and size the grids below share, for n×n objects. *)
let grid_header n =
  Printf.sprintf
    "let n = %d\n\
     settings { width: 64, height: 48 }\n\
     camera { position: (0, 0.6 * n, -0.9 * n), look_at: (0, 0, 0), fov: 50 }\n\
     light { position: (-0.4 * n, 0.8 * n, -0.6 * n) }\n"
    n

let language_grid n =
  grid_header n
  ^ "for i in 0 to n - 1 { for j in 0 to n - 1 { sphere { center: (i - n / 2, 0.4, j - n \
     / 2), radius: 0.4 } } }\n"

(* The same grid, each sphere with its own material expression (the field of
   scenes/bench/field_100000.rts), and one of transformed boxes in groups. *)
let language_field n =
  grid_header n
  ^ "for i in 0 to n - 1 { for j in 0 to n - 1 { sphere { center: (i - n / 2, 0.4, j - n \
     / 2), radius: 0.4, material: material { color: (0.5 + 0.5 * sin(i), 0.5 + 0.5 * \
     cos(j), 0.6) } } } }\n"

let language_transformed n =
  grid_header n
  ^ "for i in 0 to n - 1 { group { translate: (i - n / 2, 0, 0), for j in 0 to n - 1 { \
     box { min: (-0.4, 0, -0.4), max: (0.4, 0.8, 0.4), rotate: (0, 3 * j, 0), translate: \
     (0, 0, j - n / 2), material: material { color: (0.9, 0.5, 0.2), specular: 0.5 } } } \
     } }\n"

(* One whole check of a program in this process (parse, static check, evaluation): its
   wall time, the words it allocated and the words its result holds. *)
let language_eval text =
  Gc.full_major ();
  let live0 = (Gc.stat ()).live_words in
  let w0 = Gc.minor_words () in
  let t0 = Unix.gettimeofday () in
  match Lancer_dsl.Dsl.load_string ~filename:"bench.rts" text with
  | Ok p ->
      let t = Unix.gettimeofday () -. t0 in
      let words = Gc.minor_words () -. w0 in
      Gc.full_major ();
      let live = (Gc.stat ()).live_words - live0 in
      ignore (Sys.opaque_identity p);
      (t, words, live)
  | Error es ->
      raise
        (Job_error.User
           ("the benchmark's program failed: "
           ^ String.concat "" (List.map Lancer_dsl.Error.to_string es)))

let on_path exe =
  let path = Option.value (Sys.getenv_opt "PATH") ~default:"" in
  List.find_map
    (fun d ->
      let f = Filename.concat (if d = "" then "." else d) exe in
      if Sys.file_exists f && not (Sys.is_directory f) then Some f else None)
    (String.split_on_char ':' path)

(* The wall time of a whole python3 process running [code]. *)
let python_time python code =
  let t0 = Unix.gettimeofday () in
  let pid =
    Unix.create_process python [| python; "-c"; code |] Unix.stdin Unix.stdout Unix.stderr
  in
  match snd (Unix.waitpid [] pid) with
  | Unix.WEXITED 0 -> Some (Unix.gettimeofday () -. t0)
  | _ -> None

let run ~repeat ~grid ~json =
  if repeat < 1 then raise (Job_error.User "--repeat must be at least 1");
  if grid < 1 then raise (Job_error.User "--grid must be at least 1");
  let python = on_path "python3" in
  let runs f = List.init repeat (fun _ -> f ()) in
  (* Alternated, so that a change in the machine's load falls on both. *)
  let loop, py =
    List.split
      (runs (fun () ->
           let t, _, _ = language_eval language_loop in
           (t, Option.bind python (fun p -> python_time p language_python))))
  in
  let loop_t = Timing.median loop in
  let py_t =
    match List.filter_map Fun.id py with [] -> None | ts -> Some (Timing.median ts)
  in
  let grid_runs = runs (fun () -> language_eval (language_grid grid)) in
  let grid_t = Timing.median (List.map (fun (t, _, _) -> t) grid_runs) in
  let objects = grid * grid in
  let per (_, words, live) =
    (words /. Float.of_int objects, Float.of_int live /. Float.of_int objects)
  in
  let words, live = per (List.hd grid_runs) in
  let other prog =
    let rs = runs (fun () -> language_eval (prog grid)) in
    let w, l = per (List.hd rs) in
    (Timing.median (List.map (fun (t, _, _) -> t) rs), w, l)
  in
  let field_t, field_words, field_live = other language_field in
  let tr_t, tr_words, tr_live = other language_transformed in
  if json then
    print_endline
      (Yojson.Safe.pretty_to_string
         (`Assoc
            [
              ("repeat", `Int repeat);
              ("loop_iterations", `Int 3_000_001);
              ("loop_seconds", `Float loop_t);
              ( "python3_loop_seconds",
                match py_t with Some t -> `Float t | None -> `Null );
              ( "ratio_to_python3",
                match py_t with Some t -> `Float (loop_t /. t) | None -> `Null );
              ("objects", `Int objects);
              ("objects_seconds", `Float grid_t);
              ("minor_words_per_object", `Float words);
              ("live_words_per_object", `Float live);
              ("material_objects_seconds", `Float field_t);
              ("material_minor_words_per_object", `Float field_words);
              ("material_live_words_per_object", `Float field_live);
              ("transformed_objects_seconds", `Float tr_t);
              ("transformed_minor_words_per_object", `Float tr_words);
              ("transformed_live_words_per_object", `Float tr_live);
            ]))
  else (
    Printf.printf
      "The scene language, a whole check in this process (parse, static check, \
       evaluation), median of %d run%s\n\n"
      repeat
      (if repeat = 1 then "" else "s");
    print_endline "| program | lancer (s) | python3 (s) | lancer / python3 |";
    print_endline "|---|---:|---:|---:|";
    (match py_t with
    | Some p ->
        Printf.printf
          "| `for i in 0 to 3000000 { let x = sin(i) * cos(i) }` | %.3f | %.3f | %.2f |\n"
          loop_t p (loop_t /. p)
    | None ->
        Printf.printf
          "| `for i in 0 to 3000000 { let x = sin(i) * cos(i) }` | %.3f | — | — |\n"
          loop_t);
    Printf.printf "| %s sphere blocks from two loops (%d × %d) | %.3f | — | — |\n"
      (if objects >= 1_000_000 && objects mod 1_000_000 = 0 then
         Printf.sprintf "%d million" (objects / 1_000_000)
       else string_of_int objects)
      grid grid grid_t;
    Printf.printf
      "| the same spheres, each with a material { color: … } of its own | %.3f | — | — |\n"
      field_t;
    Printf.printf
      "| as many rotated boxes with a material, in translated groups | %.3f | — | — |\n"
      tr_t;
    Printf.printf
      "\n\
       Per object, words allocated and words held by the description: %.0f and %.0f \
       (spheres), %.0f and %.0f (spheres with a material each), %.0f and %.0f (boxes in \
       groups).\n"
      words live field_words field_live tr_words tr_live;
    if python = None then
      print_endline
        "python3 is not on the PATH: the CPython row (the same loop with math.sin and \
         math.cos) was skipped."
    else if py_t = None then print_endline "python3 failed: the CPython row was skipped.")
