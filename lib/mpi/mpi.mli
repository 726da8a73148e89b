(** Thin bindings to MPI (Open MPI), just what [lancer-mpi] needs.

    Everything works on [MPI_COMM_WORLD]. Only the main domain may call these functions
    (the library is initialised with [MPI_THREAD_FUNNELED]); calls that can block release
    the OCaml runtime lock meanwhile, so other domains keep running. MPI's default error
    handler is kept: an MPI error, or a rank that dies, aborts the whole job.

    OCaml values travel marshalled ({!send}, {!recv}): a receiver must know the type a tag
    carries, exactly as with [Marshal], and all ranks must run the same executable. Float
    arrays travel as raw IEEE doubles, bit for bit. *)

val init : unit -> unit
(** [MPI_Init_thread] with [MPI_THREAD_FUNNELED]; does nothing if already initialised.
    Outside [mpirun] the process becomes a job of one rank. *)

val initialized : unit -> bool
(** Initialised and not yet finalised. *)

val finalize : unit -> unit
(** [MPI_Finalize] if initialised and not yet finalised; otherwise nothing. Collective:
    every rank must call it. *)

val rank : unit -> int
(** This process's rank, from 0 to [size () - 1]. *)

val size : unit -> int
(** The number of ranks in the job. *)

val barrier : unit -> unit

val abort : int -> 'a
(** [abort code] ends every rank of the job with [code] (MPI_Abort). *)

val wtime : unit -> float
(** Wall-clock seconds since some fixed time in the past. *)

val any_source : int
(** Receive or probe from any rank. *)

val any_tag : int
(** Receive or probe any tag. *)

(** {1 Bytes and marshalled values} *)

val send_bytes : bytes -> dest:int -> tag:int -> unit
(** [send_bytes b ~dest ~tag] sends [b] (copied first; [b] may be reused at once). Tags
    are in [0, 32767]. Blocks until MPI no longer needs the copy. *)

val recv_bytes : source:int -> tag:int -> bytes * int * int
(** [recv_bytes ~source ~tag] is (data, source, tag) of the next matching message of any
    length. *)

val bcast_bytes : bytes -> root:int -> bytes
(** [bcast_bytes b ~root] is [root]'s [b] on every rank (the others' [b] is ignored).
    Collective. *)

val send : 'a -> dest:int -> tag:int -> unit
(** [send v ~dest ~tag] sends [v] marshalled (no closures). *)

val recv : source:int -> tag:int -> 'a * int * int
(** [recv ~source ~tag] is (value, source, tag). The type is the caller's promise, as with
    [Marshal.from_bytes]. *)

val bcast : 'a -> root:int -> 'a
(** {!bcast_bytes} of a marshalled value. *)

(** {1 Float arrays} *)

type floats = (float, Bigarray.float64_elt, Bigarray.c_layout) Bigarray.Array1.t

val send_floats : ?len:int -> floats -> dest:int -> tag:int -> unit
(** [send_floats a ~dest ~tag] sends the first [len] (default all) elements of [a], in
    place (no copy). *)

val recv_floats : floats -> source:int -> tag:int -> int * int * int
(** [recv_floats a ~source ~tag] receives the next matching message of doubles into the
    start of [a] and is (count, source, tag). Raises [Invalid_argument] (the message is
    then dropped) when it holds more than [Bigarray.Array1.dim a] elements. *)

(** {1 Looking before receiving} *)

val probe : source:int -> tag:int -> int * int * int
(** [probe ~source ~tag] waits for a matching message and is (source, tag, length in
    bytes), leaving the message to be received. *)

val iprobe : source:int -> tag:int -> (int * int * int) option
(** As {!probe}, but [None] at once when no matching message has arrived. *)
