(** Light sources: point lights (spherical area lights with a radius), spot lights and
    directional lights. *)

type spot = {
  point_at : Vec3.t;  (** the point the spot is aimed at *)
  axis : Vec3.t;  (** unit vector from the light's position towards [point_at] *)
  inner : float;  (** degrees: full light within this angle of the axis *)
  outer : float;  (** degrees: no light beyond this angle; inner ≤ outer ≤ 180 *)
  cos_inner : float;
  cos_outer : float;
}
(** A spot light's cone. With θ the angle between the axis and the direction from the
    light to a lit point, the light's E is multiplied by 1 where θ ≤ inner, 0 where θ ≥
    outer, and in between by s(t) = t²(3 − 2t), t = (cos θ − cos outer)/(cos inner − cos
    outer). *)

type t =
  | Point of {
      position : Vec3.t;
      color : Color.t;
      intensity : float;
      attenuation : Vec3.t;  (** (a0, a1, a2): att = 1/(a0 + a1·d + a2·d²) *)
      radius : float;  (** > 0 makes a spherical area light (soft shadows) *)
      samples : int;  (** samples × samples shadow rays when [radius > 0] *)
      spot : spot option;  (** [Some] makes it a spot light; default none *)
    }
  | Directional of { direction : Vec3.t; color : Color.t; intensity : float }
      (** [direction] is unit, the way the light travels; Ldir = −direction *)

(** {1 Defaults}

    What a light has when a scene does not say: the scene language's defaults are these
    values. *)

val default_color : Color.t
(** White. *)

val default_intensity : float
(** 1. *)

val default_attenuation : Vec3.t
(** (1, 0, 0): no fall-off with distance. *)

val default_radius : float
(** 0: a point, not an area light. *)

val default_samples : int
(** 1 (an area light's n×n shadow rays). *)

val default_inner : float
(** 30 degrees: a spot light's full-light cone. *)

val default_outer : float
(** 45 degrees: beyond it a spot light gives nothing. *)

(** {1 Lights} *)

val point :
  ?color:Color.t ->
  ?intensity:float ->
  ?attenuation:Vec3.t ->
  ?radius:float ->
  ?samples:int ->
  ?spot:spot ->
  Vec3.t ->
  t
(** Defaults: those above, and no spot. *)

val spot :
  position:Vec3.t ->
  point_at:Vec3.t ->
  inner:float ->
  outer:float ->
  (spot, string) result
(** The cone of a spot light at [position] aimed at [point_at], angles in degrees; [Error]
    when [point_at] is the position, or unless 0 ≤ inner ≤ outer ≤ 180. *)

val spot_factor : spot -> float -> float
(** [spot_factor s cos_theta] is the factor of E at angle θ from the axis (see
    {!type-spot}). *)

val is_spot : t -> bool
(** Whether the light is a spot light. *)

val directional : ?color:Color.t -> ?intensity:float -> Vec3.t -> t
(** [directional d] travels along [normalize d]. *)

val is_area : t -> bool
(** Whether the light is a point light with a radius and more than one sample: an area
    light casting soft shadows. *)

val translate : Vec3.t -> t -> t
(** [translate d l] is [l] moved by [d] (a directional light has no position to move). *)
