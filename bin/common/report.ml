open Lancer
module Job_error = Lancer_job.Job_error

(* Ends what the start-up stub (startup_stubs.c) began before the runtime started. *)
external startup_done : unit -> unit = "lancer_startup_done"

let errors_text errs =
  String.concat "\n" (List.map (Format.asprintf "%a" Diagnostic.pp) errs)

let scene_text errors note =
  errors_text errors ^ if note = "" then "" else "lancer: " ^ note ^ "\n"

let internal e =
  Printf.sprintf
    "lancer: internal error: %s\n\
     This is a bug in lancer; please report it with the scene and the command.\n"
    (Printexc.to_string e)

let describe ?(interrupted = "interrupted; no output was written") = function
  | Job_error.User m -> ("lancer: " ^ m ^ "\n", 1)
  | Job_error.Scene { errors; note } -> (scene_text errors note, 1)
  | Sys.Break | Fun.Finally_raised Sys.Break -> ("\nlancer: " ^ interrupted ^ "\n", 130)
  | Job_error.Interrupted what -> ("\nlancer: interrupted; " ^ what ^ "\n", 130)
  | Out_of_memory -> ("lancer: out of memory (try a smaller image or fewer objects)\n", 1)
  | Sys_error m -> ("lancer: " ^ m ^ "\n", 1)
  | e -> (internal e, 2)

let message = function
  | Job_error.User m -> m
  | Job_error.Scene { errors; note } -> scene_text errors note
  | e -> "internal error: " ^ Printexc.to_string e

type stop = { signal : int Atomic.t (* the signal that stopped the run; 0: none *) }

(* From the program's first moment (the start-up stub blocks SIGINT and SIGTERM before the
   runtime starts, and this module's initialisation, before any command runs, before the
   options are parsed and MPI is started, installs these handlers and lets the signals
   through) to the command's own handler of {!on_interrupt}, SIGINT and SIGTERM end the
   run with the interrupt's message and status, as they do later; the default action
   would end it without a word. *)
let early_exit = ref exit

let () =
  let early =
    Sys.Signal_handle
      (fun _ ->
        let text, status = describe Sys.Break in
        prerr_string text;
        flush stderr;
        !early_exit status)
  in
  Sys.set_signal Sys.sigint early;
  Sys.set_signal Sys.sigterm early;
  startup_done ()

let on_interrupt stop =
  let token = Cancel.create () in
  (* Inside a pool or a write the work stops at its next poll of the token, in lancer's
     own code; elsewhere (loading, evaluating) at once. *)
  let h =
    Sys.Signal_handle
      (fun signal ->
        Atomic.set stop.signal signal;
        Cancel.signal token)
  in
  Sys.set_signal Sys.sigint h;
  Sys.set_signal Sys.sigterm h;
  (* Past a file-size limit (ulimit -f) the default action of SIGXFSZ kills the process
     and leaves the temporary file behind; ignored, the write fails with EFBIG and the
     atomic write cleans up and reports it. *)
  Sys.set_signal Sys.sigxfsz Sys.Signal_ignore;
  token

(* Standard output that cannot take what was printed (a full disk, /dev/full): said once,
   and fd 1 is pointed at /dev/null so that the flush at exit does not fail again. *)
let stdout_failed m =
  prerr_endline ("lancer: cannot write to standard output: " ^ m);
  (try
     let null = Unix.openfile "/dev/null" [ Unix.O_WRONLY ] 0 in
     Unix.dup2 null Unix.stdout;
     Unix.close null
   with Unix.Unix_error _ -> ());
  1

let fail ?(interrupted = "no output was written") ?terminated stop e =
  let interrupted =
    match terminated with
    | Some m when Atomic.get stop.signal = Sys.sigterm -> m
    | _ -> "interrupted; " ^ interrupted
  in
  match e with
  | Sys_error _ -> (
      (* What the system refused: a file, or standard output. *)
      match flush stdout with
      | () ->
          prerr_string (fst (describe e));
          flush stderr;
          1
      | exception Sys_error m -> stdout_failed m)
  | e ->
      let text, status = describe ~interrupted e in
      prerr_string text;
      flush stderr;
      status

let run ?interrupted ?terminated f =
  let stop = { signal = Atomic.make 0 } in
  let outcome =
    match f stop with () -> 0 | exception e -> fail ?interrupted ?terminated stop e
  in
  match flush stdout with
  | () -> outcome
  | exception Sys_error m -> if outcome = 0 then stdout_failed m else outcome

let say ~program line = prerr_endline (program ^ ": " ^ line)

let resumed_interrupt =
  "the finished tiles are kept in the checkpoint; run again with --resume to continue"
