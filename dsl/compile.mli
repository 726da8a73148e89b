(** The typed program to closures, once: each top-level statement becomes code that runs
    in the program's frame and puts its objects in a scope ({!Run} runs them, as many
    times as it is asked). A block's fields are evaluated in the order written into the
    places the checker gave them, and read by {!Build}; what the checker found wrong is
    not run, and gives up quietly. *)

type scode = Value.frame -> Value.scope -> unit

type t = {
  stmts : scode array;  (** the top-level statements, includes flattened *)
  slots : int;  (** the size of the program's frame *)
}

val program : Check.program -> t

(** {1 Statement by statement} *)

type state

val start : unit -> state

val top : state -> Tast.stmt -> unit
(** The next top-level statement (includes flattened). *)

val finish : state -> t

val objects_written : Tast.stmt list -> int
(** The objects a list of statements surely builds each time it runs: object blocks, and
    those of groups; not those behind a condition (the smaller branch), a macro call or an
    inner loop (which checks its own). *)
