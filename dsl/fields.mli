(** A block's fields, read: where a block is written, which of its kind's fields it gives
    and where ({!type-site}, made once); each time it is evaluated, their values ({!t}),
    read by the accessors below with their kind's defaults and ranges. A value outside its
    range, or of a type the checker could not know and that is wrong, is reported at the
    value, the block marked failed and the default given instead, so that every mistake of
    a block is reported at once. What the checker reported is not reported again. *)

type entry = Kind.entry = { sch : Schema.field; default : Value.t; required : bool }

type site = {
  kind_ : Kind.t;
  block : Schema.block;
  kind : string;  (** the keyword, as messages name the block *)
  kloc : Loc.t;
  names : string array;  (** the kind's fields ({!Schema.names_of}) *)
  entries : entry array;  (** by field: the first entry of its name *)
  given : bool array;  (** by field: written (and not dropped by the checker) *)
  vlocs : Loc.t array;  (** by field: where its value is written *)
  wrong : bool array;  (** by field: its value's type is one it does not take *)
  steps : (string * Loc.t) array;  (** the transforms, in order: name, value's place *)
  failed : bool;  (** the checker found the block wrong *)
  kind_known : bool;  (** the checker knew its [kind] and checked what depends on it *)
}

val site : Tast.block -> site
val step_count : site -> int

type t = {
  site : site;
  vals : Value.t array;
      (** by field, up to the last one given at least; [VPoison] where it is not given *)
  svals : Value.t array;  (** the transforms' values, in order *)
  mutable failed : bool;  (** a value failed (reported), or a mistake was found *)
  out : Value.sink;  (** where its mistakes go, and the files it names *)
}
(** One evaluation of a block: its fields' values, [VPoison] for one that failed. *)

val make : site -> Value.sink -> Value.t array -> Value.t array -> t
(** Failed from the start where the checker found the block wrong. *)

val slot : site -> string -> int
(** A field's index in its kind's fields. *)

val bad : t -> Loc.t -> string -> unit
(** Reports a mistake of the block, and marks it failed. *)

val finish : t -> bool
(** Whether the block is right. *)

val given : t -> int -> bool

val value : t -> int -> Value.t
(** A field's value, [VPoison] where it is not given. *)

val live : t -> int -> bool
(** Given, and its value did not fail. *)

val check_range : t -> entry -> int -> float -> unit

val number : ?default:float -> ?check:(Loc.t -> float -> float) -> t -> int -> float
(** A number, refused outside the field's range; [check] instead checks it otherwise. *)

val number_or : t -> int -> float -> float
(** [number_or b i default]: {!number} where the field is given, [default] where not. *)

val integer : t -> int -> int
val boolean : ?default:bool -> t -> int -> bool
val file : t -> int -> string

val point : ?default:Vec3.t -> ?check:(Loc.t -> Vec3.t -> Vec3.t) -> t -> int -> Vec3.t
(** A vector with coordinates within ±1e150; [check] checks it further. *)

val direction : t -> int -> Vec3.t
val color : ?default:Color.t -> t -> int -> Color.t

val color_or : t -> int -> Color.t -> Color.t
(** [color_or b i default]: {!color} where the field is given, [default] where not. *)

val as_vector : Value.t -> Vec3.t option
