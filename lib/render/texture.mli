(** Albedo textures: solid and procedural colour fields, and image maps.

    Solid (3-D) textures are evaluated at an object-space point; the caller passes P − δ·N
    (doc/shading.md, section 6) so that a surface lying exactly on a cell boundary does
    not flicker. Image textures use the surface's (u, v). All colours are linear RGB.
    Every texture is a pure function of its arguments (the noise is seeded once, see
    {!module-Noise}), and never returns NaN for finite input. *)

type color_map = { ts : float array; cs : Color.t array }
(** A colour map: entries (t_k, c_k) with 0 ≤ t_0 ≤ t_1 ≤ … ≤ 1, at least one. *)

val color_map : (float * Color.t) list -> (color_map, string) result
(** [color_map entries] checks the entries: at least one, each t in [0, 1], in
    non-decreasing order, colours finite and non-negative. *)

val lookup : color_map -> float -> Color.t
(** [lookup m v] is the colour at [v]: c_0 below t_0, the last colour from the last t on,
    and in between linear between the bracketing entries t_k ≤ v < t_(k+1): c_k + ((v −
    t_k)/(t_(k+1) − t_k))·(c_(k+1) − c_k). *)

type t =
  | Solid of Color.t
  | Checker of { c1 : Color.t; c2 : Color.t; size : float }
      (** k = ⌊x/s⌋ + ⌊y/s⌋ + ⌊z/s⌋; c1 where k is even, c2 where odd. *)
  | Stripes of { c1 : Color.t; c2 : Color.t; size : float }  (** along x: ⌊x/s⌋ parity *)
  | Noise of { c1 : Color.t; c2 : Color.t; scale : float }
      (** mix c1 c2 by ½(1 + perlin(P/scale)), clamped to [0, 1] *)
  | Marble of { c1 : Color.t; c2 : Color.t; scale : float }
      (** veins along x: mix c1 c2 by ½(1 + sin(π·(x/scale + 4·turbulence(P/scale)))) *)
  | Wood of { c1 : Color.t; c2 : Color.t; scale : float }
      (** rings around the y axis, [scale] apart: the fraction of r/scale +
          0.35·perlin(x/2s, y/10s, z/2s) (s = scale, r = √(x² + z²)), mixed smoothly from
          c1 (ring start) to c2 *)
  | Gradient of { axis : Vec3.t; map : color_map }
      (** value fract(P·axis) = P·axis − ⌊P·axis⌋ (object space), coloured by the map *)
  | Mapped of { pattern : pattern; map : color_map }
      (** a noise, marble or wood pattern coloured by a map: the value that would mix c1
          and c2, clamped to [0, 1], looked up in the map *)
  | Image of { img : Image.t; scale : float }
      (** a linear framebuffer (from {!Image.read_linear}) on (u, v): u left to right, v
          bottom to top, [scale] copies across the unit square in each direction, bilinear
          filtering, wrapping at the edges *)

and pattern =
  | Noise_pattern of float
  | Marble_pattern of float
  | Wood_pattern of float  (** each with its scale *)

val eval : t -> Vec3.t -> float -> float -> Color.t
(** [eval tex p u v] is the albedo at object-space point [p] with texture coordinates
    ([u], [v]). *)

val eval_into : t -> Frag.t -> unit
(** [eval_into tex f] is {!eval} at the point [(f.x, f.y, f.z)] with texture coordinates
    [(f.u, f.v)], written into [(f.r, f.g, f.b)], bit for bit. Solid colours, checkers,
    stripes and two-colour noise allocate nothing. *)

val bilinear : Image.t -> float -> float -> Color.t
(** [bilinear img u v] samples [img] at (u, v) with wrapping (period 1 in both), v = 0 at
    the bottom row; non-finite coordinates sample (0, 0). *)

val needs_uv : t -> bool
(** Whether [eval] reads (u, v) (image textures), so shading computes them only then. *)

val name : t -> string
(** The kind, as written in a scene ("checker", "marble", "image", …; "solid" for a plain
    colour). *)
