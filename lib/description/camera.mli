(** The camera: how a point of the image becomes a primary ray (doc/reference/shading.md,
    section 1). Left-handed, pixel units from the top-left corner of the image.

    With f = normalize(look_at − position), r = normalize(up × f), u = f × r, a = W/H:
    - perspective (pinhole, the default): h = tan(fov/2), the ray through (x, y) leaves
      [position] with direction normalize(f + ((2x/W − 1)·h·a)·r + ((1 − 2y/H)·h)·u);
      [fov] is vertical, in (0, 180) degrees;
    - orthographic: every ray has direction f and starts at position + ((2x/W −
      1)·width/2)·r + ((1 − 2y/H)·width/(2a))·u ([width] in world units across the image;
      [fov] is not used);
    - fisheye (equidistant): with S = min(W, H), n_x = (2x − W)/S, n_y = (H − 2y)/S and ρ
      = √(n_x² + n_y²), a point with ρ ≤ 1 looks at θ = ρ·fov/2 from f (fov in (0, 360\]
      degrees, the angle across the inscribed circle) towards φ = atan2(n_y, n_x):
      direction cos θ·f + sin θ·(cos φ·r + sin φ·u). Points with ρ > 1 see the background
      as a ray along f that hits nothing would ({!in_view}).

    Depth of field ([aperture] A > 0): each primary ray is replaced by [lens_samples]²
    rays from points of the disk of radius A around its origin, in the (r, u) plane, all
    aimed at the point at distance [focal_distance] along it ({!lens_ray}); the renderer
    averages them.

    Motion blur ([shutter] (open, close) with close > open, in frames): the image of frame
    f at [fps] is that of the instants (f + s)/fps for s in the shutter, taken at the
    {!shutter_times}; each camera sample sees one of them (the renderer's choice). *)

type kind =
  | Perspective
  | Orthographic of { width : float  (** world units across the image, > 0 *) }
  | Fisheye

type t = private {
  kind : kind;
  position : Vec3.t;
  look_at : Vec3.t;
  up : Vec3.t;
  fov : float;  (** degrees: vertical for perspective, across the circle for fisheye *)
  aperture : float;
      (** radius of the lens disk, world units, ≥ 0; 0 = a pinhole (default) *)
  focal_distance : float;
      (** distance to the points in focus along each ray, > 0; default 1 *)
  lens_samples : int;  (** n: n×n lens points per sample, in 1–64; default 1 *)
  shutter : float * float;
      (** (open, close), in frames from the frame's time, −1 ≤ open ≤ close ≤ 1; default
          (0, 0): closed, no motion blur *)
  shutter_samples : int;
      (** how many distinct instants an open shutter is rendered at, in 1–64; default 8 *)
  f : Vec3.t;
  r : Vec3.t;
  u : Vec3.t;
  h : float;
  pinhole : bool;  (** perspective without depth of field: {!pinhole_perspective} *)
}

val make :
  ?kind:kind ->
  ?position:Vec3.t ->
  ?look_at:Vec3.t ->
  ?up:Vec3.t ->
  ?fov:float ->
  ?aperture:float ->
  ?focal_distance:float ->
  ?lens_samples:int ->
  ?shutter:float * float ->
  ?shutter_samples:int ->
  unit ->
  t
(** Defaults: perspective, position (0,0,−5), look_at origin, up (0,1,0), fov 60, no depth
    of field (aperture 0, focal distance 1, 1 lens sample), the shutter closed ((0, 0),
    {!default_shutter_samples} shutter samples when opened). *)

val kind_names : string list
(** The kinds by the names a scene gives them: ["perspective"], ["orthographic"],
    ["fisheye"]. *)

val kind_name : kind -> string
(** A kind's name among {!kind_names}. *)

val default_shutter_samples : int
(** 8: the instants an open shutter is rendered at unless told. *)

val max_shutter : float
(** 1: the shutter's open and close are within ±1 frame. *)

val default : t
(** The camera of {!make} with every default: at (0, 0, −5) looking at the origin. *)

val validate : t -> (unit, string) result
(** [Error] when look_at = position, up is parallel to the view direction, fov is outside
    (0, 180) (perspective) or (0, 360\] (fisheye), an orthographic width is not a positive
    finite number, the aperture is negative or not finite, the focal distance is not
    positive, lens_samples is outside 1–64, the shutter is not −1 ≤ open ≤ close ≤ 1 or
    shutter_samples is outside 1–{!max_shutter_samples}. *)

val with_lens_samples : t -> int -> t
(** The same camera with another number of lens samples (a quality knob). *)

val with_shutter_samples : t -> int -> t
(** The same camera with another number of shutter samples (a quality knob). *)

val max_shutter_samples : int
(** 64: the most instants an open shutter is rendered at. *)

val motion_blur : t -> bool
(** Whether the shutter is open: close > open. *)

val shutter_times : t -> float array
(** The instants an open shutter is rendered at, in frames from the frame's time: the
    middles open + (k + ½)·(close − open)/n of its n = [shutter_samples] equal parts, k =
    0 … n − 1, in order; empty when the shutter is closed. *)

val translate : Vec3.t -> t -> t
(** [translate d c] is [c] moved by [d]: the same directions (f, r, u) and lens, from
    [position + d]. *)

val kind_name : kind -> string
(** "perspective", "orthographic" or "fisheye", as written in a scene. *)

val pinhole_perspective : t -> bool
(** Whether the camera is the plain perspective pinhole (no depth of field): the renderer
    then takes its shortest path. *)

val depth_of_field : t -> bool
(** Whether [aperture > 0]. *)

val ray : t -> width:int -> height:int -> float -> float -> Ray.t
(** [ray c ~width ~height x y] is the pinhole ray through image point (x, y) for the
    camera's kind (a fisheye point outside its circle gives the ray along f). *)

val ray_into : t -> width:int -> height:int -> float -> float -> Probe.t -> unit
(** [ray_into c ~width ~height x y q] writes {!ray}'s origin and unit direction into [q],
    bit for bit, building no vector ([q]'s reciprocal direction and interval are left as
    they were). Inlined where it is called, so that [x] and [y] are not boxed. *)

val in_view : t -> width:int -> height:int -> float -> float -> bool
(** False only for a fisheye point with ρ > 1 (outside the image circle). *)

val lens_ray : t -> Ray.t -> float -> float -> Ray.t
(** [lens_ray c pinhole lx ly] is the ray from the origin of [pinhole] moved by lx·r +
    ly·u (a point of the lens disk) towards origin + focal_distance·dir. *)

val lens_point : t -> int -> int -> float -> float -> float * float
(** [lens_point c a b u1 u2] is lens point (a, b) of the n×n stratified pattern, with
    [u1], [u2] in \[0, 1) its place inside its stratum: radius A·√((a + u1)/n) and angle
    2π(b + u2)/n, as (lx, ly). *)

val lens_ray_into : t -> Probe.t -> int -> int -> float -> float -> Probe.t -> unit
(** [lens_ray_into c pin a b u1 u2 q] writes into [q] the origin and unit direction of
    [lens_ray c pinhole lx ly] for lens point [(lx, ly) = lens_point c a b u1 u2], the
    pinhole ray held in [pin], bit for bit and building nothing (inlined). *)
