(** [lancer verify]: whether an image lancer wrote still comes from the scene its record
    names ({!Lancer_job.Provenance}). The image's blocks are checked against the digests
    the record holds (a block edited since it was written is found whatever it is); the
    scene and every file it read against their digests (a missing or changed input is
    named); then some blocks, chosen from the image's own digest, and every edited one,
    are rendered again from the scene and compared sample for sample. *)

type blocks = All | Count of int  (** how many blocks to render again *)

val run : ?cancel:Cancel.t -> ?domains:int -> blocks:blocks -> string -> bool
(** [run ~blocks image] says on stdout what it found and is whether the image was
    reproduced. Raises {!Lancer_job.Job_error.User} for an image that cannot be read or
    holds no record (or one that is not lancer's), {!Lancer_job.Job_error.Scene} for a
    scene that no longer loads; [Sys.Break] when [cancel] is cancelled. *)
