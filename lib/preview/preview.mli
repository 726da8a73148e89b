(** [lancer watch] as a library function: a live preview in the browser. A local web
    server ({!Http}) shows the scene rendered in passes ({!Versions}: one sample per 8×8,
    4×4, 2×2 pixels, then preview quality, then the chosen quality), renders it again
    whenever the scene or a file it reads is saved ({!File_watch}), cancelling the render
    in progress, and shows scene errors over the last good image. The page
    ([watch_page.html]) is built into the library. *)

val run :
  ?max_error:Lancer.Compare.metric ->
  Lancer.Options.t ->
  host:string ->
  port:int ->
  poll:bool ->
  beyond_loopback:bool ->
  any_source_line:bool ->
  'a
(** Check the options (a scene file, not standard input; the host as {!Listen.socket}
    says), print the address, and serve until SIGINT or SIGTERM, then remove the temporary
    directory of the images and raise [Sys.Break]. The options' quality, size, samples,
    depth and domains apply to the full image; [quiet] prints only the address. [poll]
    watches the files by polling; [any_source_line] shows the line of an error in a file
    outside the scene's directory tree too. With [max_error], the full image of each
    version (not while playing) is at the settings {!Lancer.Budget.choose} picks for it,
    said in the terminal. Raises {!Lancer.Job_error.User}. *)
