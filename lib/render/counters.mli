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
}

val zero : t
(** Nothing counted. *)

val add : t -> t -> t
(** The sum of two counts; the pixel with a bad sample is the first one's if it has one.
*)

val sum : t array -> t
(** The counts added in order. *)

val total_rays : t -> int
(** Primary, shadow, reflected and refracted rays together. *)
