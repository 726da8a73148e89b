(** The fields of every block of the language, as data: for each block kind, each field's
    name, the type of value it takes, the range a number must lie in, its default (or that
    it is required), whether it may be given more than once, when it applies and one line
    of documentation.

    The type checker ({!Check}) takes from here the fields each block allows and their
    types, the building of blocks ({!Build}) each field's default and its range (and how
    its messages word the range), and the field tables of the language reference
    (doc/reference/language.md) are generated from it. *)

(** The value a field takes. *)
type ty =
  | Number
  | Integer  (** a number that is a whole number *)
  | Boolean
  | File  (** a string naming a file, relative to the scene file *)
  | Choice of string list  (** a string, one of these *)
  | Vector  (** (x, y, z), coordinates within ±1e150 *)
  | Direction  (** a non-zero vector *)
  | Colour  (** a vector with no negative component *)
  | Material  (** an object's [material { … }] *)
  | Base_material  (** the material a [material { base: … }] copies *)
  | Texture  (** a texture value ([checker(…)], …) or a colour *)
  | Bump  (** [noise(scale, amount)] or [image("file.png", amount)] *)
  | Scale  (** a number (uniform) or a vector *)
  | Background  (** a colour or [gradient(HORIZON, ZENITH)] *)
  | Fog  (** [fog(COLOR, DISTANCE)] *)
  | Gamma  (** ["srgb"] or a number (in the field's range) *)
  | Interval  (** [(a, b)]: two numbers in the field's range, a ≤ b *)

type bound = Incl of float | Excl of float | Unbounded

type range =
  | Any
  | Real of bound * bound  (** a number between the two bounds *)
  | Whole of int * int  (** a whole number in [[lo, hi]] *)

type default =
  | Required
  | Value of string
      (** the default, as it would be written in a scene: a literal (a number, [-x], a
          fraction [a/b], a vector of those, a string, [true] or [false]); the evaluator
          uses it as if it were written *)
  | Absent of string  (** no value: what leaving the field out means *)

(** When a field applies. *)
type condition =
  | Always
  | Kind_in of string list  (** when the block's [kind] field is one of these *)
  | With of string  (** when this other field is given too *)
  | Without of string  (** when this other field is not given *)

type field = {
  name : string;
  ty : ty;
  range : range;
  default : default;
  repeats : bool;  (** may be given more than once, applied in order *)
  condition : condition;
  noun : string;
      (** what an error message calls a number of the field's range (["a length"],
          ["an angle"]); [""] for none. A whole number is ["a whole number"] whatever this
          says, and a field whose range is that of a length is ["a length"] unless told
          otherwise. *)
  unit : string;
      (** what the number counts, after its range in a message (["degrees"]) *)
  doc : string;
}

type block = {
  id : string;  (** unique: the keyword, or [point_light], [directional_light] *)
  keyword : string;  (** the word that starts it: [sphere], [light], [body], … *)
  chosen_by : string option;
      (** for kinds sharing a keyword: the field whose presence selects this one (a
          [light] with a [position] is a point light, with a [direction] a directional
          one) *)
  holds_objects : bool;  (** group, CSG and body blocks hold object statements *)
  doc : string;  (** one line, possibly empty *)
  fields : field list;
      (** in the order the reference lists them (and the order "did you mean" prefers); a
          field may appear twice with different conditions (the camera's [fov]) *)
}

val blocks : block list
(** Every block kind: settings, camera, the two lights, animation, physics, material, the
    shapes, group, the CSG blocks, body. *)

val find : string -> block option
(** [find id] is the block of that id. *)

val for_keyword : string -> block list
(** The blocks started by a keyword: one, or the two lights for [light]. *)

val choose : keyword:string -> (string -> bool) -> block option
(** [choose ~keyword present] is the block a [keyword { … }] whose fields are those for
    which [present] holds is: the only one, or the one chosen by the field present; [None]
    when the keyword is unknown or the fields do not choose exactly one. *)

val names_of : block -> string list
(** The names of a block's fields, in order, each once. *)

val field_names : string -> string list
(** [field_names id] is [names_of] the block [id] ([[]] for an unknown id). *)

val fields_named : block -> string -> field list
(** The entries of a block for one field name (usually one; none when unknown). *)

val shapes : string list
(** The shape keywords, in the reference's order. *)

val csg : string list
(** [union], [merge], [intersection], [difference]. *)

val is_shape : string -> bool

val keywords : string list
(** Every keyword that starts a block statement, in the order "did you mean" prefers (not
    [material], a value, nor [body], which names itself). *)

val repeatable : string list
(** The names of the fields that may repeat ([rotate], [scale], [translate]). *)

val in_range : range -> float -> bool

val range_text : range -> string
(** [[0, 1]], [(0, 1e150\]], [within ±1e150]; [""] for [Any]. *)

val type_text : ty -> string
(** The type as the reference names it: [number], [vector (x, y, z)], … *)

val big : float
(** 1e150: no number of a scene is larger in magnitude (vector coordinates included). *)

val non_negative : range
(** [[0, 1e150]]. *)

val length : range
(** [[1e-150, 1e150]]: a length, or a scale factor's magnitude. *)

val coordinate : range
(** [±1e150]: a coordinate of a vector. *)

val must : field -> string
(** What an error message says of a number out of the field's range:
    [must be a length in [1e-150, 1e150]], [must be a whole number in [1, 64]],
    [must be an angle in [0, 180] degrees], [must be within ±1e150], and
    [must be greater than 0] for a positive number with no limit of its own. *)

val value_text : field -> string
(** Type and range in one: [number in [1e-150, 1e150]]. *)

val condition_text : condition -> string
(** [with `point_at`], [with `kind`: "orthographic"]; [""] for [Always]. *)

val quoted : string list -> string
(** ["a", "b" or "c"]. *)
