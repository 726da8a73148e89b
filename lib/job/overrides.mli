(** The command-line options that change a scene's pixels: the image size, samples and
    depth, and a quality preset ({!Quality}), applied over what the scene file sets. *)

type t = {
  width : int option;
  height : int option;
  samples : int option;
  depth : int option;
  quality : Quality.t option;
}

val none : t
(** Nothing overridden. *)

val apply : t -> Scene.t -> Scene.t
(** The scene under the preset, then with the given size, samples and depth. Raises
    {!Job_error.User} for a depth beyond {!Lancer_description.Settings.max_depth} (named
    [--depth]) or settings the scene refuses. *)

val named_fields : t -> (string * string) list
(** Each option by its name on the command line (["--width"]) with its value as text
    (["-"] when unset), in a fixed order. *)

val digest_fields : t -> string list
(** Each option as text (["-"] when unset), in a fixed order: for the digests that say
    which pixels a record holds. *)
