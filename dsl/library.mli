(** The scene library shipped with lancer: the files that [include "lancer/…"] finds
    (lancer/materials.rts, lancer/colors.rts).

    An include path is first taken relative to the including file, as always. When no such
    file exists and the path starts with [lancer/], it is looked for under each directory
    of [LANCER_PATH] (colon-separated), then under the [share] directory beside the
    running program's [bin] (where [dune install] puts the library:
    [PREFIX/share/lancer/]), and last in the copy built into the language, so that a scene
    using the library loads wherever lancer runs. *)

val locate : including:string -> string -> string
(** [locate ~including p] is the path to read for [include "p"] written in file
    [including]: the file beside [including] when it exists or [p] is not a library path,
    otherwise the first library copy found; a built-in copy is named
    ["(built in)/lancer/NAME"]. *)

val read : string -> (string, string) result
(** [read path] is the text of [path] as {!locate} gave it: a built-in copy, or the file.
*)

val files : string list
(** The library's include paths, e.g. ["lancer/materials.rts"]. *)

val builtin : string -> string option
(** [builtin p] is the text of the built-in copy of library path [p]. *)

val names : string -> string list
(** [names p] are the names library path [p] defines at top level ([let NAME = …] at a
    line's start), in order, from its built-in copy; [[]] for a path not in the library.
*)
