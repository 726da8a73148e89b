(** [lancer watch]: a live preview in the browser. A local web server (cohttp) shows the
    scene rendered progressively (one sample per 8×8, 4×4, 2×2 pixels, then preview
    quality, then the chosen quality), renders it again whenever the scene or a file it
    reads is saved (inotify, or polling), cancelling the render in progress between tiles,
    and shows scene errors over the last good image. The page is [watch_page.html], built
    into the executable. The server listens on a loopback address unless told otherwise,
    answers only its own page, and bounds each request's size, each connection's idle time
    and the connections at once. *)

val cmd : int Cmdliner.Cmd.t
(** The [watch] command. *)
