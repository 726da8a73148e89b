(** Running the [lancer] executable as a user would, for the command-line test suites. *)

val tmpdir : string -> string
(** [tmpdir prefix] makes a fresh, empty directory under the system's temporary directory.
*)

val write_file : string -> string -> unit
(** [write_file path text] writes [text] to [path]. *)

val read_file : string -> string
(** The whole contents of a file. *)

val scene_files : string -> string list -> string list
(** [scene_files dir subs]: the [.rts] files of each folder [subs] of [dir] (["."] for
    [dir] itself), each folder's sorted, as paths under [dir]. *)

val pixels : string -> string
(** The decoded image of a PNG or PPM file (its size, channels, depth and samples), for
    comparing the pixels of images made by different routes: their bytes differ where
    their records do ({!Lancer_job.Provenance}: the frame, the time, the options). *)

val contains : string -> string -> bool
(** [contains s sub]: whether [sub] occurs in [s]. *)

val run :
  ?prefix:string -> exe:string -> dir:string -> string list -> int * string * string
(** [run ~exe ~dir args] runs [exe args] through the shell in [dir], with [prefix] (shell
    words such as [ulimit -f 10;]) before it and stdin closed: (exit status, stdout,
    stderr). *)

val check_status : string -> int -> int * string * string -> unit
(** [check_status msg expected r]: the exit status of [r] (from {!run}) is [expected]; the
    failure shows its stderr. *)

val says : string -> int * string * string -> string -> unit
(** [says msg r sub]: [r]'s stdout or stderr contains [sub]. *)

val spawn : exe:string -> dir:string -> string list -> int
(** [spawn ~exe ~dir args] starts [exe args] in [dir] in the background, its standard
    streams on /dev/null; its pid. *)

val wait_status : int -> int
(** The exit status of a spawned process, −1 if a signal ended it. *)

val status_text : Unix.process_status -> string
(** ["exit 1"], ["killed by signal 9"], … *)

val quality_rows : exe:string -> dir:string -> string -> string -> (string * float) list
(** [quality_rows ~exe ~dir scene knob]: the rows of [knob] that
    [lancer bench quality SCENE --domains 1 --json] measures in [dir] (with its own cache
    there), as (value, RMSE), in order; fails the test when the command fails. *)
