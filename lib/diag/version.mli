(** The version of lancer, as written in [dune-project] (its one source). *)

val v : string
(** For example ["0.1.0"]: what [lancer --version] prints. *)
