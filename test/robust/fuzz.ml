(* `make fuzz`: feeds random and mutated input to the scene language (parser and
   evaluator), the OBJ loader and the image decoder for a fixed time, and reports the cases
   tried and the failures (an exception, or an error that breaks the loader's contract).

   FUZZ_SECONDS  total time budget (default 60), shared by the three targets
   FUZZ_SEED     seed of the first case (default 1); each case has its own seed, printed
                 with every failure so that it can be replayed
   FUZZ_ROOT     project root, where scenes/ is found (default .)
   FUZZ_TARGETS  comma-separated subset of scene,obj,ply,image (default all)

   The first failing inputs of each target are written to fuzz-failures/ in the current
   directory. Exit status 1 when anything failed. *)
module G = Fuzz_gen

let env name default =
  match Sys.getenv_opt name with Some s when String.trim s <> "" -> s | _ -> default

let env_float name default =
  match float_of_string_opt (env name (string_of_float default)) with
  | Some f when Float.is_finite f && f >= 0. -> f
  | _ ->
      Printf.eprintf "fuzz: %s must be a number of seconds >= 0\n" name;
      exit 2

type target = {
  name : string;
  share : float;
  case : Random.State.t -> string * string;
  check : string * string -> (unit, string) result;
  mutable tried : int;
  mutable failed : int;
}

let failure_dir = "fuzz-failures"

(* Failures printed and kept per target; the rest are only counted. *)
let max_reported = 20

let save_failure t seed (ext, input) message =
  (try Unix.mkdir failure_dir 0o755 with Unix.Unix_error (Unix.EEXIST, _, _) -> ());
  let base = Filename.concat failure_dir (Printf.sprintf "%s-%d" t.name seed) in
  let ext = if t.name = "scene" then ".rts" else ext in
  Out_channel.with_open_bin (base ^ ext) (fun oc -> output_string oc input);
  Out_channel.with_open_bin (base ^ ".txt") (fun oc -> output_string oc (message ^ "\n"));
  base ^ ext

let () =
  let seconds = env_float "FUZZ_SECONDS" 60. in
  let seed0 =
    match int_of_string_opt (env "FUZZ_SEED" "1") with Some s -> s | None -> 1
  in
  let root = env "FUZZ_ROOT" "." in
  let wanted =
    String.split_on_char ',' (env "FUZZ_TARGETS" "scene,obj,ply,image")
    |> List.map String.trim
  in
  let seeds = G.scene_seeds root in
  let targets =
    [
      {
        name = "scene";
        share = 0.5;
        case = G.scene_case seeds;
        check = (fun (file, text) -> G.check_scene (file, text));
        tried = 0;
        failed = 0;
      };
      {
        name = "obj";
        share = 0.3;
        case =
          (fun st ->
            (".obj", if Random.State.bool st then G.random_obj st else G.mutated_obj st));
        check =
          (fun (_, text) ->
            Result.bind (G.check_obj text) (fun () -> G.check_obj_lines text));
        tried = 0;
        failed = 0;
      };
      {
        name = "ply";
        share = 0.1;
        case =
          (fun st ->
            ( ".ply",
              if Random.State.bool st then
                G.ply_text
                  (List.nth
                     [ "ascii"; "binary_little_endian"; "binary_big_endian" ]
                     (Random.State.int st 3))
                  (G.random_ply st)
              else G.mutated_ply st ));
        check = (fun (_, text) -> G.check_ply text);
        tried = 0;
        failed = 0;
      };
      {
        name = "image";
        share = 0.2;
        case = G.image_case;
        check = G.check_image;
        tried = 0;
        failed = 0;
      };
    ]
    |> List.filter (fun t -> List.mem t.name wanted)
  in
  if targets = [] then (
    prerr_endline "fuzz: FUZZ_TARGETS names none of scene, obj, ply, image";
    exit 2);
  let total_share = List.fold_left (fun a t -> a +. t.share) 0. targets in
  Printf.printf "fuzzing %s for %g s from seed %d (%d seed scenes)\n%!"
    (String.concat ", " (List.map (fun t -> t.name) targets))
    seconds seed0 (Array.length seeds);
  let seed = ref seed0 in
  let start = Unix.gettimeofday () in
  (* Round-robin slices, each target getting its share of every round; at least one case
     each, so that FUZZ_SECONDS=0 replays the case FUZZ_SEED. *)
  let slice = 0.05 and first = ref true in
  while !first || Unix.gettimeofday () -. start < seconds do
    first := false;
    List.iter
      (fun t ->
        let until =
          Float.min (start +. seconds)
            (Unix.gettimeofday () +. (slice *. t.share /. total_share *. 3.))
        in
        let continue = ref true in
        while !continue do
          let s = !seed in
          incr seed;
          let st = Random.State.make [| s |] in
          let input = t.case st in
          t.tried <- t.tried + 1;
          (match t.check input with
          | Ok () -> ()
          | Error m ->
              t.failed <- t.failed + 1;
              if t.failed <= max_reported then
                let file = save_failure t s input m in
                Printf.printf "FAIL %s case %d: %s (input in %s)\n%!" t.name s m file);
          continue := Unix.gettimeofday () < until
        done)
      targets
  done;
  let elapsed = Unix.gettimeofday () -. start in
  List.iter
    (fun t -> Printf.printf "%-6s %8d cases, %d failures\n" t.name t.tried t.failed)
    targets;
  let failed = List.fold_left (fun a t -> a + t.failed) 0 targets in
  Printf.printf "%.1f s, %d cases, %d failures%s\n" elapsed
    (List.fold_left (fun a t -> a + t.tried) 0 targets)
    failed
    (if failed > 0 then
       Printf.sprintf " (inputs in %s/; replay with FUZZ_SEED=<case> FUZZ_SECONDS=0)"
         failure_dir
     else "");
  exit (if failed > 0 then 1 else 0)
