(** The failures of a job that the user can fix or that stop it early: raised by the job
    layer, turned into text and an exit status only at the command line's edge. *)

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
