(* See mpi.mli. The stubs are in mpi_stubs.c. *)

external init : unit -> unit = "lancer_mpi_init"
external initialized : unit -> bool = "lancer_mpi_initialized"
external finalize : unit -> unit = "lancer_mpi_finalize"
external rank : unit -> int = "lancer_mpi_rank"
external size : unit -> int = "lancer_mpi_size"
external barrier : unit -> unit = "lancer_mpi_barrier"
external abort_ : int -> unit = "lancer_mpi_abort"
external wtime : unit -> float = "lancer_mpi_wtime"
external send_bytes_ : bytes -> int -> int -> unit = "lancer_mpi_send_bytes"
external recv_bytes_ : int -> int -> bytes * int * int = "lancer_mpi_recv_bytes"
external bcast_bytes_ : bytes -> int -> bytes = "lancer_mpi_bcast_bytes"

type floats = (float, Bigarray.float64_elt, Bigarray.c_layout) Bigarray.Array1.t

external send_floats_ : floats -> int -> int -> int -> unit = "lancer_mpi_send_floats"
external recv_floats_ : floats -> int -> int -> int * int * int = "lancer_mpi_recv_floats"
external probe_ : int -> int -> int * int * int = "lancer_mpi_probe"
external iprobe_ : int -> int -> (int * int * int) option = "lancer_mpi_iprobe"

let abort code =
  abort_ code;
  exit code

(* The stubs map a negative source or tag to MPI_ANY_SOURCE / MPI_ANY_TAG. *)
let any_source = -1
let any_tag = -1

(* MPI guarantees tags up to 32767 at least. *)
let check_tag tag =
  if tag < 0 || tag > 32767 then
    invalid_arg (Printf.sprintf "Mpi: tag %d is not in [0, 32767]" tag)

let send_bytes b ~dest ~tag =
  check_tag tag;
  send_bytes_ b dest tag

let recv_bytes ~source ~tag = recv_bytes_ source tag
let bcast_bytes b ~root = bcast_bytes_ b root
let send v ~dest ~tag = send_bytes (Marshal.to_bytes v []) ~dest ~tag

let recv ~source ~tag =
  let b, s, t = recv_bytes ~source ~tag in
  (Marshal.from_bytes b 0, s, t)

let bcast v ~root = Marshal.from_bytes (bcast_bytes (Marshal.to_bytes v []) ~root) 0

let send_floats ?len a ~dest ~tag =
  check_tag tag;
  let len = Option.value len ~default:(Bigarray.Array1.dim a) in
  send_floats_ a len dest tag

let recv_floats a ~source ~tag = recv_floats_ a source tag
let probe ~source ~tag = probe_ source tag
let iprobe ~source ~tag = iprobe_ source tag
