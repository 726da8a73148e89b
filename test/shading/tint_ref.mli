(** A reference Whitted shader for one sphere under one point light and a gradient sky,
    written from the shading formulas alone (camera, local light with shadows through
    transparent surfaces, reflection, refraction with total internal reflection and
    Schlick's Fresnel, metallic and filter tints, sRGB encoding), with none of lancer's
    code: what lancer renders is compared with it byte for byte. *)

type v = { x : float; y : float; z : float }

val v : float -> float -> float -> v

type scene = {
  width : int;
  height : int;
  depth : int;  (** the most ray depth; primary rays have depth 1 *)
  horizon : v;
  zenith : v;  (** the sky: mix(horizon, zenith, max(0, D.y)) *)
  eye : v;
  look_at : v;
  fov : float;  (** vertical, degrees; up is +y *)
  light : v;  (** a point light of white colour, intensity 1, no attenuation *)
  center : v;
  radius : float;
  material : Lancer.Description.material;  (** its texture and bump are not read *)
}

val render : scene -> Bytes.t
(** The sRGB-encoded RGB bytes, one sample at each pixel's centre, rows top to bottom. *)

val rts : scene -> string
(** The scene as lancer's language writes it. *)
