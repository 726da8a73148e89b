(* lancer watch's HTTP server: cohttp's, over Lwt's channels, on connections it accepts
   itself, with what one connection may cost and who may ask. *)

open Lwt.Infix

(* What one connection may cost the server. The page's own requests are a few hundred
   bytes of headers and no body (the controls carry their arguments in the query). *)

(* The request line and headers of one request, together: past this, 431. *)
let max_head_bytes = 16 * 1024

(* A request body: past this, 413 before any of it is read. *)
let max_body_bytes = 4096

(* Seconds a connection may take to send a complete request (from its first byte, or from
   the end of the last answer on a kept-alive connection), and a write of an answer may
   wait for the client to read: then the connection is closed. An open event stream is
   not idle: it waits for the server, not for the client. *)
let idle_timeout = 10.

(* Connections served at once. A new one past this closes the one that has waited
   longest for its request; when none is waiting, the next is accepted only once one
   ends (the open answers are bounded by [idle_timeout] or are event streams, bounded by
   [max_streams]). *)
let max_connections = 64

(* One accepted connection, and where its current request is. *)
type link = {
  fd : Lwt_unix.file_descr;
  ic : Lwt_io.input_channel;
  oc : Lwt_io.output_channel;
  order : int;  (** accepted n-th *)
  mutable in_head : bool;
      (** reading a request line and headers: waiting for the client *)
  mutable head_left : int;  (** the bytes this request's head may still take *)
  mutable too_large : bool;  (** this request's head went past [max_head_bytes] *)
  mutable done_reading : bool;  (** refused or cut: nothing more is read from it *)
  mutable deadline : float;
      (** closed when this passes; [infinity] while the server works *)
}

(* Close a connection now, both ways: a read or a write in progress on it ends. *)
let cut l =
  l.done_reading <- true;
  l.deadline <- infinity;
  try Lwt_unix.shutdown l.fd Unix.SHUTDOWN_ALL with Unix.Unix_error _ -> ()

(* cohttp's server over Lwt's channels, on connections the watch accepts itself. cohttp's
   Unix binding would accept them through conduit, whose TLS module opens the system's
   certificate store as the program starts: some 50 M instructions (15 ms) in every
   lancer command, for a server that speaks plain HTTP to one machine. Reading a line
   here is bounded by what is left of the request's head, and reading stops for good on
   a connection refused or cut. *)
module Io = struct
  type 'a t = 'a Lwt.t

  let ( >>= ) = Lwt.bind
  let return = Lwt.return

  type ic = link
  type oc = link
  type conn = link
  type error = exn

  (* A peer gone or a channel closed under a read is the end of its input. *)
  let gone = function
    | Lwt_io.Channel_closed _ | Unix.Unix_error _ | End_of_file -> true
    | _ -> false

  (* A request's head starts with its first line: its budget and its deadline. *)
  let start_head l =
    if not l.in_head then (
      l.in_head <- true;
      l.head_left <- max_head_bytes;
      l.deadline <- Unix.gettimeofday () +. idle_timeout)

  (* A line without its "\n" (nor a "\r" before it), as [Lwt_io.read_line_opt] reads it,
     but one byte at a time against the head's budget: past it, the end of the input. *)
  let read_line l =
    if l.done_reading then Lwt.return_none
    else (
      start_head l;
      let buf = Buffer.create 128 in
      let line () =
        let n = Buffer.length buf in
        if n > 0 && Buffer.nth buf (n - 1) = '\r' then Buffer.sub buf 0 (n - 1)
        else Buffer.contents buf
      in
      let rec go () =
        Lwt_io.read_char l.ic >>= fun c ->
        l.head_left <- l.head_left - 1;
        if l.head_left < 0 then (
          l.too_large <- true;
          l.done_reading <- true;
          Lwt.return_none)
        else if c = '\n' then Lwt.return_some (line ())
        else (
          Buffer.add_char buf c;
          go ())
      in
      Lwt.catch go (fun e ->
          if gone e then
            Lwt.return (if Buffer.length buf = 0 then None else Some (line ()))
          else Lwt.reraise e))

  let read l n =
    if l.done_reading then Lwt.return ""
    else
      Lwt.catch
        (fun () -> Lwt_io.read ~count:(min n max_body_bytes) l.ic)
        (fun e -> if gone e then Lwt.return "" else Lwt.reraise e)

  (* A write may wait [idle_timeout] for the client to take it. *)
  let timed l f =
    let before = l.deadline in
    l.deadline <- Float.min before (Unix.gettimeofday () +. idle_timeout);
    Lwt.finalize f (fun () ->
        if not l.done_reading then l.deadline <- before;
        Lwt.return_unit)

  let write l s = timed l (fun () -> Lwt_io.write l.oc s)
  let flush l = timed l (fun () -> Lwt_io.flush l.oc)

  (* What the server is told a failed write was: it then drops the connection. *)
  let catch f =
    Lwt.try_bind f Lwt.return_ok (fun e ->
        if gone e then Lwt.return_error e else Lwt.reraise e)

  let pp_error ppf e = Format.pp_print_string ppf (Printexc.to_string e)
end

module Server = Cohttp_lwt.Make_server (Io)

(* The answer to a request line past [max_head_bytes], which cohttp never sees. *)
let head_too_large =
  let body = "request headers too large\n" in
  Printf.sprintf
    "HTTP/1.1 431 Request Header Fields Too Large\r\n\
     content-type: text/plain; charset=utf-8\r\n\
     content-length: %d\r\n\
     connection: close\r\n\
     \r\n\
     %s"
    (String.length body) body

(* Each connection accepted on [sock], served by [spec] until either side ends it, then
   closed; what goes wrong with one of them ends only that one. Past [max_connections],
   or out of descriptors, the connection that has waited longest for its request is
   closed to make room. A connection that failed before it was accepted is skipped; out
   of descriptors or memory, the server waits a tenth of a second for some to be given
   back, rather than stop. Every half second the connections past their deadline are
   closed. Only a listening socket that is no longer one ends it; the socket is closed
   when the server ends. *)
let serve sock spec =
  let close ch = Lwt.catch (fun () -> Lwt_io.close ch) (fun _ -> Lwt.return_unit) in
  let links : (int, link) Hashtbl.t = Hashtbl.create 64 in
  let accepted = ref 0 in
  let live () = Hashtbl.fold (fun _ l n -> if l.done_reading then n else n + 1) links 0 in
  let longest_waiting () =
    Hashtbl.fold
      (fun _ l acc ->
        if l.in_head && not l.done_reading then
          match acc with Some m when m.order < l.order -> acc | _ -> Some l
        else acc)
      links None
  in
  let make_room () = Option.iter cut (longest_waiting ()) in
  let connection (fd, _peer) =
    incr accepted;
    let l =
      {
        fd;
        ic = Lwt_io.of_fd ~mode:Lwt_io.input fd;
        oc = Lwt_io.of_fd ~mode:Lwt_io.output fd;
        order = !accepted;
        in_head = false;
        head_left = max_head_bytes;
        too_large = false;
        done_reading = false;
        deadline = infinity;
      }
    in
    Io.start_head l;
    Hashtbl.replace links l.order l;
    if live () > max_connections then make_room ();
    Lwt.async (fun () ->
        Lwt.finalize
          (fun () ->
            Lwt.catch
              (fun () ->
                Server.callback spec l l l >>= fun () ->
                if l.too_large then
                  Io.catch (fun () -> Io.write l head_too_large >>= fun () -> Io.flush l)
                  >|= ignore
                else Lwt.return_unit)
              (fun _ -> Lwt.return_unit))
          (fun () ->
            (* Closing flushes what is left to send: within the deadline too. *)
            l.deadline <- Float.min l.deadline (Unix.gettimeofday () +. idle_timeout);
            close l.oc >>= fun () ->
            close l.ic >|= fun () -> Hashtbl.remove links l.order))
  in
  let rec accept () =
    if live () >= max_connections && longest_waiting () = None then
      Lwt_unix.sleep 0.1 >>= accept
    else
      Lwt.try_bind
        (fun () -> Lwt_unix.accept ~cloexec:true sock)
        (fun c ->
          connection c;
          accept ())
        (function
          | Lwt.Canceled as e -> Lwt.reraise e
          | Unix.Unix_error ((EBADF | EINVAL | ENOTSOCK), _, _) as e -> Lwt.reraise e
          | Unix.Unix_error ((EMFILE | ENFILE | ENOBUFS | ENOMEM), _, _) ->
              make_room ();
              Lwt_unix.sleep 0.1 >>= accept
          | _ ->
              (* A connection that failed before it was accepted (the network errors
                 accept(2) passes on) or a signal: the next one. *)
              Lwt.pause () >>= accept)
  in
  let rec expire () =
    Lwt_unix.sleep 0.5 >>= fun () ->
    let now = Unix.gettimeofday () in
    Hashtbl.iter (fun _ l -> if l.deadline < now then cut l) links;
    expire ()
  in
  Lwt.finalize
    (fun () -> Lwt.pick [ accept (); expire () ])
    (fun () -> Lwt.catch (fun () -> Lwt_unix.close sock) (fun _ -> Lwt.return_unit))

(* Open event streams are bounded: past this many, the oldest is closed (a page that is
   still there reconnects by itself; a closed browser tab may be noticed only later). *)

type response = Cohttp.Response.t * Cohttp_lwt.Body.t

let respond = Server.respond
let respond_string = Server.respond_string

let text ?(close = false) status s =
  Server.respond_string
    ~headers:
      (Cohttp.Header.of_list
         (("content-type", "text/plain; charset=utf-8")
         :: (if close then [ ("connection", "close") ] else [])))
    ~status ~body:s ()

(* A request refused is answered before its body is read, and its connection closed
   after the answer: nothing more is read from it. *)
let refuse (l : link) status s =
  l.done_reading <- true;
  text ~close:true status s

(* Who may ask what, checked on every request in this order:
   - its head within [max_head_bytes], or 431;
   - exactly one Host header (400 for more), and it is this server's own address
     (403), so that a page elsewhere cannot reach the server through a domain
     renamed to 127.0.0.1;
   - a browser says where a request comes from. An Origin header (at most one, 400
     for more) must be this server's own, on every path (403). A Sec-Fetch-Site
     header must be "same-origin" (403), except for the page itself at "/", which a
     link or a typed address may open: it holds nothing, and may not be framed. A
     request with neither comes from a program on this machine, not from a page, and
     is answered;
   - a body of at most [max_body_bytes] with its length given (413, or 411 for one
     without), though no path takes one;
   all of it before any byte of the body is read. *)
let admit ~authority (l : link) (req : Cohttp.Request.t) =
  let headers = Cohttp.Request.headers req in
  let all k = Cohttp.Header.get_multi headers k in
  let own = "http://" ^ authority in
  let page = Cohttp.Request.meth req = `GET && Uri.path (Cohttp.Request.uri req) = "/" in
  if l.too_large then (
    l.too_large <- false;
    Some (`Request_header_fields_too_large, "request headers too large\n"))
  else
    match (all "host", all "origin", all "sec-fetch-site") with
    | _ :: _ :: _, _, _ | _, _ :: _ :: _, _ ->
        Some (`Bad_request, "one Host and at most one Origin header, please\n")
    | h, _, _ when h <> [ authority ] ->
        Some (`Forbidden, "this server answers only to its own address\n")
    | _, [ org ], _ when org <> own -> Some (`Forbidden, "foreign origin\n")
    | _, _, sites when (not page) && List.exists (fun s -> s <> "same-origin") sites ->
        Some (`Forbidden, "only the page of this server may ask for this\n")
    | _ -> (
        match (all "transfer-encoding", all "content-length") with
        | _ :: _, _ -> Some (`Length_required, "a body needs its length\n")
        | [], [] -> None
        | [], [ n ]
          when n <> ""
               && String.length n <= 9
               && String.for_all (fun c -> c >= '0' && c <= '9') n ->
            if int_of_string n > max_body_bytes then
              Some (`Request_entity_too_large, "request body too large\n")
            else None
        | [], _ -> Some (`Bad_request, "one Content-Length, a number, please\n"))

let run ~authority ~route ~conn_closed sock =
  let callback ((l : link), conn) (req : Cohttp.Request.t) body =
    (* A complete head: from now on the server is the one working. *)
    l.in_head <- false;
    l.deadline <- infinity;
    match admit ~authority l req with
    | Some (status, why) -> refuse l status why
    | None -> Cohttp_lwt.Body.drain_body body >>= fun () -> route conn req
  in
  let conn_closed (_, conn) = conn_closed conn in
  serve sock (Server.make ~conn_closed ~callback ())
