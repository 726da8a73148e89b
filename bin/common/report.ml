open Lancer
module Job_error = Lancer_job.Job_error

(* Ends what the start-up stub (startup_stubs.c) began before the runtime started. *)
external startup_done : unit -> int = "lancer_startup_done"

(* "lancer: out of memory …", with the limit when there is one: the words the stub's
   handler of the runtime's fatal errors uses too. *)
external out_of_memory_text : unit -> string = "lancer_out_of_memory_text"

let describe ?interrupted e =
  Job_error.describe ?interrupted ~out_of_memory:out_of_memory_text e

(* ---- Standard output and error ---- *)

(* Standard output or error that cannot take what is buffered for it is pointed at
   /dev/null once its failure is known, so that no later flush (the one at exit among
   them) fails again. *)
let silence fd =
  try
    let null = Unix.openfile "/dev/null" [ Unix.O_WRONLY ] 0 in
    Unix.dup2 null fd;
    Unix.close null
  with Unix.Unix_error _ -> ()

(* A message on stderr; stderr that cannot take it (closed, full) loses it and nothing
   else. *)
let print_error text =
  try
    prerr_string text;
    flush stderr
  with Sys_error _ -> silence Unix.stderr

(* Which standard descriptors were closed when lancer started (bit i for descriptor i):
   the start-up stub opened them on /dev/null so that writing fails as on a closed one. *)
let closed_at_start = ref 0

(* Standard output that cannot take what was printed (a full disk, /dev/full, closed):
   said once, with the system's reason. *)
let stdout_failed m =
  let why = if !closed_at_start land 2 <> 0 then "it is closed" else m in
  print_error ("lancer: cannot write to standard output: " ^ why ^ "\n");
  silence Unix.stdout;
  1

(* What is still buffered for standard output (by Printf or Format), written: a status
   of 0 becomes 1 when it cannot be, with the reason; another status stays. *)
let flush_stdout status =
  match
    Format.pp_print_flush Format.std_formatter ();
    flush stdout
  with
  | () -> status
  | exception Sys_error m ->
      if status = 0 then stdout_failed m
      else (
        silence Unix.stdout;
        status)

(* What the system refused: a file, or standard output. Standard output fails again when
   flushed, unless the failure was permanent (closed: the channel then drops what it
   held), and lancer's only descriptor that can be closed is one closed at start. *)
let system_error m =
  match flush stdout with
  | () when !closed_at_start land 2 <> 0 && m = Unix.error_message Unix.EBADF ->
      stdout_failed m
  | () ->
      print_error ("lancer: " ^ m ^ "\n");
      1
  | exception Sys_error m -> stdout_failed m

let exit status =
  let status = flush_stdout status in
  (try flush stderr with Sys_error _ -> silence Unix.stderr);
  Stdlib.exit status

type stop = {
  signal : int Atomic.t;  (** the signal that stopped the run; 0: none *)
  over : bool Atomic.t;  (** the command's body has returned or raised *)
}

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
        print_error text;
        !early_exit status)
  in
  Sys.set_signal Sys.sigint early;
  Sys.set_signal Sys.sigterm early;
  (* An exception that no command caught (there should be none) is said as {!describe}
     says it, never as the runtime's "Fatal error". *)
  Printexc.set_uncaught_exception_handler (fun e _ ->
      Unix._exit
        (match e with
        | Sys_error m -> system_error m
        | e ->
            let text, status = describe e in
            print_error text;
            status));
  closed_at_start := startup_done ()

let on_interrupt stop =
  let token = Cancel.create () in
  (* Inside a pool or a write the work stops at its next poll of the token, in lancer's
     own code; elsewhere (loading, evaluating) at once. Once the command's body is over,
     there is nothing left to stop: a signal that comes while the run ends (its message
     printed, standard output flushed, the process exiting) is let go, and the run ends
     with its own status, instead of raising Sys.Break where nothing catches it. *)
  let h =
    Sys.Signal_handle
      (fun signal ->
        if not (Atomic.get stop.over) then (
          Atomic.set stop.signal signal;
          Cancel.signal token))
  in
  Sys.set_signal Sys.sigint h;
  Sys.set_signal Sys.sigterm h;
  (* Past a file-size limit (ulimit -f) the default action of SIGXFSZ kills the process
     and leaves the temporary file behind; ignored, the write fails with EFBIG and the
     atomic write cleans up and reports it. *)
  Sys.set_signal Sys.sigxfsz Sys.Signal_ignore;
  token

let fail ?(interrupted = "no output was written") ?terminated stop e =
  let interrupted =
    match terminated with
    | Some m when Atomic.get stop.signal = Sys.sigterm -> m
    | _ -> "interrupted; " ^ interrupted
  in
  match e with
  | Sys_error m -> system_error m
  | e ->
      let text, status = describe ~interrupted e in
      print_error text;
      status

let run ?interrupted ?terminated f =
  let stop = { signal = Atomic.make 0; over = Atomic.make false } in
  (* [over] is set before anything that can poll for a signal (an allocation, a call). *)
  let outcome =
    match f stop with
    | () ->
        Atomic.set stop.over true;
        0
    | exception e ->
        Atomic.set stop.over true;
        fail ?interrupted ?terminated stop e
  in
  flush_stdout outcome

let main eval =
  exit
    (match eval () with
    | status -> status
    | exception Sys_error m -> system_error m
    | exception e ->
        let text, status = describe e in
        print_error text;
        status)

let say ~program line = print_error (program ^ ": " ^ line ^ "\n")

let resumed_interrupt =
  "the finished tiles are kept in the checkpoint; run again with --resume to continue"
