(** An immutable, fully evaluated scene at one instant: what the renderer sees.

    Built by {!make}, which validates every part, builds the acceleration structure and
    derives {!Lancer_description.Features.t}. The scene language ([dsl/]) produces one per
    frame time. *)

type t = private {
  settings : Settings.t;
  camera : Camera.t;
  lights : Light.t array;
  objects : Primitive.t array;  (** in render coordinates: moved by −[origin] *)
  accel : Accel.t;
  features : Features.t;
  time : float;  (** seconds *)
  frame : int;
  origin : Vec3.t;
      (** the world point that renders at the origin: the camera's position rounded to a
          multiple of G in each coordinate, G the power of two at least 1024 times the
          camera's distance to its look_at point (zero for a camera within G/2 of the
          world's origin) *)
  view : Camera.t;  (** [camera] in render coordinates *)
  view_lights : Light.t array;  (** [lights] in render coordinates *)
  moments : t array;
      (** with the camera's shutter open ({!Lancer_description.Camera.motion_blur}): the
          scenes at its {!Lancer_description.Camera.shutter_times}, in order, which the
          renderer's samples see instead of this one (each with no moments of its own);
          empty otherwise *)
}
(** [camera] and [lights] are as the scene gave them; the renderer traces in coordinates
    centred near the camera ([view], [view_lights], [objects]), so that a scene far from
    the world's origin renders as it would at the origin. *)

val make :
  ?checked:bool ->
  ?settings:Settings.t ->
  ?camera:Camera.t ->
  ?time:float ->
  ?frame:int ->
  lights:Light.t list ->
  Primitive.t list ->
  (t, string) result
(** [make ~lights objects] validates settings, camera and materials
    ({!Lancer_description.Description.validate_material}) and builds the scene. With
    [~checked:true] the materials are not checked: they are a description's, which its
    language checked (the scenes {!Compile} makes). *)

val of_array :
  ?checked:bool ->
  ?settings:Settings.t ->
  ?camera:Camera.t ->
  ?time:float ->
  ?frame:int ->
  lights:Light.t list ->
  Primitive.t array ->
  (t, string) result
(** {!make} of an array of objects, which the scene keeps (the caller must not change it).
*)

val mover : Camera.t -> Primitive.t -> Primitive.t
(** What {!of_array} does to each object before it builds the scene seen through this
    camera: moves it by −[origin_of camera] ({!Primitive.translate}), or when that is zero
    only {!Lancer_render.Primitive.baked} (a shape that its transform only moves becomes
    that shape moved). A primitive's move made by one [mover] shares the vectors that are
    the same for all of them. *)

val of_moved :
  ?index:bool ->
  ?checked:bool ->
  ?settings:Settings.t ->
  ?camera:Camera.t ->
  ?time:float ->
  ?frame:int ->
  lights:Light.t list ->
  Primitive.t array ->
  (t, string) result
(** {!of_array} of objects already moved by [mover camera] (each one as it was made, so
    that a large scene never holds both copies): the same scene. With [~index:false] its
    queries scan every object ({!Lancer_render.Accel.unindexed}): the same answers and
    features, without the time and memory of the hierarchy, for a caller that reads the
    scene but traces few rays or none. *)

val origin_of : Camera.t -> Vec3.t
(** The [origin] of a scene seen through this camera. *)

(** {1 A part built once for many frames} *)

type fixed
(** Primitives that do not change between the frames of an animation, moved into the
    render coordinates of one origin, with their acceleration structure. *)

val fixed : key:int array -> origin:Vec3.t -> Primitive.t array -> fixed
(** [fixed ~key ~origin prims] moves [prims] (in world coordinates) by −[origin] and
    builds their structure. [key] names what they are: the scenes made with it have it as
    their structure's {!Accel.fixed_key}. *)

val fixed_origin : fixed -> Vec3.t

type piece =
  | Fixed of int * int
      (** [Fixed (first, n)]: the fixed part's primitives first … first+n−1 *)
  | Moving of Primitive.t list  (** primitives of this frame, in world coordinates *)

val make_layered :
  ?checked:bool ->
  ?settings:Settings.t ->
  ?camera:Camera.t ->
  ?time:float ->
  ?frame:int ->
  lights:Light.t list ->
  fixed:fixed ->
  piece list ->
  (t, string) result
(** [make_layered ~lights ~fixed pieces] is {!make} of the primitives the pieces list, in
    order; every primitive of [fixed] must be among them once, in its order. The same
    scene as {!make} gives, object for object and answer for answer, but for the work: the
    fixed part's structure is reused ({!Lancer_render.Accel.layered}) and only the moving
    primitives' is built; with a transparent material anywhere, one structure is built
    over them all, as {!make} does. [fixed] must be for [origin_of camera]. *)

val make_exn :
  ?settings:Settings.t ->
  ?camera:Camera.t ->
  ?time:float ->
  ?frame:int ->
  lights:Light.t list ->
  Primitive.t list ->
  t
(** As {!make}; raises [Invalid_argument] on an invalid scene (for tests and code-built
    scenes). *)

val with_settings : t -> Settings.t -> (t, string) result
(** The same scene with other settings (command-line overrides), features re-derived; its
    {!moments} are left as they are (each is a scene to change in its own right). *)

val with_camera : t -> Camera.t -> (t, string) result
(** The same scene seen through another camera (quality knobs), features re-derived; its
    {!moments} are left as they are. *)

val map_lights : t -> (Light.t -> Light.t) -> t
(** The same scene with each light replaced (quality presets change area-light samples),
    features re-derived; its {!moments}' lights too. *)

val map_settings : t -> (Settings.t -> Settings.t) -> (t, string) result
(** [map_settings sc f]: {!with_settings} of [f] of its settings, for the scene and each
    of its {!moments} (whose settings may be their own, a background that changes with
    time). *)

val map_camera : t -> (Camera.t -> Camera.t) -> (t, string) result
(** [map_camera sc f]: {!with_camera} of [f] of its camera, for the scene and each of its
    {!moments}. *)

val with_moments : t -> t array -> (t, string) result
(** [with_moments sc ms] is [sc] rendered as the scenes [ms] at its camera's
    {!Lancer_description.Camera.shutter_times} ({!moments}): one for each, of [sc]'s image
    size; none for a closed shutter. *)

val object_count : t -> int
(** How many objects the scene has, a mesh counting as its faces: what [lancer check] and
    the statistics report. *)
