(* lancer-mpirun ARGS…: runs `mpirun ARGS…` and tells the truth about an interrupt.

   On Ctrl-C, Open MPI's mpirun stops every rank with SIGTERM (each rank runs in a process
   group of its own, so the terminal's signal reaches mpirun alone) and exits with its own
   status, 1, whatever the ranks said; their last messages may be lost. This launcher runs
   mpirun as its child without a process group of its own, so that a terminal's Ctrl-C
   reaches both; it passes on the signals mpirun may not have received itself (SIGTERM,
   SIGHUP, and a SIGINT that was not a terminal's), waits for mpirun, and then exits 130
   with one line if it was interrupted, mpirun's status otherwise. It knows nothing of
   lancer-mpi: it only wraps mpirun. *)

open Cmdliner

external install_handlers : unit -> unit = "lancer_mpirun_install"
external interrupted : unit -> bool = "lancer_mpirun_interrupted"
external forward : int -> unit = "lancer_mpirun_forward"
external wait_nohang : int -> int = "lancer_mpirun_wait"

let say fmt = Printf.ksprintf (fun m -> prerr_endline ("lancer-mpirun: " ^ m)) fmt

let is_executable path =
  match Unix.stat path with
  | { Unix.st_kind = Unix.S_REG; _ } -> (
      try
        Unix.access path [ Unix.X_OK ];
        true
      with Unix.Unix_error _ -> false)
  | _ -> false
  | exception Unix.Unix_error _ -> false

(* [name] looked up as a shell does: as a path if it has a slash, else on $PATH. *)
let find name =
  if String.contains name '/' then if is_executable name then Some name else None
  else
    let dirs =
      String.split_on_char ':' (Option.value (Sys.getenv_opt "PATH") ~default:"")
    in
    List.find_map
      (fun d ->
        let p = Filename.concat (if d = "" then "." else d) name in
        if is_executable p then Some p else None)
      dirs

(* The mpirun to run, as (the name it is called by, its path). *)
let mpirun () =
  match Sys.getenv_opt "LANCER_MPIRUN" with
  | Some name when name <> "" -> (
      match find name with
      | Some path -> Ok (name, path)
      | None -> Error (Printf.sprintf "LANCER_MPIRUN=%s: no such executable" name))
  | _ -> (
      match find "mpirun" with
      | Some path -> Ok ("mpirun", path)
      | None ->
          Error
            "mpirun was not found on PATH: install Open MPI (Debian: apt-get install \
             openmpi-bin) or set LANCER_MPIRUN to the mpirun to run")

let not_found = 127
let interrupted_status = 130

let run args =
  match mpirun () with
  | Error m ->
      say "%s" m;
      not_found
  | Ok (name, path) -> (
      install_handlers ();
      if interrupted () then (
        say "interrupted";
        interrupted_status)
      else
        match
          Unix.create_process path
            (Array.append [| name |] args)
            Unix.stdin Unix.stdout Unix.stderr
        with
        | exception Unix.Unix_error (e, _, _) ->
            say "cannot run %s: %s" path (Unix.error_message e);
            not_found
        | pid ->
            (* Polled rather than blocked on, so that a signal that comes at any moment is
               passed on at once. *)
            let rec wait () =
              forward pid;
              match wait_nohang pid with
              | -1 ->
                  Unix.sleepf 0.02;
                  wait ()
              | status -> status
            in
            let status = wait () in
            if interrupted () && status <> 0 then (
              say "interrupted";
              interrupted_status)
            else if status >= 256 then (
              say "%s was killed by signal %d" name (status - 256);
              128 + (status - 256))
            else status)

(* --help and --version, and the man page they make (--help=groff). *)
let cmd =
  let doc = "run mpirun, and exit 130 with a message when interrupted" in
  let man =
    [
      `S Manpage.s_description;
      `P
        "$(tname) runs $(b,mpirun) with exactly the arguments it is given and waits for \
         it: $(b,lancer-mpirun -np 4 lancer-mpi render scene.rts -o scene.png) is \
         $(b,mpirun -np 4 lancer-mpi render scene.rts -o scene.png).";
      `P
        "On Ctrl-C, Open MPI's $(b,mpirun) stops every rank with SIGTERM and exits with \
         status 1 whatever the ranks reported, and may drop their last messages (each \
         rank runs in a process group of its own, so the terminal's Ctrl-C reaches \
         $(b,mpirun) alone). $(tname) notes the interrupt, waits for $(b,mpirun) to stop \
         the job, prints $(b,lancer-mpirun: interrupted) and exits 130, like $(b,lancer) \
         itself. Pressing Ctrl-C again while $(b,mpirun) stops the job (it then offers \
         to terminate it forcibly) changes nothing: the status is still 130.";
      `P
        "A terminal's Ctrl-C reaches $(b,mpirun) directly (both are in the terminal's \
         foreground process group). SIGTERM and SIGHUP sent to $(tname), and a SIGINT \
         that does not come from the terminal ($(b,kill -INT) of its pid), are passed on \
         to $(b,mpirun).";
      `P
        "$(tname) takes no option of its own but a lone $(b,--help) or $(b,--version); \
         $(b,mpirun --help) shows $(b,mpirun)'s options.";
      `S Manpage.s_examples;
      `Pre
        "  lancer-mpirun -np 4 --bind-to none lancer-mpi render scene.rts -o scene.png \
         --domains 2";
    ]
    @ [ `S Manpage.s_bugs; `P "Report bugs at https://github.com/lancer/lancer/issues." ]
  in
  let exits =
    [
      Cmd.Exit.info 0 ~doc:"when $(b,mpirun) succeeds.";
      Cmd.Exit.info 130
        ~doc:
          "when interrupted (SIGINT, SIGTERM or SIGHUP) and $(b,mpirun) did not succeed.";
      Cmd.Exit.info 127 ~doc:"when there is no $(b,mpirun) to run.";
      Cmd.Exit.info 1 ~max:255
        ~doc:
          "otherwise $(b,mpirun)'s own status, or 128 + N if signal N ended $(b,mpirun).";
    ]
  in
  let envs =
    [
      Cmd.Env.info "LANCER_MPIRUN"
        ~doc:"The $(b,mpirun) to run, a path or a name looked up on PATH; default mpirun.";
    ]
  in
  let args =
    Arg.(
      value & pos_all string []
      & info [] ~docv:"MPIRUN-ARGUMENT" ~doc:"Passed to $(b,mpirun) unchanged.")
  in
  Cmd.v
    (Cmd.info "lancer-mpirun" ~version:Lancer.Version.v ~doc ~man ~exits ~envs)
    Term.(const ignore $ args)

let () =
  let argv = Sys.argv in
  let own a = a = "--version" || a = "--help" || String.starts_with ~prefix:"--help=" a in
  if Array.length argv = 2 && own argv.(1) then exit (Cmd.eval cmd)
  else exit (run (Array.sub argv 1 (Array.length argv - 1)))
