(** Comparing two encoded images: the figures a golden-image test or [lancer diff] needs,
    and a diff image that shows where they differ.

    Differences are measured on the 8-bit encoded values, per channel, by default: the
    largest difference and the share of pixels beyond a threshold. A comparison may
    instead be judged by a {!metric}: the RMSE, the PSNR, the mean FLIP (the perceptual
    error of {!module-Flip}) or the SSIM (of {!module-Ssim}). *)

(** A limit in one metric: what two images may differ by and still count as equal. *)
type metric =
  | Rmse of float  (** RMSE at most this, in 0–255 units *)
  | Psnr of float  (** PSNR at least this, in dB *)
  | Flip of float  (** mean FLIP at most this, 0–1 *)
  | Ssim of float  (** SSIM at least this, -1–1 *)

val check_metric : metric -> (unit, string) result
(** [Error] for a limit outside the metric's range (RMSE 0–255, PSNR at least 0, FLIP 0–1,
    SSIM -1–1) or not a number. *)

val measure :
  metric -> int * int * Bytes.t -> int * int * Bytes.t -> (float, string) result
(** The value of the metric's figure for two images; [Error] when their sizes differ, or
    for SSIM when they are under {!Ssim.window} pixels on a side. *)

val passes : metric -> float -> bool
(** Whether a value of the metric's figure is within its limit. *)

val pp_judged : Format.formatter -> metric * float -> unit
(** A metric's value against its limit, e.g. [mean FLIP 0.0123 > 0.01] or
    [SSIM 0.9871 >= 0.95]. *)

type t = {
  width : int;
  height : int;
  max_diff : int;  (** largest per-channel difference, 0–255 *)
  rmse : float;  (** root mean square of per-channel differences, in 0–255 units *)
  psnr : float;  (** 20·log10(255/rmse) dB; infinity for identical images *)
  over : int;  (** pixels with some channel differing by more than the threshold *)
  over_share : float;  (** [over] / pixels *)
  judged : (metric * float) option;
      (** the metric the images were judged by and its value, when one was given *)
}

val compare :
  ?threshold:int ->
  ?metric:metric ->
  int * int * Bytes.t ->
  int * int * Bytes.t ->
  (t, string) result
(** [compare ~threshold a b] compares two (width, height, RGB bytes) images; [Error] when
    their sizes differ (or as {!measure} and {!check_metric} say, with a [metric]).
    [threshold] (default 1) is the per-channel difference a pixel may have without
    counting in [over]; a [metric] is measured into [judged]. *)

val diff_image : ?threshold:int -> int * int * Bytes.t -> int * int * Bytes.t -> Bytes.t
(** A picture of the differences: the first image dimmed to a quarter, with pixels over
    the threshold in red, brighter for larger differences. Same size as the inputs. *)

val flip_image : int * int * Bytes.t -> int * int * Bytes.t -> Bytes.t
(** FLIP's error map of the second image against the first, in grey ({!Flip.grey}): black
    where they agree, white at error 1. Same size as the inputs. *)

val within : ?max_diff:int -> ?max_share:float -> t -> bool
(** [within ~max_diff ~max_share c]: every channel within [max_diff] (default 1), except a
    share of at most [max_share] (default 0) of the pixels; when [c] was judged by a
    metric, whether its value is within that metric's limit instead. *)

val pp : Format.formatter -> t -> unit
(** One line: max difference, RMSE, PSNR, pixels over the threshold, then the metric and
    its value when the images were judged by one. *)

(** {1 Golden images} *)

type outcome =
  | Same of t  (** within tolerance *)
  | Updated of string  (** golden (re)written at this path *)
  | Different of { figures : t; actual : string; diff : string }
      (** beyond tolerance; where the actual and diff images were written *)
  | Missing of { actual : string }  (** no golden yet; the actual image was written *)

val golden :
  ?tolerance:int ->
  ?max_share:float ->
  ?metric:metric ->
  update:bool ->
  golden:string ->
  int * int * Bytes.t ->
  (outcome, string) result
(** [golden ~update ~golden img] holds an encoded image against the PNG at [golden]: with
    [update], writes it there instead. On a difference (or with no golden) the image is
    written beside the golden as [NAME.actual.png], with [NAME.diff.png] for a difference;
    after a pass or an update, those of an earlier failure are removed. The golden's
    directory is created when it is missing. [tolerance] (default 1) and [max_share]
    (default 0) are as in {!within}; with a [metric], the image passes when it is within
    that metric's limit instead, and the diff image is FLIP's error map ({!flip_image}).
    What [lancer golden] and [lancer-alcotest] both do. *)
