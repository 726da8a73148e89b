(** Where a still's image and statistics go, checked before any rendering: an image file
    (PNG, PPM, or the linear EXR, HDR and PFM, by its extension) or standard output ([-]),
    at the depth asked, with an alpha channel of coverage, of a region or cropped to it.
*)

type encoding = {
  bits : int option;
      (** bits per channel ({!Lancer_image.Image.file_of}); [None]: the format's own
          default *)
  alpha : bool;  (** an alpha channel of coverage *)
  region : Image.region option;  (** render only these pixels *)
  crop : bool;  (** write only the region *)
  format : Image.format option;  (** [--format], for [-o -] *)
}
(** How the image of a still is rendered and written ([--bits], [--alpha], [--region],
    [--crop], [--format]). *)

val default_encoding : encoding
(** The format's default depth, no alpha, the whole image. *)

val is_stdout : string -> bool
(** Whether an output path is [-], standard output. *)

val format_of : ?format:Image.format -> string -> Image.format
(** The format of an output: [format] (default PNG) for [-], else its extension's; raises
    {!Lancer_job.Job_error.User} for an unknown extension or one that [format]
    contradicts. *)

val check_output : ?format:Image.format -> string -> unit
(** Refuse, before any rendering, an output with an unknown extension (or one that
    [format] contradicts), in a missing directory, that is a directory or read-only, and
    [-] when standard output is a terminal; raises {!Lancer_job.Job_error.User}. *)

val stats_to_stdout : Options.t -> bool
(** Whether [--stats] is [-]: the statistics go to standard output. *)

val stats_file : Options.t -> string option
(** The file the statistics go to: [--stats]'s, unless it is [-] (standard output). *)

val write_stats_stdout : Yojson.Safe.t -> unit
(** The statistics on standard output, as their file holds them; a reader that went away
    is an error with a message. *)

val check_stats_name : string option -> unit
(** Refuse a [--stats] file named like a scene, image, mesh or video ([.rts], [.png], …):
    the sign that the option took the scene as its value. *)

val check_encoding : encoding -> out:string -> Scene.t -> unit
(** Refuse a region outside the scene's image, [--crop] without [--region], and [--alpha]
    with a PPM output; raises {!Lancer_job.Job_error.User}. *)

val guard_render : Options.t -> Scenes.t -> out:string -> unit
(** {!Lancer_job.Files.guard_writes} for a still: the image and the statistics against the
    scene's files and an animation's records, and not both on standard output. *)

val write_image :
  ?cancel:Cancel.t ->
  ?encoding:encoding ->
  ?alpha:Float.Array.t ->
  ?record:Provenance.t ->
  string ->
  Scene.t ->
  Framebuffer.t ->
  unit
(** Encode with the scene's gamma (and [encoding]: 8 bits, whole image by default; the
    coverage [alpha] as a fourth channel; [record] in a PNG's text) and write atomically,
    or to standard output for [-] (PNG unless [--format ppm]; a closed pipe is an error,
    not a signal); raises {!Lancer_job.Job_error.User}. With [cancel] an interrupt during
    the write does not cut it short ({!Lancer_job.Files.uninterrupted}). *)
