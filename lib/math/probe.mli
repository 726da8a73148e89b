(** A ray held as scalars in one flat, reusable record, with a query interval and its
    answer: the form in which the renderer traces, so that casting a ray builds no
    {!Ray.t} and boxes no float.

    A record of floats is stored flat: reading and writing its fields allocates nothing. A
    probe is scratch, owned by one domain at a time. *)

(* The hierarchy's descent, in C (lib/render/descent_stubs.c), reads the origin and the
   reciprocal direction by their position in this record of floats: keep its order. *)
type t = {
  mutable ox : float;
  mutable oy : float;
  mutable oz : float;  (** origin *)
  mutable dx : float;
  mutable dy : float;
  mutable dz : float;  (** direction, not necessarily unit *)
  mutable ix : float;
  mutable iy : float;
  mutable iz : float;  (** 1/direction, component-wise *)
  mutable p_tmin : float;
  mutable p_tmax : float;  (** the interval (p_tmin, p_tmax) *)
  mutable p_t : float;  (** the answer *)
}

val create : unit -> t
(** A fresh probe (all zero, answer infinity). *)

val set_origin : t -> float -> float -> float -> unit
(** [set_origin q x y z] makes (x, y, z) the origin. *)

val set_unit_dir : t -> float -> float -> float -> unit
(** [set_unit_dir q x y z] makes [Vec3.normalize (x, y, z)] the direction, bit for bit
    (the zero vector stays zero): the direction {!Ray.make} would give. The reciprocal is
    left as it was (see {!set_inv_dir}). *)

val set_inv_dir : t -> unit
(** [set_inv_dir q] sets (ix, iy, iz) to 1/(dx, dy, dz), as {!Ray.make_raw} computes it.
*)

val of_ray : t -> Ray.t -> unit
(** [of_ray q r] copies the origin, direction and reciprocal direction of [r] into [q]. *)

val to_ray : t -> Ray.t
(** The ray [q] holds, as {!Ray.make_raw} builds it (its direction kept as it is). *)

val inverse_into : Transform.t -> t -> t -> unit
(** [inverse_into tr q out] writes into [out] the ray [q] holds, moved by the inverse of
    [tr] (into the space [tr] maps from): origin and direction as {!Transform.inv_point}
    and {!Transform.inv_vector} move them, coordinate by coordinate and bit for bit, the
    direction not renormalised (a t means the same point in both spaces), the reciprocal
    direction recomputed as {!set_inv_dir} does. [out]'s interval is left as it was. *)
