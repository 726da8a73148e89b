(** Random spheres against the sphere count, the domain count and the image size: build
    and render times, rays per second, minor words per ray, peak memory, each
    configuration in a child process of this executable so that its peak memory is its
    own. *)

val sphere_field : int -> Lancer.Primitive.t list * Lancer.Camera.t * Lancer.Light.t list
(** [sphere_field n]: [n] random spheres from a fixed seed, uniform in a cube of side
    n^(1/3), radii in [0.1, 0.4], the camera outside the cube and one point light. *)

val run :
  repeat:int ->
  counts:int list ->
  width:int ->
  height:int ->
  domains:int ->
  domain_counts:int list ->
  sizes:string list ->
  base_count:int ->
  sweeps:string list ->
  in_process:bool ->
  row:string option ->
  json:bool ->
  unit
(** The sweeps named ([counts], [domains], [sizes]), printed as they are measured, or
    JSON; with [row] ("COUNT,WxH,DOMAINS") one configuration measured in this process and
    printed as one line of JSON (what the sweeps' child processes run). Raises
    {!Lancer.Job_error.User}. *)
