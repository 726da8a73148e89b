(** Images beside a render that say what each pixel shows ([lancer render --aov]): which
    object of the scene, how far, facing where; and, for a golden test that fails, which
    objects the changed pixels lie on. All are made from {!Lancer_render.Aov.primary}: one
    ray through each pixel's centre. *)

(** An image [--aov] may ask for. *)
type kind =
  | Object  (** [OUT.object.png] and [OUT.objects.json] *)
  | Depth  (** [OUT.depth.pfm] *)
  | Normal  (** [OUT.normal.png] *)

val kinds : (string * kind) list
(** The names [--aov] takes: [object], [depth], [normal]. *)

val parse : string -> kind list
(** [parse "object,depth"]: the kinds a comma-separated list names, each once, in the
    order of {!kinds}; raises {!Lancer_job.Job_error.User} for an empty list or an unknown
    name, naming the known ones. *)

type objects
(** The objects of a scene as its description lists them (kind and place in the scene's
    text), and which of them each primitive of the compiled scene was made from. *)

val objects : Program.t -> time:float -> frame:int -> Scene.t -> objects
(** The objects of [scene], the program's scene at [time] and [frame] (its description
    made again). Raises {!Lancer_job.Job_error.User} when the description does not account
    for the scene's primitives. *)

val ids : objects -> Aov.t -> int array
(** Per pixel, row-major: 0 for the background, k for the k-th object of the scene
    (counting from 1, in program order; a CSG object or a mesh is one object). *)

val label : objects -> int -> string
(** [label objs k]: ["the background"] for 0, otherwise the kind and place of object k, as
    ["sphere at scene.rts:7"]. *)

val paths : string -> kind -> string list
(** The files a kind writes beside the image [OUT.ext]: [OUT.object.png] and
    [OUT.objects.json], [OUT.depth.pfm], [OUT.normal.png]. *)

val write : kind list -> out:string -> objects -> Aov.t -> unit
(** Write the kinds' files beside [out]: the object ids as 16-bit gray (an id over 65535
    is written as 65535) with a JSON list of every object (id, kind, file, line, column);
    the depth in each channel of a PFM (+∞ where nothing is hit); the normal n as the
    8-bit colour ⌊255·(n + 1)/2 + ½⌋ (black where nothing is hit). Raises
    {!Lancer_job.Job_error.User} when a file cannot be written. *)

val blame :
  tolerance:int ->
  objects ->
  int array ->
  int * int * Bytes.t ->
  int * int * Bytes.t ->
  string
(** [blame ~tolerance objs ids a b]: where the encoded images [a] and [b] (of the size of
    [ids]) differ by more than [tolerance] in some channel (by anything, where no pixel
    does), how many such pixels lie on each object ({!ids}): the line
    ["most changed pixels: 812 on sphere at scene.rts:7, 120 on the background"], the five
    largest counts in decreasing order (ties by id), and how many pixels the others hold.
*)

val golden_hint :
  tolerance:int ->
  Program.t ->
  time:float ->
  frame:int ->
  Scene.t ->
  golden:string ->
  int * int * Bytes.t ->
  string option
(** What a failing golden test says of its cause: {!blame} of the render [actual] against
    the golden file (read again), with the ids of {!Lancer_render.Aov.primary} of the
    scene; [None] when the golden cannot be read or has another size. *)
