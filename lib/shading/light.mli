(** Light sources: point, spherical area and directional lights. *)

type t =
  | Point of {
      position : Vec3.t;
      color : Color.t;
      intensity : float;
      attenuation : Vec3.t;  (** (a0, a1, a2): att = 1/(a0 + a1·d + a2·d²) *)
      radius : float;  (** > 0 makes a spherical area light (soft shadows) *)
      samples : int;  (** samples × samples shadow rays when [radius > 0] *)
    }
  | Directional of { direction : Vec3.t; color : Color.t; intensity : float }
      (** [direction] is unit, the way the light travels; Ldir = −direction *)

val point :
  ?color:Color.t -> ?intensity:float -> ?attenuation:Vec3.t -> ?radius:float -> ?samples:int ->
  Vec3.t -> t
(** Defaults: white, intensity 1, attenuation (1, 0, 0), radius 0, 1 sample. *)

val directional : ?color:Color.t -> ?intensity:float -> Vec3.t -> t
(** [directional d] travels along [normalize d]. *)

val is_area : t -> bool
(** Whether the light is a point light with a radius and more than one sample: an area light
    casting soft shadows. *)
