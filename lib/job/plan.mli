(** Which frames a run renders, and in which order: a range of the animation, and the
    share of one shard of several ([--shard K/N], or the task of a Slurm job array). *)

val frames_of_string : string -> (int * int, string) result
(** ["A..B"] (inclusive, 0 <= A <= B) or ["K"]. *)

type shard = Shard of int * int  (** [--shard K/N] *) | Slurm  (** [--shard slurm] *)

val shard_of_string : string -> (shard, string) result
(** ["K/N"] with 0 <= K < N, or ["slurm"]. *)

val slurm_shard : (string -> string option) -> int * int
(** (K, N) from a Slurm job array's environment, read through the given [getenv]: N =
    [SLURM_ARRAY_TASK_COUNT], K = ([SLURM_ARRAY_TASK_ID] − [SLURM_ARRAY_TASK_MIN]) /
    [SLURM_ARRAY_TASK_STEP] (MIN 0 and STEP 1 when unset). Raises
    {!Lancer_job.Job_error.User}. *)

val resolve_shard : getenv:(string -> string option) -> shard -> int * int
(** (K, N) of a shard: as given, or {!slurm_shard}. *)

val shard_frames : first:int -> last:int -> (int * int) option -> int list
(** The frames of [first..last] that shard (K, N) renders, ascending: those whose index in
    the range is K modulo N; all of them without a shard. *)
