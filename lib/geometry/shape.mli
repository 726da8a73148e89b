(** Geometric primitives in object space: the closed set of surfaces lancer can intersect.

    Every function takes rays and points in the primitive's own object space (world space
    for an untransformed object). Intersections return the ray parameter t of the nearest
    root strictly inside (tmin, tmax), or [Float.infinity] when there is none; a NaN is
    never returned. Rays may have non-unit directions (object-space rays), and t then
    means the same point as in world space. *)

type t =
  | Sphere of { center : Vec3.t; radius : float }
  | Plane of { normal : Vec3.t; offset : float }  (** unit normal; n̂·P = offset *)

val sphere : center:Vec3.t -> radius:float -> t
val plane : normal:Vec3.t -> offset:float -> t
(** [plane ~normal ~offset]: [normal] need not be unit; the plane is n̂·P = offset with
    n̂ = normalize normal. *)

val intersect : t -> Ray.t -> float -> float -> float
(** [intersect s r tmin tmax] is the smallest root t of [r] on [s] with tmin < t < tmax,
    or [infinity]. *)

val normal : t -> Vec3.t -> Vec3.t
(** [normal s p] is the unit geometric normal at the surface point [p] (outward for closed
    surfaces; for planes, the plane's own normal). *)

val uv : t -> Vec3.t -> float * float
(** [uv s p] is the texture coordinate of surface point [p], each in [0, 1) for bounded
    parametrisations (spheres: longitude and latitude; planes: x and z). *)

val bbox : t -> Bbox.t option
(** Object-space bounds; [None] for unbounded surfaces (planes). *)

val name : t -> string
(** The kind, as written in a scene ("sphere", "plane", …). *)

val solve_quadratic : float -> float -> float -> float -> float -> float
(** [solve_quadratic a b c tmin tmax] is the smallest root of a·t² + b·t + c in
    (tmin, tmax), or infinity: roots by q = −½(b + sign(b)·√Δ), t₀ = q/a, t₁ = c/q;
    the linear case a = 0 is solved as such (and a = b = 0 has no root). *)
