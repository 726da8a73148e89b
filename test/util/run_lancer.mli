(** Running the [lancer] executable as a user would, for the command-line test suites. *)

val tmpdir : string -> string
(** [tmpdir prefix] makes a fresh, empty directory under the system's temporary directory.
*)

val write_file : string -> string -> unit
(** [write_file path text] writes [text] to [path]. *)

val read_file : string -> string
(** The whole contents of a file. *)

val contains : string -> string -> bool
(** [contains s sub]: whether [sub] occurs in [s]. *)

val run :
  ?prefix:string -> exe:string -> dir:string -> string list -> int * string * string
(** [run ~exe ~dir args] runs [exe args] through the shell in [dir], with [prefix] (shell
    words such as [ulimit -f 10;]) before it and stdin closed: (exit status, stdout,
    stderr). *)
