(* lancer watch: a local web server showing the scene, rendered again in passes on every
   save (Versions), the files watched (File_watch), the server's bounds (Http). *)

open Lancer
open Lwt.Infix

(* Open event streams are bounded: past this many, the oldest is closed (a page that is
   still there reconnects by itself; a closed browser tab may be noticed only later). *)
let max_streams = 32

let run ?max_error (o : Options.t) ~host ~port ~poll ~beyond_loopback ~any_source_line =
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
  Option.iter
    (fun m ->
      Budget.check m;
      Budget.check_options o ~resume:false)
    max_error;
  let domains = Options.domains o in
  Option.iter (fun d -> if d < 1 then Job_error.user "--width must be at least 1") o.width;
  Option.iter
    (fun d -> if d < 1 then Job_error.user "--height must be at least 1")
    o.height;
  let sock, authority = Listen.socket ~host ~port ~beyond_loopback in
  let tmp = Filename.temp_dir "lancer-watch" "" in
  let wake_r, wake = Unix.pipe ~cloexec:true () in
  Unix.set_nonblock wake;
  let sh = Versions.create o ~wake in
  Versions.start ?max_error sh o ~any_line:any_source_line ~domains ~tmp;
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
      List.iter deliver (Versions.events sh);
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
  (* The answer to a request admitted. *)
  let route conn (req : Cohttp.Request.t) =
    let meth = Cohttp.Request.meth req in
    let target = Uri.path (Cohttp.Request.uri req) in
    match (meth, target) with
    | `GET, "/" ->
        Http.respond_string
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
        Http.respond ~flush:true
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
            match Versions.image sh k with
            | Some bytes ->
                Http.respond_string
                  ~headers:
                    (Cohttp.Header.of_list
                       [ ("content-type", "image/png"); ("cache-control", "no-store") ])
                  ~status:`OK ~body:bytes ()
            | None -> Http.text `Not_found "no such image (a newer one replaced it)\n")
        | _ -> Http.text `Not_found "not found\n")
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
        | Error q, _ -> Http.text `Bad_request (Printf.sprintf "unknown quality %S\n" q)
        | _, Some None -> Http.text `Bad_request "frame must be a whole number\n"
        | Ok q, f ->
            let play = Uri.get_query_param uri "play" = Some "1" in
            Versions.request sh (fun p ->
                {
                  Versions.quality = Option.value q ~default:p.quality;
                  frame = (match f with Some (Some k) -> max 0 k | _ -> p.frame);
                  play;
                });
            Http.text `No_content "")
    | (`GET | `POST), _ -> Http.text `Not_found "not found\n"
    | _ -> Http.text `Method_not_allowed "method not allowed\n"
  in
  let conn_closed conn =
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
  let changed () = Versions.request sh ~reload:true Fun.id in
  let inputs () = Versions.inputs sh in
  Printf.printf "lancer watch: http://%s/ shows %s (Ctrl-C to stop)\n%!" authority path;
  let server = Http.run ~authority ~route ~conn_closed sock in
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
           [ server; stop; pump (); keepalive (); File_watch.watch ~poll inputs changed ]);
      raise Sys.Break)
