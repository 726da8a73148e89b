(** What [lancer check] prints about a scene: a summary in a few lines, or the whole
    description as JSON ([--json]).

    Both print a {!Lancer_description.Description.t} beside what the renderer made of it
    ({!Lancer_description.Description.rendered}): the settings as rendered (command-line
    overrides show), the lights, the objects by kind as built, the features the renderer
    uses. The description's [animation], [bodies], [physics] and [warnings] are printed as
    they are: pass those of the program (at time 0) for a scene at another time. *)

val warnings :
  empty:bool -> objects:int -> lights:int -> Description.t -> Diagnostic.t list
(** What is legal but likely a mistake: an empty program ([empty]), a scene without
    objects or without lights (it has [objects] and [lights], as rendered), and the
    description's own warnings (a loop that runs zero times, colours given as 0–255). *)

val colour_warnings :
  ?source:(string -> string option) -> Description.t -> Diagnostic.t list
(** Colours that look given as 0–255 rather than 0–1: a warning for each distinct surface
    colour (an object's, or its texture's and colour map's) whose largest component m is
    above 1 while no light of the scene makes up for it, that is when every light has
    intensity × (its colour's largest component) × m above 1 (and always when there is no
    light). It is located at the first object with that colour ([source file] is the text
    of a file, for the source line), suggests the colour divided by 255 and counts the
    other objects that have it. Backgrounds, fog, ambient light and lights themselves may
    be brighter than 1 and are not looked at. *)

type colours
(** The surface colours above 1 of objects noted one by one, for {!colour_warnings_of}:
    what {!colour_warnings} reads of a description's objects, gathered as they are made.
*)

val colours : unit -> colours
(** Nothing noted yet. *)

val note_object : colours -> Description.obj -> unit
(** [note_object acc o]: the surface colours of [o] (and of its CSG members), after those
    of the objects noted before. *)

val colour_warnings_of :
  ?source:(string -> string option) -> colours -> Light.t list -> Diagnostic.t list
(** {!colour_warnings} of a description whose objects are those noted, in order, and whose
    lights are these. *)

val summary : empty:bool -> Description.t -> Description.rendered -> string
(** Image size, sampling (jitter, adaptive), camera, frames, objects by kind, CSG trees,
    lights, distinct materials, bodies, and which {!Features} the renderer uses and skips;
    then the {!warnings}. *)

val json :
  ?state:(string -> float -> (Vec3.t * Vec3.t) option) ->
  Description.t ->
  Description.rendered ->
  Yojson.Safe.t
(** The scene at its time: settings, camera, lights, every object with its kind, fields
    (object space, as written), transforms and material, bodies (with, from
    [state name time], their position and velocity at that time; without it, their initial
    ones), physics, animation and features. *)
