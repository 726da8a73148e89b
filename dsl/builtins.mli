(** The one table of built-in names: each function's (and [pi]'s, [time]'s and [frame]'s)
    signature, implementation and line of documentation. The type checker takes the
    signatures from here, the compiled code the implementations, "did you mean" the names,
    and the language reference (doc/reference/language.md) its list of built-ins. *)

(** What an argument must be. *)
type arg =
  | Of of (Ty.t -> bool) * string
      (** a value of a type this accepts; the string says what, after "must be" *)
  | Any  (** read where the value is used (a texture's colours, say) *)
  | Entry  (** an entry [(t, colour)] of a colour map *)

(** How many arguments a function takes, and the message when a call gives another count
    (given that count). *)
type arity =
  | Exactly of int
  | At_least of int * (int -> string)
  | Among of int list * (int -> string)

(** What a call computes, from arguments whose types were checked. *)
type impl =
  | F1 of (float -> float)  (** a number of a number; a NaN or an infinity is refused *)
  | Partial of (float -> bool) * string * (float -> float)
      (** defined where the predicate holds: the string says where, after "needs" *)
  | F2 of (float -> float -> float)
  | Code of (Loc.t -> (Value.t * Loc.t) array -> Value.t)
      (** the call's place and the arguments with theirs; raises {!Value.Fail} *)

type fn = {
  arity : arity;
  arg : int -> arg;  (** what argument [i] (from 0) must be *)
  result : Ty.t list -> (Ty.t, string) result;
      (** the result's type for arguments of these types, each known and accepted; or the
          message (at the call) for a combination the function does not take *)
  impl : impl;
}

(** A built-in name. *)
type kind =
  | Number of (Value.hooks -> Value.t)
      (** a number: [pi], or the run's [time], [frame] *)
  | Function of fn

type t = { name : string; usage : string; doc : string; kind : kind }
(** [usage] is how the reference writes it ([atan2(y, x)]), [doc] its line there. *)

val all : t list
(** In the reference's order. *)

val find : string -> t option
val names : string list

val check : t -> fn -> Loc.t -> (Ty.t * Loc.t) list -> (Ty.t, Loc.t * string) result
(** [check b f loc args]: a call of [b] at [loc] with arguments of these types (known or
    not), each with its place. [Error] for the first mistake found among the known types
    (the count, then each argument in order, then their combination), with its place;
    otherwise the result's type, {!Ty.Unknown} unless every argument's type is known. The
    checker calls it with the types it knows, a call of a built-in it could not check with
    the types of the values: the same mistakes, the same messages. *)

val call : t -> fn -> Loc.t -> (Value.t * Loc.t) array -> Value.t
(** Its implementation, for arguments whose types are right. *)
