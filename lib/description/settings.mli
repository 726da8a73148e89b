(** Render settings (the [settings] block of a scene), with their defaults. *)

type gamma = Lancer_image.Image.gamma =
  | Srgb
  | Power of float  (** The output encoding ({!Lancer_image.Image.gamma}). *)

type sky = { horizon : Color.t; zenith : Color.t }
(** A background gradient: a ray leaving the scene along unit direction D sees
    mix(horizon, zenith, max(0, D.y)), i.e. horizon + max(0, D.y)·(zenith − horizon). *)

type fog = { color : Color.t; distance : float }
(** Fog: a ray segment of length t (infinite for a ray that hits nothing) turns its colour
    c into c·e^(−t/distance) + color·(1 − e^(−t/distance)); [distance] > 0, world units.
    Primary and secondary rays are fogged, shadow rays are not. *)

type t = {
  width : int;  (** pixels, ≥ 1; default 640 *)
  height : int;  (** pixels, ≥ 1; default 480 *)
  depth : int;  (** maximum ray depth, ≥ 1 (primary rays have depth 1); default 5 *)
  samples : int;  (** n: n×n samples per pixel, ≥ 1; default 1 *)
  jitter : bool;  (** move each sample inside its sub-cell by a hash; default false *)
  adaptive : float;  (** adaptive supersampling threshold; 0 = off (default) *)
  shadows : bool;  (** default true *)
  background : Color.t;
      (** linear colour of rays that hit nothing; default black. With [sky] it is the
          horizon colour (what stands for the background where one colour is needed, e.g.
          in place of a NaN sample) *)
  sky : sky option;
      (** a background gradient instead of the flat [background]; default none *)
  fog : fog option;  (** default none *)
  ambient : Color.t;
      (** scene ambient light, multiplies material ambient; default white *)
  gamma : gamma;  (** output encoding; default sRGB *)
}

val default : t
(** The settings with every default, as listed with the fields above. *)

val max_pixels : int
(** {!Lancer_image.Image.max_pixels}: the largest image accepted. *)

val max_depth : int
(** 1000: the largest ray depth (each bounce is a nested call). *)

val validate : t -> (unit, string) result
(** [Error] naming the field when a setting is out of range: size below 1×1 or above
    {!max_pixels}, depth below 1, samples outside 1–64, adaptive negative or not finite,
    or a gamma that is not a positive number, a fog distance that is not a positive
    number. *)

val background_along : t -> Vec3.t -> Color.t
(** [background_along s d] is what a ray with unit direction [d] that hits nothing sees,
    before fog: [background], or the [sky] gradient at [d]. *)

val fog_segment : fog -> float -> Color.t -> Color.t
(** [fog_segment f t c] is c·e^(−t/distance) + color·(1 − e^(−t/distance)), per channel; t
    may be infinite (then it is [f.color]). *)
