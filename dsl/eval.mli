(** The evaluator: runs a loaded program (includes already resolved) at one instant and
    builds everything a {!Lancer.Scene.t} needs, or the located errors of the program.

    Errors are collected, not thrown: a statement that fails is reported and skipped (a
    [let] that fails binds its name to a poisoned value, so that later uses do not report
    the same mistake again), and evaluation goes on with the next statement. Only the
    resource limits stop the whole evaluation. Limits: {!max_objects} objects,
    {!max_steps} loop iterations and calls in all, call depth {!max_depth}. Under a limit
    on the address space (ulimit -v) a scene whose objects would need more than it
    ({!bytes_per_object} each) is refused with a located error: at the loop that would
    build them, when its body builds them directly, or else at the object that crosses the
    limit. *)

open Lancer

val max_objects : int
(** 10 000 000 objects built (members of groups included). *)

val max_steps : int
(** 20 000 000 loop iterations and function or macro calls. *)

val max_depth : int
(** 1000 nested function or macro calls. *)

val bytes_per_object : int
(** 2560: the address space one object is counted as needing (measured: 2.3 KB a sphere at
    the peak of building and rendering 200 000). *)

type physics_method = Exact | Verlet | Euler

type physics = {
  gravity : Vec3.t;  (** m/s²; default (0, −9.81, 0) *)
  method_ : physics_method;  (** default [Exact] *)
  step : float;  (** seconds, for the fixed-step methods; default 1/240 *)
}

val default_physics : physics
(** Gravity (0, −9.81, 0), the exact method, step 1/240 s. *)

type body = {
  name : string;
  center : Vec3.t;  (** initial world-space centre *)
  radius : float;  (** world-space radius (the sphere's radius times the largest scale) *)
  material : Material.t;
  velocity : Vec3.t;  (** initial velocity, m/s; default 0 *)
  mass : float;  (** kg, > 0; default 1 *)
  restitution : float;  (** in [0, 1]; default 0.9 *)
  loc : Loc.t;  (** where the body is defined *)
}

type obj = {
  kind : string;  (** "sphere", "plane", … *)
  fields : (string * Yojson.Safe.t) list Lazy.t;
      (** the object's fields, in object space; built when asked for *)
  transforms : Yojson.Safe.t list;  (** the transforms applied, in order (group's last) *)
  material_json : Yojson.Safe.t Lazy.t;  (** built only when asked for *)
  prims : Primitive.t list;  (** one, or the triangles of a mesh *)
  body : string option;  (** the body this sphere is, if any *)
  loc : Loc.t;  (** where the object's block starts *)
}

type output = {
  settings : Settings.t;
  camera : Camera.t;
  lights : Light.t list;
  objects : obj list;  (** static objects in program order, then one sphere per body *)
  animation : (float * int) option;  (** fps, frames *)
  physics : physics option;
  physics_loc : Loc.t option;  (** where the [physics] block is *)
  warnings : Error.t list;
      (** what is legal but likely a mistake (a loop that runs zero times), in source
          order *)
  bodies : body list;  (** in program order *)
  files : string list;
      (** the image and mesh files this evaluation used, sorted (cached ones too) *)
}

type images
(** A cache of the image files read by [image(…)] textures and bump maps and of the OBJ
    files read by [mesh], shared between frames. *)

val new_images : unit -> images
(** An empty cache. *)

val image_files : images -> string list
(** The paths of the images and meshes read so far, sorted. *)

val run :
  ?body_state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  ?on_objects:(int -> unit) ->
  ?cancel:Cancel.t ->
  ?objects:bool ->
  sources:(string, string) Hashtbl.t ->
  images:images ->
  time:float ->
  frame:int ->
  Ast.stmt list ->
  (output, Error.t list) result
(** [run ~sources ~images ~time ~frame prog] evaluates [prog] with [time] and [frame]
    bound. [sources] maps each file name to its text (for error display).
    [body_state name t] is (position, velocity) of body [name] at time [t]; without it (or
    when it answers [None]) a body stays at its initial centre with its initial velocity.
    With [~objects:false] (a check only) [objects] is left empty. [on_objects n] is called
    every 65 536 objects built, with their count (for progress during a long build).
    [cancel] is polled every 4096 loop iterations and calls: once it is cancelled, [run]
    raises [Sys.Break]. *)

val suggest : string -> string list -> string option
(** [suggest x candidates] is the candidate closest to [x] by edit distance, when close
    enough to be a likely typo. *)

val sort_errors : Error.t list -> Error.t list
(** Errors in source order: files in the order they first appear in the list, then by line
    and column (stable). *)
