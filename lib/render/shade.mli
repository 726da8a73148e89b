(** The Whitted shading model of doc/shading.md, exactly: ambient, Lambert with distance
    attenuation, shadows with transmittance through transparent surfaces, Phong
    highlights, mirror reflection, Snell–Descartes refraction with total internal
    reflection, optional Schlick Fresnel, and the depth rule.

    Secondary and shadow rays start off the surface by {!offset}, which is proportional to
    the magnitude of the coordinates involved, so a scene scaled by any factor renders the
    same image. *)

val offset : Vec3.t -> Vec3.t -> float
(** [offset p o] is δ for hit point [p] reached from ray origin [o]: 1e−9 · max(|p|∞,
    |o|∞), never 0. *)

val reflect : Vec3.t -> Vec3.t -> Vec3.t
(** [reflect d nf] is d − 2(d·nf)·nf. *)

val refract : Vec3.t -> Vec3.t -> float -> Vec3.t option
(** [refract d nf eta] is the Snell–Descartes direction η·d + (η·c − √k)·nf with c = −d·nf
    and k = 1 − η²(1 − c²), or [None] on total internal reflection (k < 0). *)

val trace : Scene.t -> Stats.t -> Ray.t -> int -> Color.t
(** [trace scene stats ray depth] is the linear colour seen along [ray], a ray of depth
    [depth] (primary rays have depth 1): one camera sample, fogged over its segment when
    the scene has fog. Counts secondary and shadow rays in [stats], and polls its token
    ({!Stats.tick}) once per ray, raising [Sys.Break] when it is cancelled. At most
    {!max_secondary} secondary rays are cast for the sample, depth first; those past it
    contribute black, as rays past the depth do. *)

val max_secondary : int
(** 65536: the most secondary (reflected and refracted) rays one call of {!trace} casts.
*)

val miss : Scene.t -> Vec3.t -> Color.t
(** [miss scene d] is the colour of a ray with unit direction [d] that hits nothing: the
    background (flat or gradient), through the fog of an infinite segment when there is
    fog. *)

val transmittance : Scene.t -> Stats.t -> Vec3.t -> Vec3.t -> float -> Color.t
(** [transmittance scene stats origin dir dist] is the product, over every surface the ray
    crosses before [dist], of transparency · albedo (0 for an opaque surface). *)
