(* lancer bench animation: a whole animation against one still of it, whole processes. *)

open Lancer

(* Wall time of lancer [exe] run with [args]. *)
let time exe what args =
  match Timing.child exe args with
  | Ok dt -> dt
  | Error c ->
      raise
        (Job_error.User
           (Printf.sprintf
              "bench animation: lancer %s failed (status %d): run it alone to see why"
              what c))

let rec remove_tree p =
  if Sys.file_exists p then
    if Sys.is_directory p then (
      Array.iter (fun f -> remove_tree (Filename.concat p f)) (Sys.readdir p);
      Sys.rmdir p)
    else Sys.remove p

let run ~exe ~scene ~repeat ~domains ~json =
  if repeat < 1 then raise (Job_error.User "bench animation: --repeat must be at least 1");
  if not (Sys.file_exists scene) then
    raise (Job_error.User (Printf.sprintf "bench animation: no scene %s" scene));
  let dir =
    Filename.concat
      (Filename.get_temp_dir_name ())
      (Printf.sprintf "lancer-bench-animation-%d" (Unix.getpid ()))
  in
  Fun.protect
    ~finally:(fun () -> try remove_tree dir with Sys_error _ -> ())
    (fun () ->
      Unix.mkdir dir 0o700;
      let common =
        [ "-q" ]
        @ match domains with Some d -> [ "--domains"; string_of_int d ] | None -> []
      in
      let frames_dir = Filename.concat dir "frames" in
      let still = Filename.concat dir "still.png" in
      (* Alternated, so that a change in the machine's load falls on both. *)
      let runs =
        List.init repeat (fun _ ->
            remove_tree frames_dir;
            let a =
              time exe "animate" ([ "animate"; scene; "-o"; frames_dir ] @ common)
            in
            let s = time exe "render" ([ "render"; scene; "-o"; still ] @ common) in
            (a, s))
      in
      let frames =
        List.length
          (List.filter
             (fun f -> Filename.check_suffix f ".png")
             (Array.to_list (Sys.readdir frames_dir)))
      in
      let a = Timing.median (List.map fst runs)
      and s = Timing.median (List.map snd runs) in
      if json then
        print_endline
          (Yojson.Safe.to_string
             (`Assoc
                [
                  ("scene", `String scene);
                  ("frames", `Int frames);
                  ("animation_s", `Float a);
                  ("still_s", `Float s);
                  ("ratio", `Float (a /. s));
                ]))
      else (
        print_endline
          "| scene | frames | animation (s) | one still (s) | animation / still |";
        print_endline "|---|---:|---:|---:|---:|";
        Printf.printf "| %s | %d | %.2f | %.2f | %.1f |\n" scene frames a s (a /. s)))
