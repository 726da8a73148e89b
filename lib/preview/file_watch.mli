(** Watching the files of a preview: the scene, its includes, images and meshes. *)

val watch : poll:bool -> (unit -> string list) -> (unit -> unit) -> 'a Lwt.t
(** [watch ~poll inputs changed] calls [changed] (at most every few tens of milliseconds)
    when a file of [inputs ()] is written, replaced or removed: inotify on their
    directories (an editor that saves by renaming replaces the file itself), polling their
    status twice a second where inotify is not available or [poll] asks for it. The list
    is read again as it changes. It never returns. *)
