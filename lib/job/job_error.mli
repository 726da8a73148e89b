(** The failures of a job that the user can fix or that stop it early, raised by the job
    layer and the layers over it, and the text and exit status lancer gives each; the
    command line's edge prints them and exits. *)

exception User of string
(** A mistake the user can fix (options, files, the output directory): one clear message,
    without the program's name. *)

exception Scene of { errors : Diagnostic.t list; note : string }
(** A scene's located errors ([file:line:col], the line, a caret), every one of them, and
    a line to say after them ([""] for none). *)

exception Interrupted of string
(** An interrupt, and what became of the work: [Interrupted what] says it ("out.png was
    written in full first" when it came during the final write). *)

val user : ('a, unit, string, 'b) format4 -> 'a
(** [user fmt …] raises {!User} with the formatted message. *)

(** {1 What lancer says of a failure}

    The text printed on stderr and the exit status of each failure, as
    doc/reference/command-line.md documents them: 0 success, 1 a user error (a scene,
    option or file problem, explained in one message; a file the system refuses; out of
    memory), 2 an internal error (a bug: "please report it"), 130 interrupted. *)

val errors_text : Diagnostic.t list -> string
(** Each located error printed with {!Lancer_diag.Diagnostic.pp}, one after the other. *)

val out_of_memory_text : unit -> string
(** [lancer: out of memory …] with what to try, and the address-space limit when there is
    one ({!Lancer_diag.Address_space.limit}). *)

val describe :
  ?interrupted:string -> ?out_of_memory:(unit -> string) -> exn -> string * int
(** The text for an exception that ends a command, and the exit status: [lancer: message]
    for {!User} (1), the located errors and their note for {!Scene} (1),
    [lancer: interrupted; …] for an interrupt (130: [interrupted] says what became of the
    output, default "no output was written", and {!Interrupted} what was finished first),
    [lancer: …] with the system's reason for [Sys_error] (1), [out_of_memory ()] (default
    {!out_of_memory_text}) for [Out_of_memory] and for a domain that could not be started
    (1), and anything else as an internal error (2). *)

val message : exn -> string
(** What went wrong, without the program's name: the message of a user error, the located
    errors of a scene, ["internal error: …"] for anything else (a worker's failure, shown
    by another process). *)
