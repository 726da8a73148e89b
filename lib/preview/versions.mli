(** The versions of [lancer watch]'s preview: each save (or a change of quality or frame
    on the page) asks for a new version, which cancels the one being rendered; a renderer
    on a domain of its own loads the scene when its files changed, evaluates it once, and
    renders it in passes through the one tile loop ({!Lancer.Render.render}): one sample
    per 8×8, 4×4 and 2×2 pixels, then preview quality, then the chosen quality, each
    published as a PNG and an event. *)

type params = {
  quality : Lancer.Quality.t option;  (** of the last pass; [None]: the scene's own *)
  frame : int;  (** of an animation *)
  play : bool;  (** playing: the passes stop at preview quality *)
}
(** What the page asks for. *)

type t
(** The record the server and the renderer share. *)

val create : Lancer.Options.t -> wake:Unix.file_descr -> t
(** The first version asked for ([--quality], frame 0), watching the scene file; the
    renderer writes a byte to [wake] when it publishes events. *)

val start :
  ?max_error:Lancer.Compare.metric ->
  t ->
  Lancer.Options.t ->
  any_line:bool ->
  domains:int ->
  tmp:string ->
  unit
(** Start the renderer on a domain of its own, with a pool of [domains] (the options'
    size, samples and depth apply to the last pass), its PNGs encoded in the directory
    [tmp]. An error located in a file outside the scene's directory tree is shown without
    its line unless [any_line]. With [max_error], the last pass is at the settings
    {!Lancer.Budget.choose} picks, searched after the coarse passes and said on standard
    output. *)

val request : t -> ?reload:bool -> (params -> params) -> unit
(** Ask for a new version with these parameters, cancelling the render in progress;
    [reload] when the files changed. *)

val events : t -> (string * string) list
(** The events published since the last call, oldest first: (event, JSON data) of [scene],
    [ok], [image], [stats] and [failure]. *)

val image : t -> int -> string option
(** The PNG bytes of image [k] of the [image] events, while among the last few. *)

val inputs : t -> string list
(** The files to watch: the scene, its includes, images and meshes, and the files its
    errors name. *)
