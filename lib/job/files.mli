(** The files a job writes: refused before any work when they cannot be written or would
    replace what the job reads, and written whole (a temporary file, then a rename), an
    interrupt answered only once the file is complete. *)

val check_writable : string -> unit
(** Refuse, before any work, a file path in a missing directory, that is a directory, or
    that is a read-only file, or in a directory where this process cannot create a file
    (tried with an empty file, removed at once); raises {!Job_error.User}. *)

val guard_writes :
  ?distinct:bool ->
  ?names:string list ->
  reads:(string * string) list ->
  (string * string) list ->
  unit
(** [guard_writes ~reads writes] refuses, before any work, each write (path, what it is)
    that {!check_writable} refuses, that is one of the files read (by any name: a symbolic
    link, a hard link, ./a.png for a.png), that is one of [names] (files the scene may
    read later, at another frame), or, with [distinct] (default), that is the same file as
    another write. Raises {!Job_error.User} naming both. Once every write passes, the
    temporary files that a killed run of this machine left in each directory written are
    removed ({!Lancer_image.Safe_file.remove_stale}), each named on stderr: once per
    directory, before anything is written. *)

val refuse_overwrite : reads:(string * string) list -> string -> string -> unit
(** [refuse_overwrite ~reads path what]: {!guard_writes}' test of one write against the
    files read, without probing the directory: for each frame as it is written. *)

val uninterrupted : ?cancel:Cancel.t -> string -> (unit -> 'a) -> 'a
(** [uninterrupted ~cancel what write] runs [write] so that an interrupt does not cut it
    short: a token already cancelled raises [Sys.Break] and writes nothing; one cancelled
    during the write lets it finish, then raises {!Job_error.Interrupted} saying [what]
    was written in full first. *)

val write_image :
  ?cancel:Cancel.t ->
  ?bits:int ->
  ?alpha:Float.Array.t ->
  ?crop:Image.region ->
  ?record:Provenance.t ->
  string ->
  Scene.t ->
  Framebuffer.t ->
  Image.written
(** Encode with the scene's gamma ([bits] as {!Lancer_image.Image.file_of} takes them; the
    coverage [alpha] as a fourth channel; only [crop] when given) and write the file
    atomically, {!uninterrupted}, with [record] in it (a PNG's text; {!Provenance}); the
    size and MD5 of the bytes written. Raises {!Job_error.User}. *)

val write_json : ?cancel:Cancel.t -> string -> Yojson.Safe.t -> unit
(** Write a JSON file atomically, {!uninterrupted}; raises {!Job_error.User}. *)
