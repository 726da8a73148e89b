(** Every message the type checker, the evaluator and the building of blocks give, worded
    here and nowhere else, with the "did you mean" hints. A mistake the checker can find
    before the program runs and the same mistake found as it runs (where the checker could
    not know a type) read alike because both phases take their words from here. *)

val fmt_num : float -> string
(** A number as messages write it: [3], [0.5], [1e+300]. *)

val grouped : int -> string
(** A whole number in groups of three digits: [10 000 000]. *)

(** {1 Did you mean} *)

val suggest : string -> string list -> string option
(** [suggest x candidates] is the candidate closest to [x] by edit distance, when close
    enough to be a likely typo. *)

val hint : string -> string list -> string
(** ["; did you mean `c`?"] for [suggest]'s candidate, or [""]. *)

val library_hint : string -> file:string -> string list -> string
(** [library_hint x ~file names]:
    ["; did you mean `a`, `b` or `c` (of `include "file"`)?"] for up to three of [names]
    (those a library [file] defines) close to [x] in spelling or ending in the same word
    ([royal_blue], [RoyalBlue]: [blue], [sky_blue]), or [""]. *)

(** {1 Types} *)

val cannot_combine : Ast.binop -> Ty.t -> Ty.t -> string
val needs_booleans : Ast.binop -> Ty.t -> string
val neg_needs : Ty.t -> string
val not_needs : Ty.t -> string
val condition : Ty.t -> string
val component : Ty.t -> string
val vector_component : string -> string
val body_member : string -> string
val dot_needs : string -> Ty.t -> string

val loop_bound : string -> Ty.t -> string
(** [loop_bound "start" t]: the start, end or step of a [for] loop is not a number. *)

val for_each_needs : Ty.t -> string
(** [for x in e { … }] where [e] is not a list. *)

val list_element : int -> Ty.t -> Ty.t -> string
(** [list_element i t first]: element [i] (from 1) of a list literal is of type [t], which
    its first element's type [first] cannot share. *)

val index_needs : Ty.t -> string
(** [e[i]] where [e] is not a list. *)

val index_type : Ty.t -> string
(** [l[i]] where [i] is not a number. *)

val index_whole : float -> string
(** [l[x]] where [x] is not a whole number. *)

val index_range : float -> int -> string
(** [index_range i n]: [l[i]] out of a list of [n] elements. *)

val interval_order : string -> float -> float -> string
(** [interval_order name a b]: a pair field's first number above its second. *)

val field_type : Schema.field -> Ty.t -> string
(** A field given a value of a type it does not take:
    ["`radius` must be a number, got a vector"]. *)

(** {1 Names and calls} *)

val unknown_name : string -> string -> string
(** [unknown_name x hint]: a name that is not defined; [hint] as {!hint} gives it. *)

val unknown_name_later : string -> Loc.t -> string
(** A name used above its definition at that place. *)

val macro_in_expression : string -> string
val not_a_function : string -> Ty.t -> string
val function_as_statement : string -> string
val builtin_as_statement : string -> string
val not_a_macro : string -> Ty.t -> string

val arity : string -> int -> int -> string
(** [arity f expected got]. *)

val param_twice : string -> string

(** {1 Built-in functions} *)

val argument : int -> string -> string -> Ty.t -> string
(** [argument i f what got]: ["argument 2 of `f` must be <what>, got <got>"]. *)

val at_least_two : string -> int -> string
val marble_arity : string -> int -> string
val noise_arity : int -> string
val color_map_empty : string
val domain : string -> string -> float -> string
val clamp : float -> float -> string
val mix : Ty.t -> Ty.t -> string
val normalize_zero : string
val gradient_argument : Ty.t -> string
val color_map_t : int -> float -> string
val color_map_order : int -> float -> float -> string
val color_map_negative : int -> string
val color_map_entry_types : int -> Ty.t -> Ty.t -> string
val color_map_entry : int -> Ty.t -> string
val fog_distance : float -> string

(** {1 Numbers and operators} *)

val nan : string
val overflow : string
val division_by_zero : string
val modulo_by_zero : string
val not_real : float -> float -> string

(** {1 Blocks and fields} *)

val given_twice : string -> string -> int -> string
(** [given_twice field block first_line]. *)

val holds_only_fields : ?inner:string -> string -> string
(** [holds_only_fields ?inner block]: a [block] holding a statement, [inner] the keyword
    of the block written inside it (POV-Ray's [pigment { … }] gets its hint). *)

val unknown_field : string -> string -> string -> string
(** [unknown_field field block hint]. *)

val needs_field : string -> string -> string
(** [needs_field block field]: a required field is missing. *)

val out_of_range : Schema.field -> float -> string
(** A number outside the field's range:
    ["`radius` must be a length in [1e-150, 1e150], got -1"]. *)

val top_level_only : string -> string
val material_statement : string
val unknown_block : string -> string

val once : string -> Loc.t -> string
(** [once "settings" first]: a block that may be given once is given again. *)

val coordinates : string -> string
val non_zero : string -> string
val negative_colour : string -> Vec3.t -> string
val scale_factors : string
val light_choice_both : string
val light_choice_none : string
val spot_only : string -> string
val attenuation : string
val zero_direction : string
val not_parallel : string
val not_in_line : string
val box_order : string
val cylinder_ends : string
val cone_ends : string
val cone_radii : string
val height_field_size : string

val invalid : string -> string -> string
(** [invalid "settings" why]. *)

(** {1 Settings, camera, animation, physics} *)

val gamma : Schema.range -> string
val background_gradient : string
val fog_colour : string
val camera_kind : string -> string list -> string
val fisheye_fov : string -> float -> string
val orthographic_fov : string

val fov : string -> float -> bool -> string
(** [fov must x wider]: [wider] adds that a fisheye would take it. *)

val width_not_orthographic : string
val orthographic_width : string
val aperture_focal : string
val fps_low : float -> float -> string
val fps_high : float -> string
val frames_or_duration : string
val too_many_frames : int -> string
val physics_method : string -> string list -> string

(** {1 Materials and textures} *)

val reflection_transparency : float -> float -> string
val texture_size : string -> string -> float -> string
val mapped_arguments : string -> string
val marble_arguments : string -> string
val noise_texture : string
val gradient_axis : string
val gradient_texture : string
val color_map_texture : string
val image_scale : float -> string
val image_needs_scale : string
val image_arguments : string
val image_file : string
val not_a_texture : string -> string
val noise_bump_scale : float -> string
val noise_bump_amount : string
val noise_bump_arguments : string
val image_bump_arguments : string
val not_a_bump : string -> string

(** {1 Groups, CSG, bodies} *)

val csg_empty : string -> string
val difference_needs_two : string
val height_field_not_solid : string -> string -> string

val not_solid : string -> string -> string
(** [not_solid member_kind block]. *)

val body_in_group : string
val body_twice : string -> string
val body_scaled : string -> float -> float -> float -> string
val body_one_sphere : string

(** {1 Limits} *)

val steps_limit : int -> string
val depth_limit : int -> string
val objects_limit : int -> string
val memory : objects:int -> limit:int -> baseline:int -> per_object:int -> string

val loop_runs :
  count:float -> loops:float -> total:float -> steps:int -> objects:int -> string

val loop_builds :
  total:float ->
  each:float ->
  count:float ->
  loops:float ->
  built:int ->
  objects:int ->
  string

val loop_zero : float -> float -> float -> string
val loop_step_zero : string
