(** Where the memory of n × n spheres made by a loop goes, stage by stage, in words per
    object: the description the language makes, the compiled primitives (materials
    included), their materials alone, the acceleration structure, and the largest heap the
    process had. With the default material, or a colour each computed in the loop. *)

val program : colour:bool -> int -> string
(** The program of [n] × [n] spheres, each with [material { color: (i / n, j / n, 0.5) }]
    with [colour]. *)

val run : grid:int -> colour:bool -> json:bool -> unit
(** Loads, describes and compiles the program of [grid] × [grid] spheres in this process,
    as a still's render does, and prints the figures (a Markdown table, or JSON with
    [json]). Raises {!Lancer.Job_error.User}. *)
