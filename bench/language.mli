(** The scene language's evaluation, each a whole check in this process (parse, static
    check, evaluation): a 3-million-iteration loop beside the same loop in CPython (when
    [python3] is on the PATH, a whole process, alternated), a million sphere blocks, as
    many with a material expression each, and as many rotated boxes in translated groups
    (time, words allocated and held per block). *)

val grid_header : int -> string
(** The settings, camera and light of the object programs, for [n] × [n] objects around
    the origin. *)

val run : repeat:int -> grid:int -> json:bool -> unit
(** [repeat] runs of each program (medians), the objects' programs of [grid] × [grid]
    blocks; a Markdown table, or JSON with [json]. Raises {!Lancer.Job_error.User}. *)
