(** Albedo textures: solid and procedural colour fields, and image maps.

    Solid (3-D) textures are evaluated at an object-space point; the caller passes P − δ·N
    (doc/reference/shading.md, section 6) so that a surface lying exactly on a cell
    boundary does not flicker. Image textures use the surface's (u, v). All colours are
    linear RGB. Every texture is a pure function of its arguments (the noise is seeded
    once, see {!module-Noise}), and never returns NaN for finite input. *)

type color_map = { ts : float array; cs : Color.t array }
(** A colour map as arrays: t_k and c_k. *)

val color_map : Description.color_map -> color_map
(** The arrays of a colour map's entries, which the description has checked
    ({!Lancer_description.Description.color_map_problem}). *)

val lookup : color_map -> float -> Color.t
(** [lookup m v] is the colour at [v]: c_0 below t_0, the last colour from the last t on,
    and in between linear between the bracketing entries t_k ≤ v < t_(k+1): c_k + ((v −
    t_k)/(t_(k+1) − t_k))·(c_(k+1) − c_k). *)

type t = (Framebuffer.t, color_map) Description.texture_of
(** The description's texture ({!Lancer_description.Description.texture_of}, where each
    kind is defined) with its image decoded to a linear framebuffer (from
    {!Lancer_image.Image.read_linear}) and its colour maps as arrays. *)

val eval : t -> Vec3.t -> float -> float -> Color.t
(** [eval tex p u v] is the albedo at object-space point [p] with texture coordinates
    ([u], [v]). *)

val eval_into : t -> Frag.t -> unit
(** [eval_into tex f] is {!eval} at the point [(f.x, f.y, f.z)] with texture coordinates
    [(f.u, f.v)], written into [(f.r, f.g, f.b)], bit for bit. Solid colours, checkers,
    stripes and two-colour noise allocate nothing. *)

val bilinear : Framebuffer.t -> float -> float -> Color.t
(** [bilinear img u v] samples [img] at (u, v) with wrapping (period 1 in both), v = 0 at
    the bottom row; non-finite coordinates sample (0, 0). *)

val needs_uv : t -> bool
(** Whether [eval] reads (u, v) (image textures), so shading computes them only then. *)

val name : t -> string
(** The kind, as written in a scene ("checker", "marble", "image", …; "solid" for a plain
    colour). *)
