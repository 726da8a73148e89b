(** The HTTP server of [lancer watch]: cohttp's (with Lwt) on connections it accepts
    itself (cohttp's Unix binding would accept them through conduit, whose TLS support
    reads the system's certificate store as every program linked with it starts), with
    what one connection may cost and who may ask.

    Each request is checked, before any byte of its body is read: its head within
    {!max_head_bytes} (431); exactly one Host header, this server's own address (400,
    403); an Origin header (at most one) this server's own, and a Sec-Fetch-Site of
    [same-origin] except for the page itself at [/] (403); a body of at most
    {!max_body_bytes} with its length given (413, 411). A connection has {!idle_timeout}
    seconds to send a complete request or to take an answer; past {!max_connections}, the
    one that has waited longest for its request is closed. *)

val max_head_bytes : int
(** 16 KiB: a request's line and headers together. *)

val max_body_bytes : int
(** 4 KiB: a request's body. *)

val idle_timeout : float
(** 10 s. *)

val max_connections : int
(** 64. *)

type response = Cohttp.Response.t * Cohttp_lwt.Body.t

val respond :
  ?headers:Cohttp.Header.t ->
  ?flush:bool ->
  status:Cohttp.Code.status_code ->
  body:Cohttp_lwt.Body.t ->
  unit ->
  response Lwt.t
(** cohttp's [respond]. *)

val respond_string :
  ?flush:bool ->
  ?headers:Cohttp.Header.t ->
  status:Cohttp.Code.status_code ->
  body:string ->
  unit ->
  response Lwt.t
(** cohttp's [respond_string]. *)

val text : ?close:bool -> Cohttp.Code.status_code -> string -> response Lwt.t
(** A plain-text answer; with [close] the connection is closed after it. *)

val run :
  authority:string ->
  route:(Cohttp.Connection.t -> Cohttp.Request.t -> response Lwt.t) ->
  conn_closed:(Cohttp.Connection.t -> unit) ->
  Lwt_unix.file_descr ->
  unit Lwt.t
(** Serve the connections accepted on a listening socket, [authority] ("127.0.0.1:8123",
    "[::1]:8123") being this server's own address as a browser writes it: each request
    admitted as above goes to [route], its body drained; [conn_closed] when a connection
    ends. What goes wrong with one connection ends only that one; out of descriptors or
    memory, the server waits a tenth of a second rather than stop. Only a listening socket
    that is no longer one ends it; the socket is closed when it ends. *)
