(** The edge of the process for [lancer] and [lancer-mpi]: signals, standard output that
    fails, and the exit status of a failure as {!Lancer_job.Job_error.describe} gives it
    (with the start-up stub's out-of-memory text): 0 success, 1 a user error (a scene,
    option or file problem, explained in one message; a file or standard output the system
    refuses; out of memory), 2 an internal error (a bug: "please report it"), 130
    interrupted. No backtrace reaches the user. *)

(** {1 The process}

    This module's initialisation ends what the start-up stub ([startup_stubs.c], run
    before the OCaml runtime starts) began: SIGINT and SIGTERM, blocked from the first
    moment, get the handlers below and are let through (one that came in the meantime is
    then delivered to them); standard descriptors closed at start were opened on /dev/null
    so that no file takes their number, and writing to them fails as it would; the
    runtime's fatal errors are said as lancer's out of memory (1) or internal error (2);
    and an exception no command caught is said as {!Lancer_job.Job_error.describe} says
    it. *)

val main : (unit -> int) -> 'a
(** [main eval] runs the command line ([eval] gives the exit status) and ends the process
    with {!exit}: output that standard output cannot take, from help, [--version] or a
    command, is a user error (1) with the system's reason; an exception [eval] raises is
    said as {!Lancer_job.Job_error.describe} says it. *)

val exit : int -> 'a
(** [exit status] flushes standard output (what Printf and Format still hold) and ends the
    process: a status of 0 becomes 1 with "lancer: cannot write to standard output: …"
    when standard output cannot take it; standard output or error that fails is pointed at
    /dev/null, so that the flush at exit cannot fail again. *)

(** {1 Running a command} *)

type stop
(** This run's interrupts: the token SIGINT and SIGTERM cancel, and which one came. *)

val early_exit : (int -> unit) ref
(** How a run interrupted before its command's own handler ({!on_interrupt}) is installed
    ends, once its message is printed: {!exit} by default. Under MPI that would wait in
    [MPI_Finalize] for ranks that wait for this one; lancer-mpi makes it abort the job. *)

val on_interrupt : stop -> Lancer.Cancel.t
(** Make SIGINT and SIGTERM cancel the returned token ({!Lancer.Cancel.signal}): work that
    polls it stops with [Sys.Break], and outside pools and writes [Sys.Break] is raised at
    once, so that loading and evaluation stop too. Pass the token to the render, the pool
    and the writes. *)

val fail : ?interrupted:string -> ?terminated:string -> stop -> exn -> int
(** Print what {!Lancer_job.Job_error.describe} says of an exception and give its status;
    [terminated] replaces the interrupt's message when the stop came from SIGTERM. *)

val run : ?interrupted:string -> ?terminated:string -> (stop -> unit) -> int
(** [run f] runs a command body with this run's {!stop} and turns its outcome into an exit
    status ({!fail}); output that standard output cannot take (a full disk, [>/dev/full])
    is a user error, 1, with the system's reason. *)

val say : program:string -> string -> unit
(** A line on stderr from the command line, before any command runs (a hint about the
    command line itself), prefixed with the program's name. *)

val resumed_interrupt : string
(** What an interrupted [render --resume] says after "interrupted": the finished tiles are
    kept in the checkpoint. *)
