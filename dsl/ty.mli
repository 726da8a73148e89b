(** The types of the language's values, as the type checker knows them before a program
    runs and as a value has them when it runs, and how messages name them.

    A static type says what an expression's value is whenever it is computed without an
    error. {!Unknown} is what the checker cannot know (a parameter, what a function
    returns, anything computed from those): its checks are left to the evaluation. *)

type t =
  | Num
  | Bool
  | Vec
  | Str
  | Mat
  | Tex of string  (** a value of a texture-like built-in: the built-in's name *)
  | Pair of t * t  (** [(t, c)]: an entry of a colour map *)
  | List of t
      (** [[a, b, …]]: its elements' type, {!Unknown} where it is not known (or the list
          is empty) *)
  | Fun of int  (** an expression function of that many parameters *)
  | Macro of int  (** a scene macro of that many parameters *)
  | Builtin of string  (** a built-in function: its name *)
  | Body
  | Unknown

val known : t -> bool
(** Whether it is not {!Unknown}. *)

val equal : t -> t -> bool

val join : t -> t -> t option
(** [join a b] is the type of a list holding values of types [a] and [b]: [None] where
    they cannot share one (a number and a string); where one is unknown, or they differ
    only in what a message does not tell apart (two functions, two textures, lists of
    unknown elements), what is common to them (often {!Unknown}). *)

val name : t -> string
(** As messages name a value of the type: ["a number"], ["a vector"], ["a colour map"], …
*)

val accepts : Schema.ty -> t -> bool
(** Whether a field of that type takes a value of this type. A value of an accepted type
    may still be refused for its value (a range, a colour with a negative component, a
    gradient's arguments): that is the evaluation's to find. *)
