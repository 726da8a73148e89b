(** The Whitted shading model of doc/reference/shading.md, exactly: ambient, Lambert with
    distance attenuation, shadows with transmittance through transparent surfaces, Phong
    highlights, mirror reflection, Snell–Descartes refraction with total internal
    reflection, optional Schlick Fresnel, highlights and reflections tinted by a metal's
    colour and refraction by a coloured glass's, and the depth rule.

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

val trace : Scene.t -> Task.t -> Ray.t -> int -> Color.t
(** [trace scene stats ray depth] is the linear colour seen along [ray], a ray of depth
    [depth] (primary rays have depth 1): one camera sample, fogged over its segment when
    the scene has fog. Counts secondary and shadow rays in [stats], and polls its token
    ({!Task.tick}) once per ray, raising [Sys.Break] when it is cancelled. At most
    {!max_secondary} secondary rays are cast for the sample, depth first; those past it
    contribute black, as rays past the depth do. *)

type scratch
(** What tracing writes as it goes, as flat records of floats: the ray being traced, the
    shadow ray, the fragment shapes and textures answer into, the light sums. One per
    domain at a time: a tile makes its own. *)

val scratch : unit -> scratch
(** A fresh scratch, for the calling domain only: it holds that domain's query scratch
    ({!Accel.domain_scratch}). *)

val probe : scratch -> Probe.t
(** Where {!trace_into} reads its ray: fill its origin and (unit) direction. *)

val frag : scratch -> Frag.t
(** Where {!trace_into} leaves its colour, in [(r, g, b)]. *)

val accel_scratch : scratch -> Accel.scratch
(** The domain's query scratch the shading steps pass to their queries (what a watch of
    {!Accel.watch} is set on). *)

val trace_into : Scene.t -> Task.t -> scratch -> int -> unit
(** [trace_into scene stats scr depth] is {!trace} of the ray that [probe scr] holds, bit
    for bit, its colour written into [(frag scr).(r, g, b)]. Camera, reflected and
    refracted rays build no ray, vector or colour on the way, with the shapes that
    {!Lancer_render.Shape.root} and {!Lancer_render.Shape.normal_into} handle in scalars
    and the textures {!Texture.eval_into} does; bump maps and CSG objects still allocate.
    The probe and the fragment are overwritten. *)

val half_diff : int -> float -> float -> float
(** [half_diff m s d], of [m] ≥ 2 samples split into two interleaved halves A (⌈m/2⌉ of
    them) and B (⌊m/2⌋) with sum [s] = S_A + S_B and signed sum [d] = S_A − S_B, is
    (mean_A − mean_B)·√(n_A·n_B)/m: were the samples independent, its square would
    estimate, without bias, the variance of the mean of all [m] (a quarter of (mean_A −
    mean_B)² for equal halves). *)

val half_diff_into : scratch -> Float.Array.t -> int -> unit
(** [half_diff_into scr a k] writes into a.(k), a.(k+1), a.(k+2) the half-difference of
    the colour the last {!trace_into} left, in a scene with soft shadows (zero in one
    without): every area light's n×n shadow rays fall into two interleaved halves (by the
    parity of the sample's two indices), and the colour is linear in each light's
    transmittance, so the same sums carry (T_A − T_B)·√(n_A·n_B)/n² of each light instead
    of its mean transmittance. Its square estimates the variance of the colour that the
    lights' sampling leaves (doc/explanation/speed.md, "The noise estimate"). *)

val max_secondary : int
(** 65536: the most secondary (reflected and refracted) rays one call of {!trace} casts.
*)

val miss : Scene.t -> Vec3.t -> Color.t
(** [miss scene d] is the colour of a ray with unit direction [d] that hits nothing: the
    background (flat or gradient), through the fog of an infinite segment when there is
    fog. *)

val transmittance : Scene.t -> Task.t -> Vec3.t -> Vec3.t -> float -> Color.t
(** [transmittance scene stats origin dir dist] is the product, over every surface the ray
    crosses before [dist], of transparency · albedo (0 for an opaque surface). *)
