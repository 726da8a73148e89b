(** Comparing two encoded images: the figures a golden-image test or [lancer diff] needs,
    and a diff image that shows where they differ.

    Differences are measured on the 8-bit encoded values, per channel. *)

type t = {
  width : int;
  height : int;
  max_diff : int;  (** largest per-channel difference, 0–255 *)
  rmse : float;  (** root mean square of per-channel differences, in 0–255 units *)
  psnr : float;  (** 20·log10(255/rmse) dB; infinity for identical images *)
  over : int;  (** pixels with some channel differing by more than the threshold *)
  over_share : float;  (** [over] / pixels *)
}

val compare :
  ?threshold:int -> int * int * Bytes.t -> int * int * Bytes.t -> (t, string) result
(** [compare ~threshold a b] compares two (width, height, RGB bytes) images; [Error] when
    their sizes differ. [threshold] (default 1) is the per-channel difference a pixel may
    have without counting in [over]. *)

val diff_image : ?threshold:int -> int * int * Bytes.t -> int * int * Bytes.t -> Bytes.t
(** A picture of the differences: the first image dimmed to a quarter, with pixels over
    the threshold in red, brighter for larger differences. Same size as the inputs. *)

val within : ?max_diff:int -> ?max_share:float -> t -> bool
(** [within ~max_diff ~max_share c]: every channel within [max_diff] (default 1), except a
    share of at most [max_share] (default 0) of the pixels. *)

val pp : Format.formatter -> t -> unit
(** One line: max difference, RMSE, PSNR, pixels over the threshold. *)

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
  update:bool ->
  golden:string ->
  int * int * Bytes.t ->
  (outcome, string) result
(** [golden ~update ~golden img] holds an encoded image against the PNG at [golden]: with
    [update], writes it there instead. On a difference (or with no golden) the image is
    written beside the golden as [NAME.actual.png], with [NAME.diff.png] for a difference;
    after a pass or an update, those of an earlier failure are removed. The golden's
    directory is created when it is missing. [tolerance] (default 1) and [max_share]
    (default 0) are as in {!within}. What [lancer golden] and [lancer-alcotest] both do.
*)
