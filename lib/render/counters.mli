(** What a render counted: its rays by kind and its samples that came out NaN or infinite.
    Each render task counts its own ({!Task}), and the counts of the tasks are added at
    the end, so they are exact and deterministic whatever the number of domains. *)

type t = {
  primary : int;
  shadow : int;
  reflected : int;
  refracted : int;
  bad_samples : int;  (** samples that came out NaN or infinite *)
  first_bad : (int * int) option;  (** a pixel (column, row) with a bad sample *)
  noise_sq : int;
      (** the sum, over the channels of the pixels that estimate their noise, of the
          squared estimated standard error in 8-bit encoded steps, in units of
          {!noise_unit}: an integer, so that sums in any order agree *)
  noise_n : int;  (** the channels summed in [noise_sq] (3 per pixel) *)
}

val noise_unit : float
(** 2¹⁶: a squared 8-bit step is [noise_unit] units of [noise_sq]. *)

val zero : t
(** Nothing counted. *)

val add : t -> t -> t
(** The sum of two counts; the pixel with a bad sample is the first one's if it has one.
*)

val sum : t array -> t
(** The counts added in order. *)

val total_rays : t -> int
(** Primary, shadow, reflected and refracted rays together. *)

val noise : t -> float option
(** The noise estimate of a render: the root mean square, over its pixels' channels, of
    the estimated standard error of each pixel's value, in 8-bit encoded steps (the units
    of [lancer diff]'s RMSE); [None] where no pixel estimated it (nothing stochastic). *)
