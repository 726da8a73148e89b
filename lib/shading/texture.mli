(** Albedo textures: solid and procedural colour fields, and image maps.

    Solid (3-D) textures are evaluated at an object-space point; the caller passes
    P − δ·N (SPEC §2.5) so that a surface lying exactly on a cell boundary does not
    flicker. Image textures use the surface's (u, v). All colours are linear RGB. *)

type t =
  | Solid of Color.t
  | Checker of { c1 : Color.t; c2 : Color.t; size : float }
      (** k = ⌊x/s⌋ + ⌊y/s⌋ + ⌊z/s⌋; c1 where k is even, c2 where odd. *)
  | Stripes of { c1 : Color.t; c2 : Color.t; size : float }  (** along x: ⌊x/s⌋ parity *)

val eval : t -> Vec3.t -> float -> float -> Color.t
(** [eval tex p u v] is the albedo at object-space point [p] with texture coordinates
    ([u], [v]). *)

val needs_uv : t -> bool
(** Whether [eval] reads (u, v) (image textures), so shading computes them only then. *)

val name : t -> string
