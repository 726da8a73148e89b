(** Hints for habits brought from other scene languages (mostly POV-Ray) and for common
    slips: each is a sentence added to an error whose cause is likely that habit. All of
    them live here, so that one goes away in one place when the language grows the
    feature. *)

val angle_vector : string
(** For a [<] where a value was expected: vectors are written (x, y, z). *)

val directive : string -> string
(** [directive d] is the message for [#d] ([#declare], [#include], [#if], …), which the
    language does not have: what to write instead. *)

val pov_word : ?block:string -> string -> string option
(** [pov_word ?block w] is what lancer writes for POV-Ray's word [w] ([light_source],
    [angle], [pigment], [finish], [normal], [filter], [transmit], [metallic]), for an
    unknown block or field named [w] (in a block of keyword [block]); [None] for any other
    word. A field of that name where the block has one is known, and gets no hint. *)

val keyword_as_name : string -> string
(** [keyword_as_name k] says that keyword [k] (as [step]) cannot be used as a name. *)

val camera_up : Vec3.t -> Vec3.t -> string
(** [camera_up view up] is the message for a camera whose view direction [view] is along
    its [up] vector, suggesting an [up] across the view. *)

val defined_later : string -> Loc.t -> string
(** [defined_later x def] is the message for a use of [x] before its definition at [def].
*)
