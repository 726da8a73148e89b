(** Blocks to the scene description: what a block's field values (of the types the checker
    or the compiled code made sure of) state — a shape, a material, a light, the settings,
    … — or the mistakes only values show (a number out of its range, a colour with a
    negative component, a box whose corners are the wrong way round). Pure: it reads no
    file and keeps nothing; what it finds, and each file a block names (as it is met, also
    where the block fails), goes to the {!Lancer_dsl.Value.type-sink} it is given.

    Each block is read from its fields ({!Fields}). Mistakes the checker reported are not
    reported again: a block it found wrong is read for the others, and not built. *)

module D = Description

(** {1 Objects} *)

val object_ : Fields.site -> Fields.t -> D.obj
(** [object_ site] reads a shape block of that site: its object (transforms and material
    included), each time; only where the block is right ({!Lancer_dsl.Fields.finish}, once
    read) is it the block's object. *)

val transforms : Fields.t -> Transform.t * D.step list

val object_material : Fields.t -> D.material option * Color.t
(** A block's [material] as an object holds it ({!D.obj}): the option, shared by the
    materials that differ from it in their colour alone, and the colour. *)

val group_members :
  Transform.t ->
  D.step list ->
  D.material option * Color.t ->
  D.obj list ->
  D.obj list ->
  D.obj list
(** [group_members t steps (material, colour) members onto]: a group's members (newest
    first, as a scope holds them), each with the group's transform after its own and its
    material and colour unless it has a material, in front of [onto]. *)

val csg :
  Fields.t -> keyword:string -> loc:Loc.t -> in_csg:bool -> D.obj list -> D.obj option
(** A CSG block's object ([keyword] as written: ["group"] for a group inside a CSG block),
    its members in order; [in_csg]: itself a member of one. *)

val body :
  Fields.t ->
  name:string ->
  loc:Loc.t ->
  at:Loc.t ->
  D.obj list ->
  (D.body * D.obj, Loc.t * string) result option
(** A body's record and its sphere, from its block and its members (which must be one
    sphere); [loc] is the body's statement, [at] its name. [None] when a field failed;
    [Some (Error _)] for a mistake of the members, at [at]. *)

(** {1 Materials} *)

val material : Fields.site -> Fields.t -> Value.t
(** [material site] reads a material block of that site: its material (a [VMat]), each
    time; only where the block is right ({!Lancer_dsl.Fields.finish}, once read) is it the
    block's material. One that differs from its base (or, without one, from the defaults)
    in its colour alone holds the base's option ({!Lancer_dsl.Value.t}'s [VMat]), so that
    the objects of a loop that colours each one share a material. *)

(** {1 Settings, camera, lights, animation, physics} *)

val settings : Fields.t -> Settings.t option
val camera : Fields.t -> Camera.t option
val light : Fields.t -> Light.t option
val animation : Fields.t -> (float * int) option
val physics : Fields.t -> D.physics option
