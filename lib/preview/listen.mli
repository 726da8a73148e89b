(** Where [lancer watch] listens: one IP address, a loopback one unless told otherwise,
    never a wildcard (every address of the machine, however it is written). *)

type reach =
  | Everywhere  (** a wildcard: [0.0.0.0], [::], [::ffff:0.0.0.0] in any spelling *)
  | Loopback  (** [127.0.0.0/8], [::1], [::ffff:127.x.y.z] *)
  | Beyond  (** any other address *)

val listen_address : Unix.inet_addr -> Unix.inet_addr * reach
(** An address to listen on and where it listens. An IPv4 address mapped into IPv6 is
    given as the IPv4 address itself: a socket bound to either takes the same connections,
    and a browser names it by its IPv4 form (its Host header). *)

val socket :
  host:string -> port:int -> beyond_loopback:bool -> Lwt_unix.file_descr * string
(** A socket listening on [host] at [port] (0: a free one), and its address as a browser
    writes it in the Host header ("127.0.0.1:8123", "[::1]:8123"). Raises
    {!Lancer.Job_error.User} for a host that is not an IP address, a wildcard, one beyond
    loopback without [beyond_loopback], or an address and port that cannot be bound. *)
