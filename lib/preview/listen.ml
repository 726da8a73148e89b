(* Where lancer watch listens: one address, checked, and its socket. *)

open Lancer

(* Where an address listens: every address of the machine (a wildcard, however it is
   written, IPv4-mapped included), the loopback interface only (127.0.0.0/8, ::1, and
   127.x.y.z mapped into IPv6), or beyond it. *)
type reach = Everywhere | Loopback | Beyond

(* The eight 16-bit groups of an IPv6 address written as inet_ntop writes it ("::" for
   a run of zeros, a dotted IPv4 address at the end). *)
let ipv6_groups s =
  let groups part =
    if part = "" then []
    else
      List.concat_map
        (fun g ->
          if String.contains g '.' then
            match
              Scanf.sscanf_opt g "%u.%u.%u.%u%!" (fun a b c d ->
                  [ (a lsl 8) lor b; (c lsl 8) lor d ])
            with
            | Some l -> l
            | None -> invalid_arg g
          else [ int_of_string ("0x" ^ g) ])
        (String.split_on_char ':' part)
  in
  let n = String.length s in
  let rec double i =
    if i + 1 >= n then None else if String.sub s i 2 = "::" then Some i else double (i + 1)
  in
  match double 0 with
  | None -> groups s
  | Some i ->
      let a = groups (String.sub s 0 i)
      and b = groups (String.sub s (i + 2) (n - i - 2)) in
      a @ List.init (8 - List.length a - List.length b) (fun _ -> 0) @ b

(* An address to listen on and where it listens. An IPv4 address mapped into IPv6 is
   given as the IPv4 address itself: a socket bound to either takes the same
   connections, and a browser names it by its IPv4 form (its Host header). *)
let listen_address addr =
  let v4 s =
    match Scanf.sscanf_opt s "%u.%u.%u.%u%!" (fun a b c d -> (a, b, c, d)) with
    | Some (0, 0, 0, 0) -> Everywhere
    | Some (127, _, _, _) -> Loopback
    | _ -> Beyond
  in
  let s = Unix.string_of_inet_addr addr in
  match Unix.domain_of_sockaddr (Unix.ADDR_INET (addr, 0)) with
  | Unix.PF_INET -> (addr, v4 s)
  | _ -> (
      match ipv6_groups s with
      | [ 0; 0; 0; 0; 0; 0; 0; 0 ] -> (addr, Everywhere)
      | [ 0; 0; 0; 0; 0; 0; 0; 1 ] -> (addr, Loopback)
      | [ 0; 0; 0; 0; 0; 0xffff; hi; lo ] ->
          let s =
            Printf.sprintf "%d.%d.%d.%d" (hi lsr 8) (hi land 255) (lo lsr 8) (lo land 255)
          in
          (Unix.inet_addr_of_string s, v4 s)
      | _ -> (addr, Beyond)
      | exception (Invalid_argument _ | Failure _) -> (addr, Beyond))

let socket ~host ~port ~beyond_loopback =
  let addr, reach =
    match Unix.inet_addr_of_string host with
    | a -> listen_address a
    | exception Failure _ -> Job_error.user "--host must be an IP address (got %S)" host
  in
  (match reach with
  | Everywhere ->
      Job_error.user
        "--host must be one address of this machine, not %s (every address): the server \
         answers only requests addressed to it"
        host
  | Beyond when not beyond_loopback ->
      Job_error.user
        "--host %s is not a loopback address: the preview, which asks for no password, \
         would be open to other machines; add --listen-beyond-loopback to mean that"
        host
  | Loopback | Beyond -> ());
  let sock =
    Lwt_unix.socket
      (Unix.domain_of_sockaddr (Unix.ADDR_INET (addr, 0)))
      Unix.SOCK_STREAM 0
  in
  Lwt_unix.setsockopt sock Unix.SO_REUSEADDR true;
  (try Unix.bind (Lwt_unix.unix_file_descr sock) (Unix.ADDR_INET (addr, port))
   with Unix.Unix_error (e, _, _) ->
     Job_error.user "cannot listen on %s:%d: %s" host port (Unix.error_message e));
  Lwt_unix.listen sock 64;
  let port =
    match Unix.getsockname (Lwt_unix.unix_file_descr sock) with
    | Unix.ADDR_INET (_, p) -> p
    | _ -> port
  in
  (* The address as a browser writes it in the Host header: its canonical form. *)
  let authority =
    let a = Unix.string_of_inet_addr addr in
    match Unix.domain_of_sockaddr (Unix.ADDR_INET (addr, 0)) with
    | Unix.PF_INET6 -> Printf.sprintf "[%s]:%d" a port
    | _ -> Printf.sprintf "%s:%d" a port
  in
  (sock, authority)
