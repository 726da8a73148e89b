(** A block kind of the schema made ready to use, once: its fields by name and by place
    ("slot": the index in {!Lancer_dsl.Schema.names_of}), each with its default as a
    value. The checker places fields by these, and a block's evaluation reads them by
    their slots. *)

type entry = {
  sch : Schema.field;
  default : Value.t;
      (** the schema's default, read as the literal it is; for a field without one, a
          placeholder of its type (used only once the block has failed, or where its
          reading supplies the value itself) *)
  required : bool;  (** required whatever else the block holds *)
}

type t = {
  block : Schema.block;
  names : string array;  (** {!Lancer_dsl.Schema.names_of} *)
  entries : entry array;  (** by slot: the first entry of the field's name *)
  named : Schema.field list array;  (** by slot: every entry of the field's name *)
  material : int;  (** the slot of [material], [-1] for a kind without *)
  kind : int;  (** the slot of [kind], [-1] for a kind without *)
  values : int;
      (** the slots before it are those of fields that may hold a value: a field that
          repeats (a transform) is written in the order of the others, not in a slot *)
}

val get : Schema.block -> t
(** The kind of a block of a schema: its fields by slot. *)

val slot : t -> string -> int
(** A field's slot; [-1] for a name the kind does not have. *)

val entry : Schema.field -> entry
