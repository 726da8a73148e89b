(** [lancer watch]: a live preview in the browser. A local web server (cohttp) shows the
    scene rendered progressively (one sample per 8×8, 4×4, 2×2 pixels, then preview
    quality, then the chosen quality), renders it again whenever the scene or a file it
    reads is saved (inotify, or polling), cancelling the render in progress between tiles,
    and shows scene errors over the last good image. The page is [watch_page.html], built
    into the executable. *)

val cmd : int Cmdliner.Cmd.t
(** The [watch] command. *)
