(* lancer watch: a local web server showing the scene, re-rendered progressively on every
   save. Two sides share one record: the server (Lwt, on the main domain) and the renderer
   (its own domain, with the render pool). The server asks for a new version by raising
   [wanted] and cancelling the token of the version being rendered, which the render
   polls as any render does (between rows, between tiles and inside them).
   The renderer publishes server-sent events into [outbox] and wakes the server through
   a pipe. *)

open Lancer
module Job_error = Lancer_job.Job_error

exception Cancelled

type params = { quality : Quality.t option; frame : int; play : bool }

type shared = {
  lock : Mutex.t;
  cond : Condition.t;
  wanted : int Atomic.t;  (** the newest version asked for *)
  mutable started : int;  (** the version the renderer last took *)
  mutable current : Cancel.t;  (** the token of that version's render *)
  mutable reload : bool;  (** read the files again *)
  mutable params : params;
  mutable outbox : (string * string) list;  (** (event, JSON data), newest first *)
  mutable images : (int * string) list;
      (** (sequence number, PNG bytes), newest first, a few *)
  mutable inputs : string list;  (** the files to watch *)
  wake_w : Unix.file_descr;
}

let kept_images = 8

let with_lock sh f =
  Mutex.lock sh.lock;
  Fun.protect ~finally:(fun () -> Mutex.unlock sh.lock) f

(* Ask for a new version; [reload] when the files changed. *)
let request sh ?(reload = false) f =
  with_lock sh (fun () ->
      sh.params <- f sh.params;
      if reload then sh.reload <- true;
      Atomic.incr sh.wanted;
      Cancel.cancel sh.current;
      Condition.signal sh.cond)

let wake sh =
  try ignore (Unix.write_substring sh.wake_w "x" 0 1) with Unix.Unix_error _ -> ()

let publish sh ev data =
  with_lock sh (fun () -> sh.outbox <- (ev, Yojson.Safe.to_string data) :: sh.outbox);
  wake sh

(* ---------------------------------------------------------------------------------- *)
(* The renderer *)

(* The PNG bytes of an image, through camlimages and a file in a private directory. *)
let png_bytes tmp (sc : Scene.t) (fb : Image.t) =
  let path = Filename.concat tmp "view.png" in
  match
    Image.write_rgb8 path fb.width fb.height (Image.to_bytes sc.settings.gamma fb)
  with
  | Error m -> failwith m
  | Ok () -> In_channel.with_open_bin path In_channel.input_all

(* One sample per k×k block, at the block's middle pixel: a complete picture of
   ⌈w/k⌉×⌈h/k⌉ pixels with exactly the camera of the full image. Rows go over the pool;
   a newer version stops it at the next row. *)
let coarse_pass pool cancelled (sc : Scene.t) k =
  let w = sc.settings.width and h = sc.settings.height in
  let cw = (w + k - 1) / k and ch = (h + k - 1) / k in
  let fb = Image.create cw ch in
  let stats = Array.init ch (fun _ -> Stats.create ()) in
  let row j =
    if cancelled () then raise Cancelled;
    let py = min (h - 1) ((j * k) + (k / 2)) in
    for i = 0 to cw - 1 do
      Image.set fb i j (Render.pixel sc stats.(j) (min (w - 1) ((i * k) + (k / 2))) py)
    done
  in
  (match pool with
  | None ->
      for j = 0 to ch - 1 do
        row j
      done
  | Some p -> Pool.parallel_for p ch row);
  let total = Stats.create () in
  Array.iter (Stats.add_into total) stats;
  (fb, total)

let full_pass pool cancel sc =
  try Render.render ?pool ~cancel sc
  with Sys.Break when Cancel.cancelled cancel -> raise Cancelled

let knobs (o : Options.t) (sc : Scene.t) =
  let s = sc.settings in
  `Assoc
    [
      ( "quality",
        `String
          (match o.quality with
          | Some q -> Quality.to_string q
          | None -> "the scene's own") );
      ("size", `String (Printf.sprintf "%d×%d" s.width s.height));
      ("samples", `String (Printf.sprintf "%d×%d" s.samples s.samples));
      ( "adaptive",
        `String (if s.adaptive > 0. then Printf.sprintf "%g" s.adaptive else "off") );
      ("depth", `Int s.depth);
    ]

let quality_name = function Some q -> Quality.to_string q | None -> "scene"

(* What watch shows of an error located in a file: all of it for a file in the scene's
   directory tree, and only its file, line, column and message for a file outside it
   (unless [any_line]), so that a scene that includes any file the user may read cannot
   have its lines shown on the page. The tree and the file are taken as the system
   resolves them (symbolic links followed); a file that cannot be resolved is outside. *)
let shown_errors ~any_line scene =
  let root =
    try Some (Unix.realpath (Filename.dirname scene)) with Unix.Unix_error _ -> None
  in
  let inside file =
    match (root, Unix.realpath file) with
    | Some r, p -> p = r || String.starts_with ~prefix:(if r = "/" then r else r ^ "/") p
    | None, _ -> false
    | exception Unix.Unix_error _ -> false
  in
  fun (e : Diagnostic.t) ->
    if any_line || inside e.file then e else { e with source_line = None }

(* The text of an error that ends a version, each located error through [show_error]. *)
let describe show_error e =
  fst
    (Job_error.describe
       (match e with
       | Job_error.Scene { errors; note } ->
           Job_error.Scene { errors = List.map show_error errors; note }
       | e -> e))

(* Load the scene: the program, or the text lancer prints for its errors and the files
   they name (to be watched too). *)
let load show_error path =
  match Scene_file.read (Some path) with
  | exception (Job_error.User _ as e) -> Error (describe show_error e, [])
  | filename, text -> (
      match Program.load_string ~filename text with
      | Ok p -> Ok p
      | Error errs ->
          Error
            ( Job_error.errors_text (List.map show_error errs),
              List.map (fun (e : Diagnostic.t) -> e.file) errs ))

type version = {
  gen : int;
  t0 : float;
  reload : bool;
  params : params;
  cancel : Cancel.t;
}

let log quiet fmt = Printf.ksprintf (fun s -> if not quiet then print_endline s) fmt

let render_version sh show_error (o : Options.t) pool tmp prog seq v =
  let cancelled () = Cancel.cancelled v.cancel in
  let path = Option.get o.scene in
  let failed text files =
    with_lock sh (fun () ->
        sh.inputs <- List.sort_uniq compare ((path :: files) @ sh.inputs));
    publish sh "failure" (`Assoc [ ("text", `String text) ]);
    wake sh;
    if not o.quiet then prerr_string text
  in
  let t_build = Unix.gettimeofday () in
  let loaded =
    match !prog with
    | Some p when not v.reload -> Ok p
    | _ -> (
        match load show_error path with
        | Ok p ->
            prog := Some p;
            with_lock sh (fun () -> sh.inputs <- Program.inputs p);
            wake sh;
            Ok p
        | Error (text, files) ->
            (* The next version, whatever it changes, reads the files again. *)
            prog := None;
            Error (text, files))
  in
  match loaded with
  | Error (text, files) -> failed text files
  | Ok p -> (
      let fps, frames =
        match Program.animation p with Some (fps, n) -> (fps, n) | None -> (24., 1)
      in
      let frame = max 0 (min (frames - 1) v.params.frame) in
      let time = Float.of_int frame /. fps in
      let o = { o with quality = v.params.quality } in
      let coarse_q =
        match o.quality with Some Quality.Draft -> Quality.Draft | _ -> Quality.Preview
      in
      let evaluated =
        let src = Scene_file.source o p in
        try
          let sc = Options.scene_at o src ~time ~frame in
          let coarse =
            Options.scene_at
              { o with quality = Some coarse_q; samples = None }
              src ~time ~frame
          in
          Ok (sc, coarse)
        with (Job_error.User _ | Job_error.Scene _) as e ->
          Error (describe show_error e)
      in
      (* A frame may read files that frame 0 does not (an image chosen by [frame]): they
         are watched from the first version that reads them. *)
      with_lock sh (fun () ->
          sh.inputs <- List.sort_uniq compare (Program.inputs p @ sh.inputs));
      match evaluated with
      | Error text -> failed text []
      | Ok (sc, coarse) ->
          let build = Unix.gettimeofday () -. t_build in
          publish sh "ok" (`Assoc []);
          publish sh "scene"
            (`Assoc
               [
                 ("file", `String path);
                 ("quality", `String (quality_name o.quality));
                 ("frame", `Int frame);
                 ( "animation",
                   match Program.animation p with
                   | Some (fps, n) -> `Assoc [ ("fps", `Float fps); ("frames", `Int n) ]
                   | None -> `Null );
               ]);
          let summary = try Program.summary p sc with _ -> "" in
          let base = Filename.remove_extension (Filename.basename path) in
          let name =
            if frames > 1 then Printf.sprintf "%s_%04d.png" base frame else base ^ ".png"
          in
          let final_differs =
            match o.quality with
            | Some (Quality.Draft | Quality.Preview) -> false
            | _ -> true
          in
          let passes =
            [
              (`Coarse 8, "1 sample per 8×8 pixels");
              (`Coarse 4, "1 sample per 4×4 pixels");
              (`Coarse 2, "1 sample per 2×2 pixels");
              ( `Full coarse,
                if final_differs then Quality.to_string coarse_q ^ " quality" else "done"
              );
            ]
            @ if final_differs && not v.params.play then [ (`Full sc, "done") ] else []
          in
          let n = List.length passes in
          let first = ref None in
          let done_passes = ref [] in
          List.iteri
            (fun idx (pass, label) ->
              let t = Unix.gettimeofday () in
              let shown, fb, st =
                match pass with
                | `Coarse k ->
                    let fb, st = coarse_pass pool cancelled coarse k in
                    (coarse, fb, st)
                | `Full s ->
                    let fb, st = full_pass pool v.cancel s in
                    (s, fb, st)
              in
              let secs = Unix.gettimeofday () -. t in
              if cancelled () then raise Cancelled;
              let bytes = png_bytes tmp shown fb in
              incr seq;
              let s = !seq in
              with_lock sh (fun () ->
                  sh.images <-
                    (s, bytes) :: List.filteri (fun i _ -> i < kept_images - 1) sh.images);
              let last = idx = n - 1 in
              if !first = None then first := Some (Unix.gettimeofday () -. v.t0);
              let pname =
                match pass with
                | `Coarse k -> Printf.sprintf "%d×%d blocks" k k
                | `Full _ when last -> "full image"
                | `Full _ -> label
              in
              done_passes :=
                `Assoc
                  [
                    ("name", `String pname);
                    ("seconds", `Float secs);
                    ("rays", `Int (Stats.total_rays st));
                  ]
                :: !done_passes;
              publish sh "image"
                (`Assoc
                   [
                     ("seq", `Int s);
                     ( "label",
                       `String
                         (if last then
                            Printf.sprintf "%s (%d×%d)" label sc.settings.width
                              sc.settings.height
                          else label) );
                     ("last", `Bool last);
                     ("frame", `Int frame);
                     ("width", `Int sc.settings.width);
                     ("height", `Int sc.settings.height);
                     ("name", `String name);
                   ]);
              if last then (
                let rays = Stats.total_rays st in
                publish sh "stats"
                  (`Assoc
                     [
                       ("build_seconds", `Float build);
                       ("passes", `List (List.rev !done_passes));
                       ( "rays_per_second",
                         `Float (if secs > 0. then Float.of_int rays /. secs else 0.) );
                       ("knobs", knobs o shown);
                       ("summary", `String summary);
                     ]);
                log o.quiet
                  "%s: frame %d, %d×%d: first image %.3f s after the change, full image \
                   %.3f s"
                  path frame sc.settings.width sc.settings.height
                  (Option.value !first ~default:0.)
                  (Unix.gettimeofday () -. v.t0)))
            passes)

let renderer sh show_error (o : Options.t) domains tmp () =
  Render.with_pool domains (fun pool ->
      let prog = ref None and seq = ref 0 in
      let rec loop () =
        let v =
          with_lock sh (fun () ->
              while Atomic.get sh.wanted = sh.started do
                Condition.wait sh.cond sh.lock
              done;
              let gen = Atomic.get sh.wanted in
              sh.started <- gen;
              sh.current <- Cancel.create ();
              let r = sh.reload in
              sh.reload <- false;
              {
                gen;
                t0 = Unix.gettimeofday ();
                reload = r;
                params = sh.params;
                cancel = sh.current;
              })
        in
        (try render_version sh show_error o pool tmp prog seq v with
        | Cancelled -> ()
        | e -> publish sh "failure" (`Assoc [ ("text", `String (describe show_error e)) ]));
        loop ()
      in
      loop ())

(* ---------------------------------------------------------------------------------- *)
(* Watching the files *)

open Lwt.Infix

let split p = (Filename.dirname p, Filename.basename p)

(* Call [changed] (at most every few tens of milliseconds) when a file of [inputs ()]
   is written, replaced or removed: inotify on their directories (an editor that saves
   by renaming replaces the file itself), polling their status twice a second where
   inotify is not available or [poll] asks for it. *)
let watch_files ~poll inputs changed =
  let debounce = ref None in
  let fire () =
    match !debounce with
    | Some _ -> ()
    | None ->
        debounce :=
          Some
            ( Lwt_unix.sleep 0.03 >|= fun () ->
              debounce := None;
              changed () )
  in
  let polling () =
    (* Modification time (to the nanosecond, as an integer), size and inode: a file
       rewritten in place or replaced by a rename. *)
    let stamp p =
      match Unix.stat p with
      | s -> Some (Int64.of_float (s.st_mtime *. 1e9), s.st_size, s.st_ino)
      | exception Unix.Unix_error _ -> None
    in
    let snapshot () = List.map (fun p -> (p, stamp p)) (inputs ()) in
    let rec go last =
      Lwt_unix.sleep 0.5 >>= fun () ->
      let now = snapshot () in
      (* A new input set (after a reload) is a new baseline, except for the files it shares. *)
      let differs =
        List.exists
          (fun (p, s) ->
            match List.assoc_opt p last with Some s' -> s <> s' | None -> false)
          now
      in
      if differs then fire ();
      go now
    in
    go (snapshot ())
  in
  let inotify fd =
    let watched = Hashtbl.create 4 in
    let update () =
      List.iter
        (fun p ->
          let d, _ = split p in
          if not (Hashtbl.mem watched d) then
            match
              Lwt_inotify.add_watch' fd d
                Inotify.[ S_Close_write; S_Moved_to; S_Create; S_Delete; S_Modify ]
            with
            | w -> Hashtbl.replace watched d (Inotify.int_of_watch w)
            | exception Unix.Unix_error _ -> ())
        (inputs ())
    in
    let dir_of w =
      Hashtbl.fold
        (fun d w' acc -> if w' = Inotify.int_of_watch w then Some d else acc)
        watched None
    in
    let rec refresh () =
      update ();
      Lwt_unix.sleep 0.25 >>= refresh
    in
    let rec go () =
      Lwt_inotify.read fd >>= fun (w, kinds, _, name) ->
      let relevant =
        List.mem Inotify.Q_overflow kinds
        ||
        match (dir_of w, name) with
        | Some d, Some n -> List.exists (fun p -> split p = (d, n)) (inputs ())
        | _ -> false
      in
      if relevant then fire ();
      go ()
    in
    Lwt.pick [ refresh (); go () ]
  in
  if poll then polling ()
  else match Lwt_inotify.create' () with fd -> inotify fd | exception _ -> polling ()

(* ---------------------------------------------------------------------------------- *)
(* The server *)

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
let max_streams = 32

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

let run stop (o : Options.t) ~host ~port ~poll ~beyond_loopback ~any_source_line =
  ignore (Report.on_interrupt stop);
  (* A browser that goes away mid-write must not end the server. *)
  Sys.set_signal Sys.sigpipe Sys.Signal_ignore;
  let path =
    match o.scene with
    | Some "-" ->
        Job_error.user
          "watch needs a scene file to watch, not standard input: lancer watch SCENE.rts"
    | Some p -> p
    | None -> Job_error.user "watch needs a scene file: lancer watch SCENE.rts"
  in
  ignore (Scene_file.read o.scene);
  let domains = Options.domains o in
  Option.iter (fun d -> if d < 1 then Job_error.user "--width must be at least 1") o.width;
  Option.iter
    (fun d -> if d < 1 then Job_error.user "--height must be at least 1")
    o.height;
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
  let tmp = Filename.temp_dir "lancer-watch" "" in
  let wake_r, wake_w = Unix.pipe ~cloexec:true () in
  Unix.set_nonblock wake_w;
  let sh =
    {
      lock = Mutex.create ();
      cond = Condition.create ();
      wanted = Atomic.make 1;
      started = 0;
      current = Cancel.create ();
      reload = true;
      params = { quality = o.quality; frame = 0; play = false };
      outbox = [];
      images = [];
      inputs = [ path ];
      wake_w;
    }
  in
  let show_error = shown_errors ~any_line:any_source_line path in
  let worker = Domain.spawn (renderer sh show_error o domains tmp) in
  ignore worker;
  (* What a newly connected page is sent first: the last event of each kind. *)
  let current = Hashtbl.create 8 in
  let streams : (string, int * (string option -> unit)) Hashtbl.t = Hashtbl.create 8 in
  let opened = ref 0 in
  let sse ev data = Printf.sprintf "event: %s\ndata: %s\n\n" ev data in
  let deliver (ev, data) =
    (match ev with "ok" -> Hashtbl.remove current "failure" | _ -> ());
    Hashtbl.replace current ev data;
    let msg = Some (sse ev data) in
    Hashtbl.iter (fun _ (_, push) -> try push msg with Lwt_stream.Closed -> ()) streams
  in
  let pump () =
    let buf = Bytes.create 256 in
    let fd = Lwt_unix.of_unix_file_descr ~blocking:false wake_r in
    let rec go () =
      Lwt_unix.read fd buf 0 256 >>= fun _ ->
      let evs =
        with_lock sh (fun () ->
            let e = List.rev sh.outbox in
            sh.outbox <- [];
            e)
      in
      List.iter deliver evs;
      go ()
    in
    go ()
  in
  let rec keepalive () =
    Lwt_unix.sleep 15. >>= fun () ->
    Hashtbl.iter
      (fun _ (_, push) ->
        try push (Some ": keep-alive\n\n") with Lwt_stream.Closed -> ())
      streams;
    keepalive ()
  in
  let text ?(close = false) status s =
    Server.respond_string
      ~headers:
        (Cohttp.Header.of_list
           (("content-type", "text/plain; charset=utf-8")
           :: (if close then [ ("connection", "close") ] else [])))
      ~status ~body:s ()
  in
  (* A request refused is answered before its body is read, and its connection closed
     after the answer: nothing more is read from it. *)
  let refuse (l : link) status s =
    l.done_reading <- true;
    text ~close:true status s
  in
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
  let admit (l : link) (req : Cohttp.Request.t) =
    let headers = Cohttp.Request.headers req in
    let all k = Cohttp.Header.get_multi headers k in
    let own = "http://" ^ authority in
    let page =
      Cohttp.Request.meth req = `GET && Uri.path (Cohttp.Request.uri req) = "/"
    in
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
  in
  (* The answer to a request admitted. *)
  let route conn (req : Cohttp.Request.t) =
    let meth = Cohttp.Request.meth req in
    let target = Uri.path (Cohttp.Request.uri req) in
    match (meth, target) with
    | `GET, "/" ->
        Server.respond_string
          ~headers:
            (Cohttp.Header.of_list
               [
                 ("content-type", "text/html; charset=utf-8");
                 ("cache-control", "no-store");
                 ("content-security-policy", "frame-ancestors 'none'");
                 ("x-frame-options", "DENY");
               ])
          ~status:`OK ~body:Watch_page.html ()
    | `GET, "/events" ->
        (if Hashtbl.length streams >= max_streams then
           let oldest =
             Hashtbl.fold
               (fun k (n, _) acc ->
                 match acc with Some (_, m) when m <= n -> acc | _ -> Some (k, n))
               streams None
           in
           Option.iter
             (fun (k, _) ->
               (try (snd (Hashtbl.find streams k)) None with Lwt_stream.Closed -> ());
               Hashtbl.remove streams k)
             oldest);
        let stream, push = Lwt_stream.create () in
        let key = Cohttp.Connection.to_string conn in
        incr opened;
        Hashtbl.replace streams key (!opened, push);
        List.iter
          (fun ev ->
            Option.iter (fun d -> push (Some (sse ev d))) (Hashtbl.find_opt current ev))
          [ "scene"; "image"; "stats"; "failure" ];
        Server.respond ~flush:true
          ~headers:
            (Cohttp.Header.of_list
               [ ("content-type", "text/event-stream"); ("cache-control", "no-store") ])
          ~status:`OK
          ~body:(Cohttp_lwt.Body.of_stream stream)
          ()
    | `GET, p
      when String.length p > 11
           && String.sub p 0 7 = "/image/"
           && Filename.check_suffix p ".png" -> (
        let n = String.sub p 7 (String.length p - 11) in
        match int_of_string_opt n with
        | Some k when String.for_all (fun c -> c >= '0' && c <= '9') n -> (
            match with_lock sh (fun () -> List.assoc_opt k sh.images) with
            | Some bytes ->
                Server.respond_string
                  ~headers:
                    (Cohttp.Header.of_list
                       [ ("content-type", "image/png"); ("cache-control", "no-store") ])
                  ~status:`OK ~body:bytes ()
            | None -> text `Not_found "no such image (a newer one replaced it)\n")
        | _ -> text `Not_found "not found\n")
    | `POST, "/control" -> (
        let uri = Cohttp.Request.uri req in
        let quality =
          match Uri.get_query_param uri "quality" with
          | None -> Ok None
          | Some "scene" -> Ok (Some None)
          | Some q -> (
              match List.assoc_opt q Quality.all with
              | Some q -> Ok (Some (Some q))
              | None -> Error q)
        in
        let frame = Option.map int_of_string_opt (Uri.get_query_param uri "frame") in
        match (quality, frame) with
        | Error q, _ -> text `Bad_request (Printf.sprintf "unknown quality %S\n" q)
        | _, Some None -> text `Bad_request "frame must be a whole number\n"
        | Ok q, f ->
            let play = Uri.get_query_param uri "play" = Some "1" in
            request sh (fun p ->
                {
                  quality = Option.value q ~default:p.quality;
                  frame = (match f with Some (Some k) -> max 0 k | _ -> p.frame);
                  play;
                });
            text `No_content "")
    | (`GET | `POST), _ -> text `Not_found "not found\n"
    | _ -> text `Method_not_allowed "method not allowed\n"
  in
  let callback ((l : link), conn) (req : Cohttp.Request.t) body =
    (* A complete head: from now on the server is the one working. *)
    l.in_head <- false;
    l.deadline <- infinity;
    match admit l req with
    | Some (status, why) -> refuse l status why
    | None -> Cohttp_lwt.Body.drain_body body >>= fun () -> route conn req
  in
  let conn_closed (_, conn) =
    let key = Cohttp.Connection.to_string conn in
    match Hashtbl.find_opt streams key with
    | Some (_, push) -> (
        Hashtbl.remove streams key;
        try push None with Lwt_stream.Closed -> ())
    | None -> ()
  in
  let stop, stopper = Lwt.wait () in
  let on_signal _ = if Lwt.is_sleeping stop then Lwt.wakeup_later stopper () in
  let sigs =
    List.map (fun s -> Lwt_unix.on_signal s on_signal) [ Sys.sigint; Sys.sigterm ]
  in
  let changed () = request sh ~reload:true Fun.id in
  let inputs () = with_lock sh (fun () -> sh.inputs) in
  Printf.printf "lancer watch: http://%s/ shows %s (Ctrl-C to stop)\n%!" authority path;
  let server = serve sock (Server.make ~conn_closed ~callback ()) in
  Fun.protect
    ~finally:(fun () ->
      List.iter Lwt_unix.disable_signal_handler sigs;
      try
        Array.iter (fun f -> Sys.remove (Filename.concat tmp f)) (Sys.readdir tmp);
        Sys.rmdir tmp
      with Sys_error _ -> ())
    (fun () ->
      Lwt_main.run
        (Lwt.pick
           [ server; stop; pump (); keepalive (); watch_files ~poll inputs changed ]);
      raise Sys.Break)

open Cmdliner

let cmd =
  let doc = "show a scene in the browser, re-rendered progressively on every save" in
  let scene =
    Arg.(
      required
      & pos 0 (some string) None
      & info [] ~docv:"SCENE.rts" ~doc:"The scene to show.")
  in
  let port =
    Arg.(
      value & opt int 8123
      & info [ "port"; "p" ] ~docv:"N" ~doc:"The port to listen on; 0 picks a free one.")
  in
  let host =
    Arg.(
      value & opt string "127.0.0.1"
      & info [ "host" ] ~docv:"ADDR"
          ~doc:
            "The address to listen on: one IP address, never a wildcard such as \
             $(b,0.0.0.0), $(b,::) or $(b,::ffff:0.0.0.0). Without \
             $(b,--listen-beyond-loopback) it must be a loopback address \
             ($(b,127.0.0.0/8), $(b,::1), or $(b,::ffff:127.x.y.z)). The server answers \
             only requests addressed to it (their Host header), so a foreign web page \
             cannot reach it by a renamed domain.")
  in
  let beyond_loopback =
    Arg.(
      value & flag
      & info [ "listen-beyond-loopback" ]
          ~doc:
            "Allow a $(b,--host) that is not a loopback address. The preview asks for no \
             password: anyone who can reach that address can watch the scene, its \
             errors, and switch its quality.")
  in
  let any_source_line =
    Arg.(
      value & flag
      & info [ "show-lines-outside" ]
          ~doc:
            "Show the source line of an error in any file. By default, an error in a \
             file outside the scene's directory tree (reached by $(b,..), an absolute \
             path or a symbolic link) is shown as its file, line, column and message \
             only, without the line's text, on the page and in the terminal.")
  in
  let poll =
    Arg.(
      value & flag
      & info [ "poll" ]
          ~doc:
            "Look for changes by polling the files' status twice a second instead of \
             inotify (network file systems).")
  in
  let int_opt names docv doc =
    Arg.(value & opt (some int) None & info names ~docv ~doc)
  in
  let width =
    int_opt [ "width"; "W" ] "W" "Image width in pixels (overrides the scene)."
  in
  let height =
    int_opt [ "height"; "H" ] "H" "Image height in pixels (overrides the scene)."
  in
  let samples = int_opt [ "samples" ] "N" "N×N samples per pixel for the full image." in
  let depth = int_opt [ "depth" ] "D" "Maximum ray depth." in
  let domains = int_opt [ "domains"; "j" ] "N" "Domains (cores) to render with." in
  let quality =
    Arg.(
      value
      & opt (some (enum Quality.all)) None
      & info [ "quality" ] ~docv:"PRESET"
          ~doc:
            "The preset of the full image: $(b,draft), $(b,preview), $(b,final) or \
             $(b,reference) (the page can switch it).")
  in
  let quiet = Arg.(value & flag & info [ "q"; "quiet" ] ~doc:"Print only the address.") in
  let man =
    [
      `S Manpage.s_description;
      `P
        "Starts a web server on this machine and prints its address. The page shows the \
         scene, first coarse (one sample every 8, 4, then 2 pixels), then at preview \
         quality, then at the chosen quality, each image replacing the last. Saving the \
         scene, or any file it includes or loads, renders it again and cancels the \
         render in progress; a scene error is shown over the last good image until the \
         file is fixed. An animation gets a time slider and play/pause. The page shows \
         what the render cost and can switch the quality preset. It writes no output \
         file (frames are the job of $(b,animate)); the page has a button that saves the \
         current view as a PNG.";
      `P
        "The server listens on one loopback address unless $(b,--listen-beyond-loopback) \
         says otherwise, answers only requests addressed to it and, from a browser, only \
         those of its own page, and bounds what a client may cost: 16 KiB of request \
         headers, 4 KiB of body, 10 seconds to send a complete request (or to take an \
         answer being written), 64 connections at once (past them, the one that has \
         waited longest for its request is closed).";
      `S Manpage.s_examples;
      `Pre "  lancer watch scenes/showcase.rts";
      `Pre "  lancer watch scene.rts --port 9000 --quality final --width 640 --height 480";
    ]
  in
  let term =
    Term.(
      const
        (fun
          scene
          port
          host
          beyond_loopback
          any_source_line
          poll
          width
          height
          samples
          depth
          domains
          quality
          quiet
        ->
          let o =
            {
              Options.default with
              scene = Some scene;
              width;
              height;
              samples;
              depth;
              domains;
              quality;
              quiet;
            }
          in
          Report.run ~interrupted:"the preview server stopped" (fun stop ->
              run stop o ~host ~port ~poll ~beyond_loopback ~any_source_line))
      $ scene $ port $ host $ beyond_loopback $ any_source_line $ poll $ width $ height
      $ samples $ depth $ domains $ quality $ quiet)
  in
  Cmd.v (Cmd.info "watch" ~doc ~man ~exits:Cli.exits) term
