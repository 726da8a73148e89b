(** [lancer watch]: its options, and a call of {!Lancer_preview.Preview.run}, the live
    preview in the browser. *)

val cmd : int Cmdliner.Cmd.t
(** The [watch] command. *)
