(** SSIM, the structural similarity of two images (Wang, Bovik, Sheikh and Simoncelli,
    2004, "Image quality assessment: from error visibility to structural similarity").

    Computed on each of the three channels of the 8-bit encoded values (dynamic range 255,
    K1 = 0.01, K2 = 0.03), with an 11×11 Gaussian window of standard deviation 1.5 (radius
    5, weights summing to 1) and the population (1/N) variances; the SSIM of a channel is
    the mean of its map over the pixels at least 5 pixels from every border (where the
    window lies inside the image), and the SSIM of the images is the mean of the three
    channels'. These are the choices of scikit-image's [structural_similarity] with
    [gaussian_weights=True, sigma=1.5, use_sample_covariance=False, data_range=255,
     channel_axis=2], whose values it matches (test/flip/). 1 for identical images; it
    falls towards 0 (or below) as they differ. *)

val window : int
(** The smallest width and height SSIM is defined for: 11. *)

val ssim : int * int * Bytes.t -> int * int * Bytes.t -> (float, string) result
(** [ssim a b] of two (width, height, RGB bytes) images; [Error] when their sizes differ
    or either side is under {!window} pixels. *)
