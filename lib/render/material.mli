(** Surface materials, with every field and its default.

    Invariants, checked by {!validate}: coefficients are finite and non-negative,
    reflection + transparency ≤ 1, ior > 0. *)

type t = {
  color : Color.t;  (** linear albedo when there is no texture; default white *)
  texture : Texture.t option;  (** albedo texture; overrides [color] *)
  ambient : float;  (** default 0.1 *)
  diffuse : float;  (** default 0.9 *)
  specular : float;  (** Phong weight; default 0 *)
  shininess : float;  (** Phong exponent; default 50 *)
  reflection : float;  (** mirror weight r in [0, 1]; default 0 *)
  transparency : float;  (** refraction weight τ in [0, 1]; default 0 *)
  ior : float;  (** index of refraction; default 1 *)
  fresnel : bool;  (** Schlick's approximation moves τ·F to r; default false *)
  bump : Bump.t option;  (** normal perturbation; default none *)
}

val default : t
(** The material with every default above: white, ambient 0.1, diffuse 0.9, no texture or
    bump. *)

val validate : t -> (unit, string) result
(** [validate m] is [Error msg] when an invariant above does not hold. *)
