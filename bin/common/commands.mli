(** The [lancer] command group (render, check, diff, …), shared by the ordinary and the
    statically linked executables. *)

val main : unit -> unit
(** Parse [Sys.argv], run the command and exit with its status. *)
