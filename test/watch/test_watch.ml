(* lancer watch over HTTP, as a page uses it: the page, the images and the event stream;
   re-rendering on a save of the scene or of an included file (inotify and polling);
   errors shown and cleared; a render in progress cancelled by a newer version; and
   requests that must not read files, crash the server or stall the renders. *)

open Watch_client

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"
let tmpdir () = Run_lancer.tmpdir "lancer-watch"

let scene ?(size = "64, height: 48") colour =
  Printf.sprintf
    {|// A sphere on a floor.
settings { width: %s }
camera { position: (0, 2, -6), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0 }
sphere { center: (0, 1, 0), radius: 1.2, material: material { color: %s } }
|}
    size colour

let with_server ?(exe = exe) ?(args = []) dir f =
  let s = start ~exe ~dir (args @ [ "s.rts" ]) in
  let result = try Ok (f s) with e -> Error (e, Printexc.get_raw_backtrace ()) in
  let st = stop s in
  match result with
  | Error (e, bt) ->
      Printf.eprintf "server stderr:\n%s\n" (stderr_text s);
      Printexc.raise_with_backtrace e bt
  | Ok () ->
      Alcotest.(check bool)
        ("exits with 130 on Ctrl-C\n" ^ stderr_text s)
        true (st = Unix.WEXITED 130)

let is_image ev _ = ev = "image"
let is_last ev j = ev = "image" && to_bool (member "last" j)

(* The pixels of image [seq], decoded. *)
let pixels s seq =
  let st, body = request s (Printf.sprintf "/image/%d.png" seq) in
  Alcotest.(check int) "the image is served" 200 st;
  Alcotest.(check string) "as a PNG" "\137PNG" (String.sub body 0 4);
  let p = Filename.concat s.dir (Printf.sprintf "got%d.png" seq) in
  Run_lancer.write_file p body;
  match Lancer.Image.read_rgb8 p with
  | Ok (w, h, b) -> (w, h, b, body)
  | Error m -> Alcotest.fail m

let count_diff a b =
  let n = ref 0 in
  Bytes.iteri
    (fun i c -> if abs (Char.code c - Char.code (Bytes.get b i)) > 8 then incr n)
    a;
  !n

let basic () =
  let d = tmpdir () in
  Run_lancer.write_file (Filename.concat d "s.rts") (scene "(0.9, 0.1, 0.1)");
  with_server d (fun s ->
      let st, page = request s "/" in
      Alcotest.(check int) "the page" 200 st;
      Alcotest.(check bool)
        "it listens to the event stream" true
        (Run_lancer.contains page "new EventSource(\"/events\")");
      let e = events s in
      (* The first version: coarse images, then the full one. *)
      let coarse = ref 0 in
      let _, j =
        wait_for e "first full image" (fun ev j ->
            if is_image ev j && not (to_bool (member "last" j)) then incr coarse;
            is_last ev j)
      in
      let w, h, red, red_png = pixels s (to_int (member "seq" j)) in
      Alcotest.(check (pair int int)) "full size" (64, 48) (w, h);
      (* The full image is what lancer render writes. *)
      let _, _, err =
        Run_lancer.run ~exe ~dir:d [ "render"; "s.rts"; "-o"; "r.png"; "-q" ]
      in
      Run_lancer.write_file (Filename.concat d "served.png") red_png;
      Alcotest.(check bool)
        ("the same pixels as lancer render\n" ^ err)
        true
        (Run_lancer.pixels (Filename.concat d "served.png")
        = Run_lancer.pixels (Filename.concat d "r.png"));
      (* An edit: a coarse image first, then a full one with other pixels. *)
      atomic_write (Filename.concat d "s.rts") (scene "(0.1, 0.2, 0.9)");
      let _, j = wait_for e "a coarse image after the edit" is_image in
      Alcotest.(check bool)
        "the first image after an edit is coarse" false
        (to_bool (member "last" j));
      Alcotest.(check bool)
        "one sample per 8×8 pixels" true
        (Run_lancer.contains (to_string (member "label" j)) "8×8");
      let cw, ch, _, _ = pixels s (to_int (member "seq" j)) in
      Alcotest.(check (pair int int))
        "a complete picture at an eighth of the size" (8, 6) (cw, ch);
      let _, j = wait_for e "the full image after the edit" is_last in
      let blue_seq = to_int (member "seq" j) in
      let _, _, blue, _ = pixels s blue_seq in
      Alcotest.(check bool) "the picture changed" true (count_diff red blue > 100);
      (* A statistics event says what it cost. *)
      let _, stats = wait_for e "statistics" (fun ev _ -> ev = "stats") in
      Alcotest.(check bool)
        "rays per second" true
        (member "rays_per_second" stats <> `Null);
      Alcotest.(check bool)
        "the check summary" true
        (Run_lancer.contains (to_string (member "summary" stats)) "objects: 2");
      (* A broken scene: the located error, as lancer prints it. *)
      atomic_write (Filename.concat d "s.rts")
        (scene "(0.1, 0.2, 0.9)" ^ "sphere { center: (0, 1, 0), radiu: 1 }\n");
      let _, j = wait_for e "the error" (fun ev _ -> ev = "failure") in
      let text = to_string (member "text" j) in
      Alcotest.(check bool)
        ("file:line:col in " ^ text) true
        (Run_lancer.contains text "s.rts:7:");
      Alcotest.(check bool)
        ("the message in " ^ text) true
        (Run_lancer.contains text "did you mean `radius`?");
      Alcotest.(check bool)
        ("the source line and a caret in " ^ text)
        true
        (Run_lancer.contains text "sphere { center: (0, 1, 0), radiu: 1 }\n"
        && Run_lancer.contains text "^^^^^");
      (* Another preset while the file is broken: still the error, not the old scene. *)
      let st, _ = request ~meth:"POST" s "/control?quality=preview" in
      Alcotest.(check int) "quality switched" 204 st;
      let ev, _ =
        wait_for e "the error again" (fun ev _ ->
            ev = "failure" || ev = "ok" || ev = "image")
      in
      Alcotest.(check string) "the error stays" "failure" ev;
      let st, _ = request ~meth:"POST" s "/control?quality=scene" in
      Alcotest.(check int) "back to the scene's own" 204 st;
      ignore (wait_for e "the error again" (fun ev _ -> ev = "failure"));
      (* A page opened now sees the error and the last good image. *)
      let e2 = events s in
      let _, j2 = wait_for e2 "the last good image, for a new page" is_image in
      Alcotest.(check int) "the last good image stays" blue_seq (to_int (member "seq" j2));
      ignore (wait_for e2 "the error, for a new page" (fun ev _ -> ev = "failure"));
      close_events e2;
      (* Fixed: the error clears and a new image comes. *)
      atomic_write (Filename.concat d "s.rts") (scene "(0.1, 0.9, 0.1)");
      ignore (wait_for e "the error cleared" (fun ev _ -> ev = "ok"));
      let _, j = wait_for e "the image after the fix" is_last in
      let _, _, green, _ = pixels s (to_int (member "seq" j)) in
      Alcotest.(check bool) "green differs from blue" true (count_diff green blue > 100);
      (* The quality preset switched from the page. *)
      let st, _ = request ~meth:"POST" s "/control?quality=draft" in
      Alcotest.(check int) "quality switched" 204 st;
      let _, sc = wait_for e "the new preset" (fun ev _ -> ev = "scene") in
      Alcotest.(check string) "draft" "draft" (to_string (member "quality" sc));
      let st, _ = request ~meth:"POST" s "/control?quality=ultra" in
      Alcotest.(check int) "an unknown preset is refused" 400 st;
      close_events e)

let includes ~poll () =
  let d = tmpdir () in
  Unix.mkdir (Filename.concat d "lib") 0o755;
  let col c = Printf.sprintf "let c = %s\n" c in
  Run_lancer.write_file (Filename.concat d "lib/col.rts") (col "(0.9, 0.1, 0.1)");
  Run_lancer.write_file (Filename.concat d "s.rts")
    ("include \"lib/col.rts\"\n" ^ scene "c");
  with_server
    ~args:(if poll then [ "--poll" ] else [])
    d
    (fun s ->
      let e = events s in
      let _, j = wait_for e "first full image" is_last in
      let _, _, a, _ = pixels s (to_int (member "seq" j)) in
      (* Written in place, not renamed: the other way editors save. *)
      Unix.sleepf 1.1;
      Run_lancer.write_file (Filename.concat d "lib/col.rts") (col "(0.1, 0.9, 0.1)");
      let _, j = wait_for e "an image after the included file changed" is_last in
      let _, _, b, _ = pixels s (to_int (member "seq" j)) in
      Alcotest.(check bool) "the picture changed" true (count_diff a b > 100);
      close_events e)

(* An image that only a later frame reads is watched once that frame has been shown:
   changing it brings a new image of that frame (not the old pixels from the cache). *)
let late_image () =
  let d = tmpdir () in
  let ppm r g b =
    "P6\n2 2\n255\n"
    ^ String.concat "" (List.init 4 (fun _ -> Printf.sprintf "%c%c%c" r g b))
  in
  Run_lancer.write_file (Filename.concat d "early.ppm") (ppm '\200' '\030' '\030');
  Run_lancer.write_file (Filename.concat d "late.ppm") (ppm '\030' '\200' '\030');
  Run_lancer.write_file (Filename.concat d "s.rts")
    {|settings { width: 48, height: 36 }
animation { fps: 10, frames: 4 }
camera { position: (0, 2, -6), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
sphere { center: (0, 1, 0), radius: 1.5,
         material: material { texture: image(if frame >= 2 then "late.ppm" else "early.ppm", 1) } }
|};
  with_server d (fun s ->
      let e = events s in
      ignore (wait_for e "frame 0" is_last);
      let st, _ = request ~meth:"POST" s "/control?frame=3" in
      Alcotest.(check int) "frame chosen" 204 st;
      let _, j =
        wait_for e "frame 3" (fun ev j -> is_last ev j && to_int (member "frame" j) = 3)
      in
      let _, _, a, _ = pixels s (to_int (member "seq" j)) in
      Unix.sleepf 1.1;
      Run_lancer.write_file (Filename.concat d "late.ppm") (ppm '\030' '\030' '\200');
      let _, j =
        wait_for e "frame 3 after its image changed" (fun ev j ->
            is_last ev j && to_int (member "frame" j) = 3)
      in
      let _, _, b, _ = pixels s (to_int (member "seq" j)) in
      Alcotest.(check bool) "the picture changed" true (count_diff a b > 100);
      close_events e)

(* A slow version is dropped when a newer one arrives: its full image never comes. *)
let cancel () =
  let d = tmpdir () in
  Run_lancer.write_file (Filename.concat d "s.rts") (scene "(0.9, 0.1, 0.1)");
  with_server ~args:[ "--domains"; "2" ] d (fun s ->
      let e = events s in
      ignore (wait_for e "first full image" is_last);
      (* 1600×1200 at 8×8 samples: minutes of work on one core, seconds to its first
         coarse image. *)
      atomic_write (Filename.concat d "s.rts")
        (scene ~size:"1600, height: 1200, samples: 8" "(0.1, 0.2, 0.9)");
      ignore (wait_for e ~timeout:120. "a coarse image of the slow version" is_image);
      atomic_write (Filename.concat d "s.rts") (scene "(0.1, 0.9, 0.1)");
      let slow_finished = ref false in
      ignore
        (wait_for e ~timeout:120. "the newer version's full image"
           ~seen:(fun ev data ->
             let j = Yojson.Safe.from_string data in
             if is_last ev j && to_int (member "width" j) = 1600 then
               slow_finished := true)
           (fun ev j -> is_last ev j && to_int (member "width" j) = 64));
      Alcotest.(check bool)
        "the slow version never finished: it was cancelled" false !slow_finished;
      let st, _ = request s "/" in
      Alcotest.(check int) "still serving" 200 st;
      close_events e)

let hostile () =
  let d = tmpdir () in
  Run_lancer.write_file (Filename.concat d "s.rts") (scene "(0.9, 0.1, 0.1)");
  Run_lancer.write_file
    (Filename.concat d "secret.txt")
    "a secret in the scene's directory\n";
  with_server d (fun s ->
      let e = events s in
      ignore (wait_for e "first full image" is_last);
      let no_secret what (_, body) =
        Alcotest.(check bool)
          (what ^ ": no file content") false
          (Run_lancer.contains body "root:"
          || Run_lancer.contains body "a secret"
          || Run_lancer.contains body "sphere {")
      in
      List.iter
        (fun p ->
          let ((st, _) as r) =
            raw s.port
              (Printf.sprintf "GET %s HTTP/1.0\r\nHost: 127.0.0.1:%d\r\n\r\n" p s.port)
          in
          Alcotest.(check int) (p ^ " is not found") 404 st;
          no_secret p r)
        [
          "/../../etc/passwd";
          "/..%2f..%2fetc%2fpasswd";
          "/etc/passwd";
          "/secret.txt";
          "/s.rts";
          "/image/../s.rts";
          "/image/..%2f..%2fetc%2fpasswd.png";
          "/image/-1.png";
          "/image/99999999999999999999999.png";
          "//etc/passwd";
        ];
      (* A foreign Host (a renamed domain pointing at 127.0.0.1), or none. *)
      List.iter
        (fun (what, req) ->
          let ((st, _) as r) = raw s.port req in
          Alcotest.(check int) (what ^ " is refused") 403 st;
          no_secret what r)
        [
          ( "a foreign Host",
            "GET / HTTP/1.1\r\nHost: evil.example:80\r\nConnection: close\r\n\r\n" );
          ( "a foreign Host for the events",
            "GET /events HTTP/1.1\r\nHost: evil.example\r\nConnection: close\r\n\r\n" );
          ( "the right port on another name",
            Printf.sprintf
              "GET / HTTP/1.1\r\n\
               Host: localhost.evil.example:%d\r\n\
               Connection: close\r\n\
               \r\n"
              s.port );
          ("no Host", "GET / HTTP/1.0\r\n\r\n");
          ( "a control from a foreign page",
            Printf.sprintf
              "POST /control?quality=draft HTTP/1.1\r\n\
               Host: 127.0.0.1:%d\r\n\
               Origin: http://evil.example\r\n\
               Content-Length: 0\r\n\
               Connection: close\r\n\
               \r\n"
              s.port );
        ];
      (* Garbage and a flood: many connections at once, some never finishing their
         request, some sending nonsense. *)
      let idle =
        List.init 40 (fun _ ->
            let fd = Unix.socket PF_INET SOCK_STREAM 0 in
            Unix.connect fd (ADDR_INET (Unix.inet_addr_loopback, s.port));
            fd)
      in
      List.iteri
        (fun i fd ->
          if i mod 2 = 0 then ignore (Unix.write_substring fd "GET / HTTP/1.1\r\nHo" 0 18))
        idle;
      ignore (raw s.port "\000\001\002 garbage \r\n\r\n");
      ignore (raw s.port (String.make 70000 'A' ^ "\r\n\r\n"));
      for _ = 1 to 10 do
        let batch =
          List.init 30 (fun i ->
              let fd = Unix.socket PF_INET SOCK_STREAM 0 in
              Unix.connect fd (ADDR_INET (Unix.inet_addr_loopback, s.port));
              let path =
                if i mod 3 = 0 then "/../../etc/passwd"
                else if i mod 3 = 1 then "/"
                else "/image/1.png"
              in
              let host =
                if i mod 5 = 0 then "evil.example"
                else Printf.sprintf "127.0.0.1:%d" s.port
              in
              ignore
                (Unix.write_substring fd
                   (Printf.sprintf "GET %s HTTP/1.0\r\nHost: %s\r\n\r\n" path host)
                   0
                   (String.length
                      (Printf.sprintf "GET %s HTTP/1.0\r\nHost: %s\r\n\r\n" path host)));
              fd)
        in
        List.iter (fun fd -> Unix.close fd) batch
      done;
      (* Renders go on: an edit still gives a new full image, and the page still loads. *)
      atomic_write (Filename.concat d "s.rts") (scene "(0.1, 0.9, 0.1)");
      ignore (wait_for e "a full image after the flood" is_last);
      let st, _ = request s "/" in
      Alcotest.(check int) "the page still loads" 200 st;
      List.iter Unix.close idle;
      close_events e;
      (* Pages opened and closed again and again, and many left open (the oldest are then
         closed): a new page still gets its events, and the next edit. *)
      let left_open = List.init 40 (fun _ -> events s) in
      for _ = 1 to 60 do
        close_events (events s)
      done;
      let fresh = events s in
      ignore (wait_for fresh "the current image, for a page opened after many" is_image);
      atomic_write (Filename.concat d "s.rts") (scene "(0.1, 0.1, 0.9)");
      ignore (wait_for fresh "a full image after many pages" is_last);
      close_events fresh;
      List.iter (fun e -> try close_events e with Unix.Unix_error _ -> ()) left_open)

(* An animation: the page learns its frames, and a chosen frame is rendered. *)
let animation () =
  let d = tmpdir () in
  Run_lancer.write_file (Filename.concat d "s.rts")
    {|settings { width: 48, height: 36 }
animation { fps: 10, frames: 8 }
camera { position: (0, 2, -6), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0 }
sphere { center: (-2 + 0.6 * frame, 1, 0), radius: 0.8, material: material { color: (0.9, 0.1, 0.1) } }
|};
  with_server d (fun s ->
      let e = events s in
      let _, sc = wait_for e "the scene" (fun ev _ -> ev = "scene") in
      Alcotest.(check int)
        "its frames" 8
        (to_int (member "frames" (member "animation" sc)));
      let _, j = wait_for e "frame 0" is_last in
      Alcotest.(check string)
        "named for saving" "s_0000.png"
        (to_string (member "name" j));
      let _, _, f0, _ = pixels s (to_int (member "seq" j)) in
      let st, _ = request ~meth:"POST" s "/control?frame=6" in
      Alcotest.(check int) "frame chosen" 204 st;
      let _, j =
        wait_for e "frame 6" (fun ev j -> is_last ev j && to_int (member "frame" j) = 6)
      in
      Alcotest.(check string)
        "named for saving" "s_0006.png"
        (to_string (member "name" j));
      let _, _, f6, _ = pixels s (to_int (member "seq" j)) in
      Alcotest.(check bool) "the sphere moved" true (count_diff f0 f6 > 50);
      (* While playing, only the preview passes: the last image is the preview. *)
      let st, _ = request ~meth:"POST" s "/control?frame=7&play=1" in
      Alcotest.(check int) "playing" 204 st;
      let _, j =
        wait_for e "frame 7" (fun ev j -> is_last ev j && to_int (member "frame" j) = 7)
      in
      Alcotest.(check bool)
        ("at preview quality: " ^ to_string (member "label" j))
        true
        (Run_lancer.contains (to_string (member "label" j)) "preview");
      let st, _ = request ~meth:"POST" s "/control?frame=x" in
      Alcotest.(check int) "a frame must be a number" 400 st;
      close_events e)

(* --max-error: the full image at the settings it chooses, said in the terminal; the page
   shows them. *)
let max_error () =
  let d = tmpdir () in
  Run_lancer.write_file (Filename.concat d "s.rts") (scene "(0.9, 0.1, 0.1)");
  with_server ~args:[ "--max-error"; "0.02" ] d (fun s ->
      let e = events s in
      let _, _ = wait_for e "the full image" is_last in
      let _, st = wait_for e "its stats" (fun ev _ -> ev = "stats") in
      let rec said () =
        match input_line_within s.out 30. with
        | Some l when Run_lancer.contains l "max error 0.02 (mean FLIP): samples " -> l
        | Some _ -> said ()
        | None -> Alcotest.fail "the terminal never said what --max-error chose"
      in
      let line = said () in
      (* "samples 3×3, …": the page's knobs show the samples chosen. *)
      let chosen =
        Scanf.sscanf (List.nth (String.split_on_char ':' line) 1) " samples %d" Fun.id
      in
      Alcotest.(check string)
        "the page shows the samples chosen"
        (Printf.sprintf "%d×%d" chosen chosen)
        (to_string (member "samples" (member "knobs" st)));
      Alcotest.(check string)
        "and says who chose them" "chosen by --max-error 0.02"
        (to_string (member "quality" (member "knobs" st)));
      close_events e);
  let st, _, err =
    Run_lancer.run ~prefix:"timeout 60" ~exe ~dir:d
      [ "watch"; "s.rts"; "--port"; "0"; "--max-error"; "0.02"; "--samples"; "2" ]
  in
  Alcotest.(check int) "with --samples: exit 1" 1 st;
  Alcotest.(check bool)
    err true
    (Run_lancer.contains err "cannot be combined with --samples")

(* Mistakes on the command line: one line, exit 1, no server left behind. *)
let mistakes () =
  let d = tmpdir () in
  Run_lancer.write_file (Filename.concat d "s.rts") (scene "(0.9, 0.1, 0.1)");
  let one what args expect =
    (* Bounded: a server that started by mistake would otherwise run on. *)
    let st, _, e = Run_lancer.run ~prefix:"timeout 60" ~exe ~dir:d ("watch" :: args) in
    Alcotest.(check int) (what ^ ": exit 1\n" ^ e) 1 st;
    Alcotest.(check bool) (what ^ ": " ^ e) true (Run_lancer.contains e expect);
    Alcotest.(check bool)
      (what ^ ": no backtrace") false
      (Run_lancer.contains e "Raised at")
  in
  one "a missing scene" [ "nope.rts"; "--port"; "0" ] "lancer: nope.rts: no such file";
  one "standard input" [ "-"; "--port"; "0" ]
    "watch needs a scene file to watch, not standard input";
  one "a host name"
    [ "s.rts"; "--host"; "localhost"; "--port"; "0" ]
    "--host must be an IP address";
  one "every address"
    [ "s.rts"; "--host"; "0.0.0.0"; "--port"; "0" ]
    "--host must be one address of this machine";
  (* A port already taken. *)
  let sock = Unix.socket PF_INET SOCK_STREAM 0 in
  Unix.bind sock (ADDR_INET (Unix.inet_addr_loopback, 0));
  Unix.listen sock 1;
  let port =
    match Unix.getsockname sock with ADDR_INET (_, p) -> p | _ -> assert false
  in
  one "a port in use"
    [ "s.rts"; "--port"; string_of_int port ]
    (Printf.sprintf "cannot listen on 127.0.0.1:%d" port);
  Unix.close sock

(* Out of file descriptors: with a limit of 40, more connections than it can accept wait
   in the listening queue; the server waits for some to close instead of stopping, and
   serves again once they have. *)
let out_of_descriptors () =
  let d = tmpdir () in
  Run_lancer.write_file (Filename.concat d "s.rts") (scene "(0.9, 0.1, 0.1)");
  let wrapper = Filename.concat d "lancer-40" in
  Run_lancer.write_file wrapper
    (Printf.sprintf "#!/bin/sh\nulimit -n 40 || exit 3\nexec %s \"$@\"\n"
       (Filename.quote exe));
  Unix.chmod wrapper 0o755;
  with_server ~exe:wrapper d (fun s ->
      let e = events s in
      ignore (wait_for e "the first full image" is_last);
      let held =
        List.init 60 (fun _ ->
            let fd = Unix.socket PF_INET SOCK_STREAM 0 in
            Unix.connect fd (ADDR_INET (Unix.inet_addr_loopback, s.port));
            fd)
      in
      Unix.sleepf 1.;
      List.iter Unix.close held;
      let st, _ = request s "/" in
      Alcotest.(check int) "the page loads once they are closed" 200 st;
      atomic_write (Filename.concat d "s.rts") (scene "(0.1, 0.9, 0.1)");
      ignore (wait_for e "a full image of the edit" is_last);
      close_events e)

(* ---- The server's bounds: what one request, one connection, one address may cost. ---- *)

(* A connection to the server, with reads and writes bounded in time. *)
let socket ?(timeout = 30.) port =
  let fd = Unix.socket PF_INET SOCK_STREAM 0 in
  Unix.connect fd (ADDR_INET (Unix.inet_addr_loopback, port));
  Unix.setsockopt_float fd SO_RCVTIMEO timeout;
  Unix.setsockopt_float fd SO_SNDTIMEO timeout;
  fd

let status_of resp =
  match Scanf.sscanf_opt resp "HTTP/1.%d %d" (fun _ c -> c) with Some c -> c | None -> 0

(* Send [head], then [size] more bytes (a body, or the rest of a header), in pieces,
   as long as the server takes them; then read its answer: (status, whether the server
   stopped taking them before the end). *)
let send_large port head size filler =
  let fd = socket port in
  Fun.protect
    ~finally:(fun () -> Unix.close fd)
    (fun () ->
      let piece = String.make 65536 filler in
      let stopped =
        try
          ignore (Unix.write_substring fd head 0 (String.length head));
          let rec go left =
            if left > 0 then
              let n = min left (String.length piece) in
              let w = Unix.write_substring fd piece 0 n in
              go (left - w)
          in
          go size;
          false
        with Unix.Unix_error ((EPIPE | ECONNRESET | EAGAIN | EWOULDBLOCK), _, _) -> true
      in
      let buf = Buffer.create 1024 and b = Bytes.create 4096 in
      let rec read () =
        match Unix.read fd b 0 4096 with
        | 0 -> ()
        | n ->
            Buffer.add_subbytes buf b 0 n;
            read ()
        | exception Unix.Unix_error _ -> ()
      in
      read ();
      (status_of (Buffer.contents buf), stopped))

(* The status of the answer to [request], read no further than its head (an event
   stream does not end). *)
let status_only port request =
  let fd = socket port in
  Fun.protect
    ~finally:(fun () -> Unix.close fd)
    (fun () ->
      ignore (Unix.write_substring fd request 0 (String.length request));
      let buf = Buffer.create 1024 and b = Bytes.create 4096 in
      let rec read () =
        if find (Buffer.contents buf) "\r\n\r\n" = None then
          match Unix.read fd b 0 4096 with
          | 0 -> ()
          | n ->
              Buffer.add_subbytes buf b 0 n;
              read ()
          | exception Unix.Unix_error _ -> ()
      in
      read ();
      status_of (Buffer.contents buf))

(* The server's resident memory, in kB. *)
let rss pid =
  let text = Run_lancer.read_file (Printf.sprintf "/proc/%d/status" pid) in
  List.find_map
    (fun l -> Scanf.sscanf_opt l "VmRSS: %d kB" Fun.id)
    (String.split_on_char '\n' text)
  |> Option.get

let own s = Printf.sprintf "127.0.0.1:%d" s.port
let mb = 1024 * 1024

let large_requests () =
  let d = tmpdir () in
  Run_lancer.write_file (Filename.concat d "s.rts") (scene "(0.9, 0.1, 0.1)");
  with_server d (fun s ->
      let e = events s in
      ignore (wait_for e "first full image" is_last);
      let before = rss s.pid in
      let grew what =
        let after = rss s.pid in
        Alcotest.(check bool)
          (Printf.sprintf
             "%s: memory grew by %d kB (from %d kB), not by the request's size" what
             (after - before) before)
          true
          (after - before < 32 * 1024)
      in
      let body ?(extra = "") n =
        Printf.sprintf
          "POST /control?quality=draft HTTP/1.1\r\n\
           Host: %s\r\n\
           %sContent-Length: %d\r\n\
           \r\n"
          (own s) extra n
      in
      let st, _ =
        send_large s.port
          (body ~extra:"Origin: http://evil.example\r\n" (64 * mb))
          (64 * mb) 'x'
      in
      Alcotest.(check int) "a foreign page's 64 MB body is refused" 403 st;
      grew "after a foreign 64 MB body";
      let st, stopped = send_large s.port (body (64 * mb)) (64 * mb) 'x' in
      Alcotest.(check int) "a 64 MB body is too large" 413 st;
      Alcotest.(check bool) "and is not read to its end" true stopped;
      grew "after a 64 MB body";
      let st, _ = send_large s.port (body 5000) 5000 'x' in
      Alcotest.(check int) "past 4 KiB is too large" 413 st;
      let st, _ =
        send_large s.port
          (Printf.sprintf
             "POST /control?quality=draft HTTP/1.1\r\n\
              Host: %s\r\n\
              Transfer-Encoding: chunked\r\n\
              \r\n"
             (own s))
          0 'x'
      in
      Alcotest.(check int) "a body without its length is refused" 411 st;
      let st, _ =
        raw s.port
          (Printf.sprintf
             "POST /control?quality=draft HTTP/1.1\r\n\
              Host: %s\r\n\
              Content-Length: 12\r\n\
              Connection: close\r\n\
              \r\n\
              quality=none"
             (own s))
      in
      Alcotest.(check int) "a small body is read (and ignored)" 204 st;
      (* Headers: one huge one, many small ones, a huge request line. *)
      let st, stopped =
        send_large s.port
          (Printf.sprintf "GET / HTTP/1.1\r\nHost: %s\r\nX-Filler: " (own s))
          (64 * mb) 'a'
      in
      Alcotest.(check int) "a 64 MB header is too large" 431 st;
      Alcotest.(check bool) "and is not read to its end" true stopped;
      grew "after a 64 MB header";
      let many =
        String.concat ""
          (List.init 400 (fun i -> Printf.sprintf "X-H%d: %s\r\n" i (String.make 60 'b')))
      in
      let st, _ =
        raw s.port (Printf.sprintf "GET / HTTP/1.1\r\nHost: %s\r\n%s\r\n" (own s) many)
      in
      Alcotest.(check int) "400 headers of 70 bytes are too large" 431 st;
      let st, _ =
        raw s.port
          (Printf.sprintf "GET /%s HTTP/1.1\r\nHost: %s\r\n\r\n" (String.make 20000 'p')
             (own s))
      in
      Alcotest.(check int) "a 20 kB request line is too large" 431 st;
      let st, _ =
        raw s.port
          (Printf.sprintf
             "GET / HTTP/1.1\r\nHost: %s\r\nX-Filler: %s\r\nConnection: close\r\n\r\n"
             (own s) (String.make 8000 'c'))
      in
      Alcotest.(check int) "an 8 kB header is fine" 200 st;
      (* Still serving, still rendering. *)
      atomic_write (Filename.concat d "s.rts") (scene "(0.1, 0.9, 0.1)");
      ignore (wait_for e "a full image after the large requests" is_last);
      close_events e)

(* Whether the server has closed [fd]: its end of the stream, or a reset. *)
let closed fd =
  match Unix.select [ fd ] [] [] 0. with
  | [], _, _ -> false
  | _ -> (
      let b = Bytes.create 4096 in
      match Unix.read fd b 0 4096 with
      | 0 -> true
      | _ -> false
      | exception Unix.Unix_error ((ECONNRESET | EPIPE), _, _) -> true)

let idle_connections () =
  let d = tmpdir () in
  Run_lancer.write_file (Filename.concat d "s.rts") (scene "(0.9, 0.1, 0.1)");
  with_server d (fun s ->
      let e = events s in
      ignore (wait_for e "first full image" is_last);
      let silent = socket s.port in
      let partial = socket s.port in
      ignore (Unix.write_substring partial "GET / HTTP/1.1\r\nHo" 0 18);
      (* A client that sends a byte of its headers every second. *)
      let slow = socket s.port in
      let slow_head = Printf.sprintf "GET / HTTP/1.1\r\nHost: %s\r\nX-Slow: " (own s) in
      ignore (Unix.write_substring slow slow_head 0 (String.length slow_head));
      (* One that takes a second to send its request is answered. *)
      let prompt = socket s.port in
      Unix.sleepf 1.;
      let req = Printf.sprintf "GET / HTTP/1.0\r\nHost: %s\r\n\r\n" (own s) in
      ignore (Unix.write_substring prompt req 0 (String.length req));
      let b = Bytes.create 64 in
      let n = Unix.read prompt b 0 64 in
      Alcotest.(check int)
        "a request sent after a second is answered" 200
        (status_of (Bytes.sub_string b 0 n));
      Unix.close prompt;
      let fds = [ ("silent", silent); ("partial", partial); ("slow", slow) ] in
      let gone = Hashtbl.create 3 in
      let rec wait k =
        if k > 0 && Hashtbl.length gone < List.length fds then (
          Unix.sleepf 1.;
          (try ignore (Unix.write_substring slow "s" 0 1) with Unix.Unix_error _ -> ());
          List.iter (fun (w, fd) -> if closed fd then Hashtbl.replace gone w ()) fds;
          wait (k - 1))
      in
      wait 40;
      List.iter
        (fun (w, fd) ->
          Alcotest.(check bool)
            (w ^ ": closed within 40 s, no request having come")
            true (Hashtbl.mem gone w);
          Unix.close fd)
        fds;
      (* The page's event stream waits for the server, not the other way round: it is
         still open, and brings the next image. *)
      atomic_write (Filename.concat d "s.rts") (scene "(0.1, 0.9, 0.1)");
      ignore (wait_for e "a full image on the event stream opened before" is_last);
      close_events e)

(* With 256 descriptors, 250 idle connections: the page still loads at once (well
   before they time out by themselves), and its event stream still works. *)
let idle_flood () =
  let d = tmpdir () in
  Run_lancer.write_file (Filename.concat d "s.rts") (scene "(0.9, 0.1, 0.1)");
  let wrapper = Filename.concat d "lancer-256" in
  Run_lancer.write_file wrapper
    (Printf.sprintf "#!/bin/sh\nulimit -n 256 || exit 3\nexec %s \"$@\"\n"
       (Filename.quote exe));
  Unix.chmod wrapper 0o755;
  with_server ~exe:wrapper d (fun s ->
      let e = events s in
      ignore (wait_for e "the first full image" is_last);
      let idle =
        List.init 250 (fun i ->
            let fd = socket s.port in
            if i mod 2 = 0 then ignore (Unix.write_substring fd "GET / HTTP/1.1\r\n" 0 16);
            fd)
      in
      let fd = socket ~timeout:8. s.port in
      let req = Printf.sprintf "GET / HTTP/1.0\r\nHost: %s\r\n\r\n" (own s) in
      ignore (Unix.write_substring fd req 0 (String.length req));
      let b = Bytes.create 64 in
      let n = try Unix.read fd b 0 64 with Unix.Unix_error _ -> 0 in
      Unix.close fd;
      Alcotest.(check int)
        "the page loads within 8 s, past 250 idle connections" 200
        (status_of (Bytes.sub_string b 0 n));
      atomic_write (Filename.concat d "s.rts") (scene "(0.1, 0.9, 0.1)");
      ignore (wait_for e "a full image after the flood" is_last);
      List.iter Unix.close idle;
      close_events e)

let origins () =
  let d = tmpdir () in
  Run_lancer.write_file (Filename.concat d "s.rts") (scene "(0.9, 0.1, 0.1)");
  with_server d (fun s ->
      let e = events s in
      let _, j = wait_for e "first full image" is_last in
      let image = Printf.sprintf "/image/%d.png" (to_int (member "seq" j)) in
      let ask ?(extra = "") ?(meth = "GET") path =
        status_only s.port
          (Printf.sprintf "%s %s HTTP/1.1\r\nHost: %s\r\n%sConnection: close\r\n\r\n" meth
             path (own s) extra)
      in
      let foreign = "Origin: http://evil.example\r\n" in
      List.iter
        (fun (what, path, extra, meth, expect) ->
          Alcotest.(check int) what expect (ask ~extra ~meth path))
        [
          ("the events for a foreign page", "/events", foreign, "GET", 403);
          ("an image for a foreign page", image, foreign, "GET", 403);
          ("the page for a foreign script", "/", foreign, "GET", 403);
          ("a control for a foreign page", "/control?quality=draft", foreign, "POST", 403);
          ("a missing path for a foreign page", "/nope", foreign, "GET", 403);
          ( "the events for another site",
            "/events",
            "Sec-Fetch-Site: cross-site\r\n",
            "GET",
            403 );
          ( "an image embedded by another site",
            image,
            "Sec-Fetch-Site: cross-site\r\n",
            "GET",
            403 );
          ( "an image for a sibling site",
            image,
            "Sec-Fetch-Site: same-site\r\n",
            "GET",
            403 );
          ( "the page, from a link elsewhere",
            "/",
            "Sec-Fetch-Site: cross-site\r\n",
            "GET",
            200 );
          ("the page, typed in", "/", "Sec-Fetch-Site: none\r\n", "GET", 200);
          ( "an image for the page itself",
            image,
            "Sec-Fetch-Site: same-origin\r\n",
            "GET",
            200 );
          ( "an image with the page's own origin",
            image,
            Printf.sprintf "Origin: http://%s\r\n" (own s),
            "GET",
            200 );
          ("an image for a program (no Origin)", image, "", "GET", 200);
          ( "a control from the page",
            "/control?quality=draft",
            Printf.sprintf "Origin: http://%s\r\nContent-Length: 0\r\n" (own s),
            "POST",
            204 );
        ];
      (* Foreign pages opening many event streams do not close the page's own. *)
      for _ = 1 to 40 do
        Alcotest.(check int) "a foreign event stream" 403 (ask ~extra:foreign "/events")
      done;
      atomic_write (Filename.concat d "s.rts") (scene "(0.1, 0.9, 0.1)");
      ignore (wait_for e "a full image on the page's own stream" is_last);
      close_events e)

let duplicate_headers () =
  let d = tmpdir () in
  Run_lancer.write_file (Filename.concat d "s.rts") (scene "(0.9, 0.1, 0.1)");
  with_server d (fun s ->
      let ask what headers expect =
        let st, _ =
          raw s.port
            (Printf.sprintf "GET / HTTP/1.1\r\n%sConnection: close\r\n\r\n"
               (String.concat "" (List.map (fun h -> h ^ "\r\n") headers)))
        in
        Alcotest.(check int) what expect st
      in
      let host = "Host: " ^ own s in
      ask "one Host" [ host ] 200;
      ask "the same Host twice" [ host; host ] 400;
      ask "a foreign Host, then its own" [ "Host: evil.example"; host ] 400;
      ask "its own Host, then a foreign one" [ host; "Host: evil.example" ] 400;
      ask "two Origins"
        [ host; "Origin: http://" ^ own s; "Origin: http://evil.example" ]
        400;
      let st, _ =
        raw s.port
          (Printf.sprintf
             "POST /control?quality=draft HTTP/1.1\r\n\
              %s\r\n\
              Content-Length: 0\r\n\
              Content-Length: 100\r\n\
              Connection: close\r\n\
              \r\n"
             host)
      in
      Alcotest.(check int) "two Content-Lengths" 400 st)

(* A scene error is printed in the terminal running the server too, as lancer prints it
   elsewhere, even with --quiet (which silences only the timings). *)
let terminal_errors () =
  let d = tmpdir () in
  Run_lancer.write_file (Filename.concat d "s.rts")
    (scene "(0.9, 0.1, 0.1)" ^ "sphere { center: (0, 1, 0), radiu: 1 }\n");
  with_server ~args:[ "-q" ] d (fun s ->
      let e = events s in
      ignore (wait_for e "the error" (fun ev _ -> ev = "failure"));
      let located = "s.rts:7:29: unknown field `radiu` in sphere" in
      (* Written just after the event: looked for a little while. *)
      let rec look n =
        if n > 0 && not (Run_lancer.contains (stderr_text s) located) then (
          Unix.sleepf 0.1;
          look (n - 1))
      in
      look 200;
      let err = stderr_text s in
      Alcotest.(check bool)
        ("the located error in the terminal: " ^ err)
        true
        (Run_lancer.contains err located
        && Run_lancer.contains err "sphere { center: (0, 1, 0), radiu: 1 }\n"
        && Run_lancer.contains err "^^^^^");
      close_events e)

(* A scene that includes a file outside its directory: the error says where, not what
   the line is (on the page and in the terminal), a symbolic link in the directory
   leading out included; --show-lines-outside shows it. *)
let outside_lines () =
  let top = tmpdir () in
  let d = Filename.concat top "scene" in
  Unix.mkdir d 0o755;
  let secret = "root:x:0:0:the-secret-line:/root:/bin/bash\n" in
  Run_lancer.write_file (Filename.concat top "secret.rts") secret;
  Unix.symlink "../secret.rts" (Filename.concat d "link.rts");
  let including f = Printf.sprintf "include \"%s\"\n" f ^ scene "(0.9, 0.1, 0.1)" in
  Run_lancer.write_file (Filename.concat d "s.rts") (including "../secret.rts");
  let no_line what ~file s text =
    Alcotest.(check bool)
      (what ^ ": where, in " ^ text)
      true
      (Run_lancer.contains text (file ^ ":1:"));
    Alcotest.(check bool)
      (what ^ ": not the line, in " ^ text)
      false
      (Run_lancer.contains text "the-secret-line");
    Alcotest.(check bool)
      (what ^ ": nor in the terminal")
      false
      (Run_lancer.contains (stderr_text s) "the-secret-line")
  in
  with_server d (fun s ->
      let e = events s in
      let _, j = wait_for e "the error" (fun ev _ -> ev = "failure") in
      no_line "an include by ../" ~file:"secret.rts" s (to_string (member "text" j));
      atomic_write (Filename.concat d "s.rts") (including "link.rts");
      let _, j =
        wait_for e "the error through the link" (fun ev j ->
            ev = "failure" && Run_lancer.contains (to_string (member "text" j)) "link.rts")
      in
      no_line "a link leading out" ~file:"link.rts" s (to_string (member "text" j));
      close_events e);
  Run_lancer.write_file (Filename.concat d "s.rts") (including "../secret.rts");
  with_server ~args:[ "--show-lines-outside" ] d (fun s ->
      let e = events s in
      let _, j = wait_for e "the error" (fun ev _ -> ev = "failure") in
      let text = to_string (member "text" j) in
      Alcotest.(check bool)
        ("--show-lines-outside shows the line: " ^ text)
        true
        (Run_lancer.contains text "the-secret-line");
      close_events e)

(* Where it may listen: one loopback address unless told otherwise, never every one. *)
let hosts () =
  let d = tmpdir () in
  Run_lancer.write_file (Filename.concat d "s.rts") (scene "(0.9, 0.1, 0.1)");
  let refused what args expect =
    let st, _, e =
      Run_lancer.run ~prefix:"timeout 60" ~exe ~dir:d
        ("watch" :: "s.rts" :: "--port" :: "0" :: args)
    in
    Alcotest.(check int) (what ^ ": exit 1\n" ^ e) 1 st;
    Alcotest.(check bool) (what ^ ": " ^ e) true (Run_lancer.contains e expect);
    Alcotest.(check bool)
      (what ^ ": no backtrace") false
      (Run_lancer.contains e "Raised at")
  in
  List.iter
    (fun h ->
      refused ("every address as " ^ h) [ "--host"; h ]
        "lancer: --host must be one address of this machine";
      refused
        ("every address as " ^ h ^ ", even beyond loopback")
        [ "--host"; h; "--listen-beyond-loopback" ]
        "lancer: --host must be one address of this machine")
    [ "::ffff:0.0.0.0"; "0:0:0:0:0:ffff:0:0"; "::"; "0:0::0"; "::0.0.0.0"; "0.0.0.0" ];
  List.iter
    (fun h ->
      refused (h ^ " without the option") [ "--host"; h ]
        (Printf.sprintf "lancer: --host %s is not a loopback address" h))
    [ "192.0.2.1"; "::ffff:192.0.2.1"; "2001:db8::1"; "::127.0.0.1" ];
  (* With the option the address is tried (this machine has not got it). *)
  refused "192.0.2.1 with the option"
    [ "--host"; "192.0.2.1"; "--listen-beyond-loopback" ]
    "lancer: cannot listen on 192.0.2.1";
  (* A loopback address written as IPv4-mapped is served as the IPv4 address. *)
  with_server ~args:[ "--host"; "::ffff:127.0.0.1" ] d (fun s ->
      let st, _ = request s "/" in
      Alcotest.(check int) "::ffff:127.0.0.1 is 127.0.0.1" 200 st)

let () =
  Sys.set_signal Sys.sigpipe Sys.Signal_ignore;
  Alcotest.run "watch"
    [
      ( "watch",
        [
          Alcotest.test_case
            "page, images, a new image on an edit, the located error and its fix, quality"
            `Quick basic;
          Alcotest.test_case "--max-error: the full image at the settings it chooses"
            `Quick max_error;
          Alcotest.test_case
            "a scene error is printed in the terminal too, even with --quiet" `Quick
            terminal_errors;
          Alcotest.test_case "a change in an included file (inotify)" `Quick
            (includes ~poll:false);
          Alcotest.test_case "a change in an included file (polling)" `Quick
            (includes ~poll:true);
          Alcotest.test_case
            "an animation: its frames, a chosen frame, playing at preview quality" `Quick
            animation;
          Alcotest.test_case "a newer version cancels the render in progress" `Quick
            cancel;
          Alcotest.test_case "an image only a later frame reads is watched too" `Quick
            late_image;
          Alcotest.test_case
            "a missing scene, a host name, a port in use: one line, exit 1" `Quick
            mistakes;
          Alcotest.test_case
            "paths, foreign hosts and a flood read nothing and stall nothing" `Quick
            hostile;
          Alcotest.test_case "out of file descriptors, it waits and serves again" `Quick
            out_of_descriptors;
          Alcotest.test_case
            "a wildcard host in any spelling is refused, and one beyond loopback without \
             --listen-beyond-loopback"
            `Quick hosts;
          Alcotest.test_case
            "bodies past 4 KiB and headers past 16 KiB are refused unread, and the \
             memory does not grow by them"
            `Quick large_requests;
          Alcotest.test_case
            "a connection with no complete request is closed after the idle timeout; the \
             event stream stays"
            `Quick idle_connections;
          Alcotest.test_case "250 idle connections do not keep the page from loading"
            `Quick idle_flood;
          Alcotest.test_case
            "the events, the images and the controls refuse other sites and foreign \
             origins"
            `Quick origins;
          Alcotest.test_case "two Host, Origin or Content-Length headers are refused"
            `Quick duplicate_headers;
          Alcotest.test_case
            "an error in a file outside the scene's directory shows its place, not its \
             line"
            `Quick outside_lines;
        ] );
    ]
