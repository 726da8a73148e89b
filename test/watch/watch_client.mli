(** A client of [lancer watch] for the tests: start the server on a free port, make raw
    HTTP requests (any path, any Host), read its server-sent events. *)

type server = {
  pid : int;
  port : int;
  out : in_channel;
  dir : string;
  mutable log : string list;
}

val start : exe:string -> dir:string -> string list -> server
(** [start ~exe ~dir args] runs [exe watch args --port 0] in [dir] and reads the address
    it prints (within 60 s). Its stderr goes to [dir/watch.err]. *)

val stderr_text : server -> string

val stop : server -> Unix.process_status
(** Interrupt it (SIGINT) and wait for it (killed after 30 s). *)

val input_line_within : in_channel -> float -> string option

val raw : int -> string -> int * string
(** [raw port text] sends [text] as it is and reads the whole answer: (status, body). *)

val request : ?host:string -> ?meth:string -> server -> string -> int * string
(** An HTTP/1.0 request for a path, with [Host] the server's own address by default. *)

type events

val events : server -> events
(** Open the event stream. *)

val close_events : events -> unit

val wait_for :
  events ->
  ?timeout:float ->
  ?seen:(string -> string -> unit) ->
  string ->
  (string -> Yojson.Safe.t -> bool) ->
  string * Yojson.Safe.t
(** [wait_for e what pred] reads events until [pred name data] holds (default timeout 60
    s, then [Failure] naming [what]); [seen] is called on every event read. *)

val member : string -> Yojson.Safe.t -> Yojson.Safe.t
val to_int : Yojson.Safe.t -> int
val to_bool : Yojson.Safe.t -> bool
val to_string : Yojson.Safe.t -> string

val atomic_write : string -> string -> unit
(** Save a file as editors do: a temporary file beside it, then a rename. *)

val find : string -> string -> int option
