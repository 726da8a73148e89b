(** Files written whole or not at all.

    A file is written into a temporary file beside it, [.NAME.tmp-OWNER-PID-RAND], and
    renamed into place only once every write, the flush, the [fsync] and the close have
    succeeded; on any failure (a full disk, a file-size limit, an interrupt) the temporary
    file is removed and the previous file under the final name is untouched. An existing
    file that its owner may not write (mode 0444) is refused, not replaced. Temporary
    files left by a process of this machine that was killed are removed by
    {!remove_stale}, which a run calls once for each directory it will write into; those
    of other machines sharing it are left alone. Messages name the final path, never the
    temporary one. *)

val check_writable : string -> (unit, string) result
(** Whether [path] could be written: not a directory, in a directory that exists, and not
    a file the user may not write (for root, one without any write permission bit).
    Checked again by {!write}; callers use it to refuse before working. *)

val write : string -> (out_channel -> unit) -> (unit, string) result
(** [write path f] writes [path] through [f] atomically, as described above. A device or a
    pipe ([/dev/stdout], a FIFO) is written in place, never replaced. [Sys.Break] from [f]
    is re-raised after the temporary file is removed. *)

val owner : string
(** This machine and process-id namespace as written in temporary names: the host name
    (characters other than letters, digits and dots made [_]), [_], and the namespace's
    number. *)

val temp_path : string -> string
(** A fresh temporary name beside [path], [.NAME.tmp-OWNER-PID-RAND] with {!owner} and
    this process's id. *)

val remove_stale : string -> (string * int) list
(** [remove_stale dir] removes the temporary files of {!temp_path}'s form in [dir] that
    {!owner} wrote and whose process is no longer running (no such process id), and is the
    list of paths removed, each with the id of the process that left it; files of other
    owners (other machines sharing the directory) are never touched. *)
