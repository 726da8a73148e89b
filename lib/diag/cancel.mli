(** Cancellation tokens: how a render (or any long job) is asked to stop.

    A token is a value passed down to the work it may stop. The work polls it at safe
    points — before each tile, and every {!check_every} units of work inside a tile (a
    ray, or a test of one surface inside a CSG object) — and raises [Sys.Break] there, in
    lancer's own code, once the token is cancelled. A signal handler cancels the token
    with {!signal}, which also raises [Sys.Break] at once unless the program is inside a
    {!deferring} region (a pool of domains, a file being written), where an exception
    arriving at an arbitrary point could leave a lock held or a write half done.
    Cancellation is final: a token is never reset. *)

type t

val create : unit -> t
(** A fresh token, not cancelled. *)

val cancel : t -> unit
(** [cancel t] asks every piece of work polling [t] to stop. Safe from any domain and from
    a signal handler. *)

val cancelled : t -> bool
(** Whether [t] has been cancelled. *)

val check : t -> unit
(** [check t] raises [Sys.Break] if [t] has been cancelled, and does nothing otherwise. *)

val signal : t -> unit
(** What a SIGINT/SIGTERM handler calls: [cancel t], then raise [Sys.Break] right away
    unless a {!deferring} region of [t] is running (then the work stops at its next poll).
*)

val deferring : t -> (unit -> 'a) -> 'a
(** [deferring t f] runs [f] with {!signal} not raising; regions nest. It does not check
    [t] afterwards: the caller says what an interruption at that point means. *)

val check_every : int
(** Units of work between two polls of the token inside a tile (4096): rays traced, and
    tests of a surface inside a CSG object, where one ray may make millions. *)
