(** A fixed pool of domains that run the iterations of a loop in parallel.

    lancer needs one parallel construct: "run [body i] for every i of \[0, n), each index
    once, on whichever domain is free", with the calling domain working too. This module
    is that construct over the standard library's [Domain], [Mutex], [Condition] and
    [Atomic], so lancer depends on no scheduler library (Debian 13 packages none).

    Indices are handed out one at a time from an atomic counter, so the assignment of
    indices to domains varies from run to run; callers write results only into slots of
    their own index, which keeps their output independent of the schedule. *)

type t
(** A pool: [size t - 1] worker domains, parked while no loop runs. *)

val create : int -> t
(** [create n] starts a pool of [n] domains in all, the caller counting as one ([n - 1]
    new domains; none when [n <= 1]), or fewer when the system has no room for more: under
    a limit on the address space (ulimit -v), a domain is started only while what starting
    it takes fits under the limit, and a domain that cannot be started ends the spawning.
    The pool then works with the domains it has, the caller at least. *)

val size : t -> int
(** The number of domains that run a loop, the caller's included: at most [n]. *)

val parallel_for : t -> int -> (int -> unit) -> unit
(** [parallel_for t n body] runs [body i] for i = 0 .. n - 1 over the pool and returns
    when every started call has returned. If a call raises, no further index is started,
    and the first exception is raised again in the caller once the others have stopped.
    Loops on one pool must not overlap (calls from inside [body] are not supported). *)

val teardown : t -> unit
(** [teardown t] stops and joins the workers. The pool cannot be used afterwards. *)
