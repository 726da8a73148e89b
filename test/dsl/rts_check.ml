(* Loads each scene given on the command line and prints its errors with Error.pp, or
   "ok" and the summary; used by the golden tests of scenes/bad. Exit status 0 always, so
   that the expected output alone decides. *)

let () =
  for i = 1 to Array.length Sys.argv - 1 do
    let path = Sys.argv.(i) in
    match Lancer.Program.load_file path with
    | Error errs -> List.iter (Format.printf "%a" Lancer_dsl.Error.pp) errs
    | Ok p -> (
        match Lancer.Program.scene_at p ~time:0. ~frame:0 with
        | Ok sc -> print_string (Lancer.Program.summary p sc)
        | Error errs -> List.iter (Format.printf "%a" Lancer_dsl.Error.pp) errs)
  done
