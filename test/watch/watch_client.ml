type server = {
  pid : int;
  port : int;
  out : in_channel;
  dir : string;
  mutable log : string list;
}

let now = Unix.gettimeofday

(* Read a line from [ic] within [timeout] seconds. *)
let input_line_within ic timeout =
  let fd = Unix.descr_of_in_channel ic in
  let deadline = now () +. timeout in
  let buf = Buffer.create 80 in
  let rec go () =
    let left = deadline -. now () in
    if left <= 0. then None
    else
      match Unix.select [ fd ] [] [] left with
      | [], _, _ -> None
      | _ -> (
          let b = Bytes.create 1 in
          match Unix.read fd b 0 1 with
          | 0 -> None
          | _ when Bytes.get b 0 = '\n' -> Some (Buffer.contents buf)
          | _ ->
              Buffer.add_char buf (Bytes.get b 0);
              go ())
      | exception Unix.Unix_error (Unix.EINTR, _, _) -> go ()
  in
  go ()

let start ~exe ~dir args =
  let r, w = Unix.pipe ~cloexec:true () in
  let err =
    Unix.openfile
      (Filename.concat dir "watch.err")
      [ O_WRONLY; O_CREAT; O_TRUNC; O_CLOEXEC ]
      0o644
  in
  let devnull = Unix.openfile "/dev/null" [ O_RDONLY; O_CLOEXEC ] 0 in
  let cwd = Sys.getcwd () in
  Sys.chdir dir;
  let pid =
    Fun.protect
      ~finally:(fun () -> Sys.chdir cwd)
      (fun () ->
        Unix.create_process exe
          (Array.of_list ((exe :: "watch" :: args) @ [ "--port"; "0" ]))
          devnull w err)
  in
  Unix.close w;
  Unix.close err;
  Unix.close devnull;
  let out = Unix.in_channel_of_descr r in
  match input_line_within out 60. with
  | None -> failwith "lancer watch printed no address within 60 s"
  | Some line -> (
      match Scanf.sscanf_opt line "lancer watch: http://127.0.0.1:%d/" Fun.id with
      | Some port -> { pid; port; out; dir; log = [] }
      | None -> failwith ("unexpected first line: " ^ line))

let stderr_text s =
  try In_channel.with_open_bin (Filename.concat s.dir "watch.err") In_channel.input_all
  with Sys_error _ -> ""

let stop s =
  (try Unix.kill s.pid Sys.sigint with Unix.Unix_error _ -> ());
  let deadline = now () +. 30. in
  let rec wait () =
    match Unix.waitpid [ Unix.WNOHANG ] s.pid with
    | 0, _ when now () < deadline ->
        Unix.sleepf 0.05;
        wait ()
    | 0, _ ->
        Unix.kill s.pid Sys.sigkill;
        snd (Unix.waitpid [] s.pid)
    | _, st -> st
    | exception Unix.Unix_error (Unix.EINTR, _, _) -> wait ()
  in
  let st = wait () in
  close_in_noerr s.out;
  st

let connect port =
  let fd = Unix.socket PF_INET SOCK_STREAM 0 in
  Unix.connect fd (ADDR_INET (Unix.inet_addr_loopback, port));
  Unix.setsockopt_float fd SO_RCVTIMEO 60.;
  fd

let send_all fd s =
  let rec go off =
    if off < String.length s then
      go (off + Unix.write_substring fd s off (String.length s - off))
  in
  go 0

let read_all fd =
  let buf = Buffer.create 4096 and b = Bytes.create 65536 in
  let rec go () =
    match Unix.read fd b 0 (Bytes.length b) with
    | 0 -> ()
    | n ->
        Buffer.add_subbytes buf b 0 n;
        go ()
    | exception Unix.Unix_error ((Unix.EAGAIN | Unix.ECONNRESET), _, _) -> ()
  in
  go ();
  Buffer.contents buf

let find s sub =
  let n = String.length s and m = String.length sub in
  let rec go i =
    if i + m > n then None else if String.sub s i m = sub then Some i else go (i + 1)
  in
  go 0

let raw port text =
  let fd = connect port in
  Fun.protect
    ~finally:(fun () -> Unix.close fd)
    (fun () ->
      send_all fd text;
      let resp = read_all fd in
      let status =
        match Scanf.sscanf_opt resp "HTTP/1.%d %d" (fun _ c -> c) with
        | Some c -> c
        | None -> 0
      in
      let body =
        match find resp "\r\n\r\n" with
        | Some i -> String.sub resp (i + 4) (String.length resp - i - 4)
        | None -> ""
      in
      (status, body))

let request ?host ?(meth = "GET") s path =
  let host = Option.value host ~default:(Printf.sprintf "127.0.0.1:%d" s.port) in
  raw s.port (Printf.sprintf "%s %s HTTP/1.0\r\nHost: %s\r\n\r\n" meth path host)

type events = { fd : Unix.file_descr; buf : Buffer.t }

let events s =
  let fd = connect s.port in
  send_all fd (Printf.sprintf "GET /events HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" s.port);
  { fd; buf = Buffer.create 4096 }

let close_events e = Unix.close e.fd

(* The next complete "event: …\ndata: …\n\n" in the stream (chunk-size lines of the
   chunked encoding lie between events and are skipped). *)
let rec next_event e ~deadline =
  let text = Buffer.contents e.buf in
  let take i j =
    let rest = String.sub text j (String.length text - j) in
    Buffer.clear e.buf;
    Buffer.add_string e.buf rest;
    String.sub text i (j - i)
  in
  match find text "event: " with
  | Some i -> (
      match find (String.sub text i (String.length text - i)) "\n\n" with
      | Some k ->
          let block = take i (i + k + 2) in
          let lines = String.split_on_char '\n' block in
          let field p =
            List.find_map
              (fun l ->
                if String.starts_with ~prefix:p l then
                  Some
                    (String.sub l (String.length p) (String.length l - String.length p))
                else None)
              lines
          in
          Some (Option.get (field "event: "), Option.value (field "data: ") ~default:"")
      | None -> more e ~deadline)
  | None -> more e ~deadline

and more e ~deadline =
  let left = deadline -. now () in
  if left <= 0. then None
  else
    match Unix.select [ e.fd ] [] [] left with
    | [], _, _ -> None
    | _ -> (
        let b = Bytes.create 65536 in
        match Unix.read e.fd b 0 65536 with
        | 0 -> None
        | n ->
            Buffer.add_subbytes e.buf b 0 n;
            next_event e ~deadline)
    | exception Unix.Unix_error (Unix.EINTR, _, _) -> more e ~deadline

let wait_for e ?(timeout = 60.) ?(seen = fun _ _ -> ()) what pred =
  let deadline = now () +. timeout in
  let rec go () =
    match next_event e ~deadline with
    | None -> failwith (Printf.sprintf "no %s within %.0f s" what timeout)
    | Some (ev, data) ->
        seen ev data;
        let j = try Yojson.Safe.from_string data with _ -> `Null in
        if pred ev j then (ev, j) else go ()
  in
  go ()

let member k j =
  match j with
  | `Assoc l -> ( match List.assoc_opt k l with Some v -> v | None -> `Null)
  | _ -> `Null

let to_int = function `Int n -> n | _ -> -1
let to_bool = function `Bool b -> b | _ -> false
let to_string = function `String s -> s | _ -> ""

let atomic_write path text =
  let tmp = path ^ ".saving" in
  Out_channel.with_open_bin tmp (fun oc -> output_string oc text);
  Unix.rename tmp path
