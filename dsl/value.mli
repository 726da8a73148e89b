(** The values of the language as a program runs, the frames and scopes they live in, a
    run's state, and how values are printed in messages.

    Compiled code ({!Compile}) is a function of a {!frame}: the values of one activation
    (a call, or the program) and, through it, the {!state} of the run it belongs to. The
    state is the run's alone: compiled code holds none, so a program compiled once runs
    any number of times. *)

type t =
  | VNum of float
  | VBool of bool
  | VVec of Vec3.t
  | VStr of string
  | VMat of { some : Description.material option; color : Color.t }
      (** a material, as an object holds it ({!Lancer_description.Description.obj}): an
          option made once, shared by its objects and by every material that differs from
          it in its colour alone, and its own colour beside it ({!full_material} is the
          whole record) *)
  | VTex of tex
  | VPair of t * t  (** [(t, c)], an entry of a colour map *)
  | VList of t array
      (** [[a, b, …]]: never changed once made; its elements of one type *)
  | VFun of closure
  | VMacro of macro
  | VBuiltin of string  (** a built-in function, by name *)
  | VBody of string
  | VPoison  (** the value of a name whose definition failed (already reported) *)

and tex = { tname : string; targs : t list; tloc : Loc.t }
(** A texture-like built-in's call ([checker(…)], [gradient(…)], [fog(…)], …): what it
    means is read where it is used (a material's [texture] or [bump], the settings'
    [background] or [fog]). *)

and closure = {
  fname : string;
  nparams : int;
  fbody : frame -> t;
  fslots : int;
  mutable fcaps : t array;
}
(** A function made of compiled code: its parameters are the first slots of the frame a
    call makes ([fslots] in all); the values it reads from around its definition are
    copied into [fcaps] when it is defined, so a function defined in a loop's body keeps
    that iteration's values. *)

and macro = {
  mname : string;
  mnparams : int;
  mbody : frame -> scope -> unit;
  mslots : int;
  mutable mcaps : t array;
}

and frame = { l : t array; c : t array; st : state }
(** One activation: its own values by slot ([l]), those its function captured ([c]), and
    the run. *)

and scope = {
  sink : Description.obj list ref;  (** newest first *)
  emit : (Description.obj -> unit) option;
      (** the program's scope only, in a run that hands each object over as it is made
          ({!Run.record}'s [emit]): the objects go there, in order, and not into [sink] *)
  in_group : bool;  (** inside a group, CSG block or body *)
  in_csg : bool;  (** directly inside a CSG block *)
}
(** Where a statement's objects go: the program's, or a group's, CSG block's or body's
    being built. *)

and state = { hooks : hooks; count : counters; out : outputs; tell : sink }
(** A run: what it was given, what it counts against the limits, what it has said. *)

and sink = {
  report : Loc.t -> string -> unit;
  use : Description.file_use -> unit;
  share : Description.material -> Description.material option;
      (** [share m] is the option of a record the run has made that is [m] but for its
          colour ({!same_but_color}), or [Some m], kept for the ones to come ({!sharing})
      *)
}
(** Where a run's mistakes go (each once), the files it names, and the materials it has
    made. *)

and hooks = {
  time : float;
  time_v : t;
  frame_v : t;
  body_state : (string -> float -> (Vec3.t * Vec3.t) option) option;
  on_objects : (int -> unit) option;  (** told the count every 65 536 objects *)
  on_file : Description.file_use -> unit;  (** told each use of a file, as it is met *)
  cancel : Cancel.t option;  (** polled every 4096 steps *)
  address_limit : int option;
      (** the process's limit on its address space (ulimit -v), read as the run starts *)
  sources : (string, string) Hashtbl.t;  (** each file's text, for error display *)
}

and counters = {
  mutable objects : int;  (** built, members of groups included *)
  mutable steps : int;  (** loop iterations and calls *)
  mutable loops : float;  (** iterations the enclosing loops have left, multiplied *)
  mutable depth : int;  (** calls under way *)
}

and outputs = {
  mutable errors : Error.t list;  (** reversed *)
  mutable warnings : Error.t list;  (** reversed *)
  seen : (string * int * int * string, unit) Hashtbl.t;
      (** each diagnostic given, so that a loop says each once *)
  mutable settings : (Settings.t * Loc.t) option;
  mutable camera : (Camera.t * Loc.t) option;
  mutable animation : ((float * int) * Loc.t) option;
  mutable physics : (Description.physics * Loc.t) option;
  mutable lights : Light.t list;  (** reversed *)
  mutable bodies : (Description.body * Description.obj) list;  (** reversed *)
  used : (string, unit) Hashtbl.t;  (** the image and mesh files named *)
}

exception Fail of Loc.t * string
(** A mistake found as the program runs, to report where it is. *)

exception Poisoned
(** The value needed is one whose mistake was already reported: give up quietly. *)

exception Abort
(** A limit was reached (and reported): the whole evaluation stops. *)

val fail : Loc.t -> string -> 'a
(** [fail loc msg] raises {!Fail}. *)

val ty : t -> Ty.t
(** The type of a value. *)

val type_name : t -> string
(** [Ty.name (ty v)]. *)

val unbound : t
(** Physically unique: the value of a name that is not defined (a body that failed with no
    name before it). *)

val num : Loc.t -> float -> t
(** [num loc x] is [VNum x], or the error at [loc] for a NaN or an infinity. *)

val finite : Loc.t -> float -> float
val finite_vec : Loc.t -> Vec3.t -> Vec3.t
val vbool : bool -> t

val material : ?some:Description.material option -> Description.material -> t
(** [material m] is [m] as a value; [some] (default [Some m]) the option its objects hold,
    whose fields are [m]'s but the colour. *)

val colored : Description.material option -> Color.t -> t
(** [colored some c] is the material whose fields are those of [some]'s (which is [Some]),
    but its colour [c]: no record made for it. *)

val same_but_color : Description.material -> Description.material -> bool
(** [same_but_color m d]: whether [m] and [d] differ in their colour alone, numbers
    compared by their bits, textures and bump maps by identity. An object of [m] can then
    hold [d]'s option, its colour beside it ({!Lancer_description.Description.obj}). *)

val sharing : unit -> Description.material -> Description.material option
(** A run's [share] ({!type-sink}): a material record that a block made equal to one made
    before in the run but for its colour is that one's option, its colour beside it, so
    that a loop computing a field other than the colour from a few values (a shininess by
    row) makes a record per value, not per object. Past
    {!Lancer_description.Description.shared_materials} records, each new one is its own,
    so that a run whose every material differs keeps no more of them beside its objects.
*)

val full_material :
  some:Description.material option -> color:Color.t -> Description.material
(** The whole record of a {!VMat}: [some]'s, with [color] (itself where its colour is
    already [color]). *)
