(** Render settings (the [settings] block of a scene), with their defaults. *)

type gamma = Srgb  (** the sRGB transfer curve *) | Power of float  (** v^(1/g) *)

type t = {
  width : int;  (** pixels, ≥ 1; default 640 *)
  height : int;  (** pixels, ≥ 1; default 480 *)
  depth : int;  (** maximum ray depth, ≥ 1 (primary rays have depth 1); default 5 *)
  samples : int;  (** n: n×n samples per pixel, ≥ 1; default 1 *)
  jitter : bool;  (** move each sample inside its sub-cell by a hash; default false *)
  adaptive : float;  (** adaptive supersampling threshold; 0 = off (default) *)
  shadows : bool;  (** default true *)
  background : Color.t;  (** linear colour of rays that hit nothing; default black *)
  ambient : Color.t;  (** scene ambient light, multiplies material ambient; default white *)
  gamma : gamma;  (** output encoding; default sRGB *)
}

val default : t
(** The settings with every default, as listed with the fields above. *)

val max_pixels : int
(** The largest image accepted: width × height ≤ this (268 435 456 = 16384², 6 GiB of
    linear framebuffer). *)

val max_depth : int
(** 1000: the largest ray depth (each bounce is a nested call). *)

val validate : t -> (unit, string) result
(** [Error] naming the field when a setting is out of range: size below 1×1 or above
    {!max_pixels}, depth below 1, samples outside 1–64, adaptive negative or not finite, or
    a gamma that is not a positive number. *)
