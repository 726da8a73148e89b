(** The language's phases run one by one on a program of one file named "test.rts", for
    the tests that look at each phase: the checker's mistakes, the run's, and the run's
    with every type left to it. *)

val parse : string -> Lancer_dsl.Ast.stmt list
(** Fails the test on a syntax error. *)

val checked :
  ?schema:Lancer_dsl.Schema.block list ->
  ?types:bool ->
  string ->
  Lancer_dsl.Check.program * Lancer_dsl.Error.t list
(** The typed program and the checker's mistakes. *)

val run :
  ?schema:Lancer_dsl.Schema.block list ->
  ?types:bool ->
  ?time:float ->
  ?frame:int ->
  ?objects:bool ->
  string ->
  (Lancer_description.Description.t, Lancer_dsl.Error.t list) result
(** The checker, then the run: the description, or the mistakes of both in source order
    (the checker's first at a place). [~types:false]: every type is the run's to check. *)

val run_errors : ?types:bool -> string -> Lancer_dsl.Error.t list
(** The run's own mistakes (the checker's left out). *)

val errors :
  ?schema:Lancer_dsl.Schema.block list -> ?types:bool -> string -> Lancer_dsl.Error.t list
(** Every mistake, as {!run} gives them. *)
