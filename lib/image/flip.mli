(** FLIP, the perceptual difference of two low-dynamic-range images (Andersson, Nilsson,
    Akenine-Möller, Oskarsson, Åström and Fairchild, 2020, "FLIP: A Difference Evaluator
    for Alternating Images", the LDR form).

    Both images are 8-bit sRGB. Each is decoded to linear RGB and taken to the opponent
    space YCxCz; the three channels are filtered by the contrast sensitivity functions of
    the paper (separable sums of Gaussians, scaled to the viewing distance in pixels per
    degree); the filtered colours are clamped to the RGB cube, taken to CIE L*a*b* with
    the Hunt adjustment, and compared by the HyAB distance, raised to 0.7 and
    redistributed so that 0.4 of the largest distance (green against blue) maps to 0.95.
    Edges and points are found on the unfiltered achromatic channel with the first and
    second derivatives of a Gaussian; their larger difference [f] raises the colour error
    [c] to [c^(1-f)]. The error of a pixel lies in 0–1, 0 where the images agree.

    Written here from the paper and the constants of NVIDIA's reference implementation (no
    packaged OCaml library computes FLIP); its values agree with the [flip-evaluator]
    Python package within 0.001 in mean (test/flip/). Computed in double precision with
    separable filters over [Float.Array] planes; the borders repeat the edge pixels. *)

val pixels_per_degree : distance:float -> pixels:float -> width:float -> float
(** [pixels_per_degree ~distance ~pixels ~width]: for a viewer [distance] metres from a
    monitor [width] metres wide showing [pixels] pixels across. *)

val default_ppd : float
(** The default viewing condition: 0.7 m from a monitor 0.7 m wide of 3840 pixels, about
    67.02 pixels per degree. *)

val error_map : ?ppd:float -> int * int * Bytes.t -> int * int * Bytes.t -> Float.Array.t
(** [error_map reference test]: the FLIP error of every pixel of two (width, height, RGB
    bytes) images of the same size, row by row. [ppd] defaults to {!default_ppd}. Raises
    [Invalid_argument] when the sizes differ or [ppd] is not positive. *)

val mean : Float.Array.t -> float
(** The mean of an error map (0 for an empty one): the figure FLIP is quoted by. *)

val grey : Float.Array.t -> Bytes.t
(** An error map as an RGB picture, grey: black where the images agree, white at error 1
    (each byte is [round (255·e)]). *)
