(* The page of lancer watch in a real browser: headless Chromium, driven over the DevTools
   protocol on a pipe (file descriptors 3 and 4). It loads the page, waits for the image,
   saves the scene with another colour and checks from screenshots that the picture
   changed by itself; then breaks the scene and checks that a screenshot shows the error
   over the image. With LANCER_WATCH_SHOTS=DIR the screenshots are kept in DIR. Skipped,
   saying so, only when Chromium cannot be started at all. *)

open Watch_client

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"

let scene colour =
  Printf.sprintf
    {|// A sphere on a floor.
settings { width: 160, height: 120 }
camera { position: (0, 1.2, -3.2), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
plane { normal: (0, 1, 0), offset: 0, material: material { texture: checker((0.9, 0.9, 0.9), (0.3, 0.3, 0.35), 0.5) } }
sphere { center: (0, 1, 0), radius: 1.6, material: material { color: %s } }
|}
    colour

(* ---- A DevTools client over the pipe: JSON messages, each ended by a NUL byte. ---- *)

type cdp = {
  pid : int;
  cmd : Unix.file_descr;
  resp : Unix.file_descr;
  buf : Buffer.t;
  mutable id : int;
  profile : string;
}

let chromium_flags profile =
  [
    "--headless";
    "--no-sandbox";
    "--disable-gpu";
    "--no-first-run";
    "--disable-background-networking";
    "--disable-component-update";
    "--disable-sync";
    "--user-data-dir=" ^ profile;
    "--remote-debugging-pipe";
    "--window-size=800,600";
    "--hide-scrollbars";
    "about:blank";
  ]

let launch dir =
  let profile = Run_lancer.tmpdir "lancer-chromium" in
  let cmd_r, cmd_w = Unix.pipe ~cloexec:true () in
  let resp_r, resp_w = Unix.pipe ~cloexec:true () in
  let log =
    Unix.openfile
      (Filename.concat dir "chromium.log")
      [ O_WRONLY; O_CREAT; O_TRUNC; O_CLOEXEC ]
      0o644
  in
  (* The shell moves the two pipes to descriptors 3 and 4, where Chromium expects them. *)
  let args =
    [ "sh"; "-c"; "exec 3<&0 4>&1 </dev/null >/dev/null; exec \"$@\""; "sh"; "chromium" ]
    @ chromium_flags profile
  in
  let pid = Unix.create_process "sh" (Array.of_list args) cmd_r resp_w log in
  Unix.close cmd_r;
  Unix.close resp_w;
  Unix.close log;
  { pid; cmd = cmd_w; resp = resp_r; buf = Buffer.create 65536; id = 0; profile }

let rec read_message c ~deadline =
  let s = Buffer.contents c.buf in
  match String.index_opt s '\000' with
  | Some i ->
      let rest = String.sub s (i + 1) (String.length s - i - 1) in
      Buffer.clear c.buf;
      Buffer.add_string c.buf rest;
      Some (Yojson.Safe.from_string (String.sub s 0 i))
  | None -> (
      let left = deadline -. Unix.gettimeofday () in
      if left <= 0. then None
      else
        match Unix.select [ c.resp ] [] [] left with
        | [], _, _ -> None
        | _ -> (
            let b = Bytes.create 65536 in
            match Unix.read c.resp b 0 65536 with
            | 0 -> None
            | n ->
                Buffer.add_subbytes c.buf b 0 n;
                read_message c ~deadline)
        | exception Unix.Unix_error (Unix.EINTR, _, _) -> read_message c ~deadline)

(* Send a command and wait for its answer (events in between are dropped). *)
let call ?session ?(timeout = 60.) c meth params =
  c.id <- c.id + 1;
  let id = c.id in
  let msg =
    `Assoc
      ([ ("id", `Int id); ("method", `String meth); ("params", `Assoc params) ]
      @ match session with Some s -> [ ("sessionId", `String s) ] | None -> [])
  in
  let text = Yojson.Safe.to_string msg ^ "\000" in
  let rec write off =
    if off < String.length text then
      write (off + Unix.write_substring c.cmd text off (String.length text - off))
  in
  write 0;
  let deadline = Unix.gettimeofday () +. timeout in
  let rec wait () =
    match read_message c ~deadline with
    | None ->
        failwith (Printf.sprintf "Chromium did not answer %s within %.0f s" meth timeout)
    | Some j when to_int (member "id" j) = id ->
        if member "error" j <> `Null then
          failwith (meth ^ ": " ^ Yojson.Safe.to_string (member "error" j));
        member "result" j
    | Some _ -> wait ()
  in
  wait ()

let close c =
  (try ignore (call ~timeout:10. c "Browser.close" []) with _ -> ());
  Unix.close c.cmd;
  let deadline = Unix.gettimeofday () +. 20. in
  let rec wait () =
    match Unix.waitpid [ Unix.WNOHANG ] c.pid with
    | 0, _ when Unix.gettimeofday () < deadline ->
        Unix.sleepf 0.1;
        wait ()
    | 0, _ ->
        (try Unix.kill c.pid Sys.sigkill with _ -> ());
        ignore (Unix.waitpid [] c.pid)
    | _ -> ()
    | exception Unix.Unix_error (Unix.EINTR, _, _) -> wait ()
  in
  wait ();
  Unix.close c.resp;
  ignore (Sys.command ("rm -rf " ^ Filename.quote c.profile))

(* The value of a JavaScript expression in the page. *)
let eval c session expr =
  let r =
    call ~session c "Runtime.evaluate"
      [ ("expression", `String expr); ("returnByValue", `Bool true) ]
  in
  member "value" (member "result" r)

let until c session what expr =
  let deadline = Unix.gettimeofday () +. 90. in
  let rec go () =
    if eval c session expr = `Bool true then ()
    else if Unix.gettimeofday () > deadline then failwith ("the page never showed " ^ what)
    else (
      Unix.sleepf 0.1;
      go ())
  in
  go ()

let screenshot c session dir name =
  let r = call ~session c "Page.captureScreenshot" [ ("format", `String "png") ] in
  let png = Base64.decode_exn (to_string (member "data" r)) in
  let path = Filename.concat dir name in
  Run_lancer.write_file path png;
  (match Sys.getenv_opt "LANCER_WATCH_SHOTS" with
  | Some keep when keep <> "" -> Run_lancer.write_file (Filename.concat keep name) png
  | _ -> ());
  match Lancer.Image.read_rgb8 path with Ok i -> i | Error m -> failwith m

(* Share of the pixels in a rectangle for which [f r g b] holds. *)
let share (w, _, bytes) (x0, y0, x1, y1) f =
  let n = ref 0 and hit = ref 0 in
  for y = y0 to y1 - 1 do
    for x = x0 to x1 - 1 do
      let k = 3 * ((y * w) + x) in
      let ch i = Char.code (Bytes.get bytes (k + i)) in
      incr n;
      if f (ch 0) (ch 1) (ch 2) then incr hit
    done
  done;
  Float.of_int !hit /. Float.of_int (max 1 !n)

let test () =
  let dir = Run_lancer.tmpdir "lancer-browser" in
  let path = Filename.concat dir "s.rts" in
  Run_lancer.write_file path (scene "(0.9, 0.1, 0.1)");
  let s = start ~exe ~dir [ "s.rts" ] in
  let c = launch dir in
  Fun.protect
    ~finally:(fun () ->
      close c;
      ignore (stop s))
    (fun () ->
      let target = call c "Target.createTarget" [ ("url", `String "about:blank") ] in
      let session =
        to_string
          (member "sessionId"
             (call c "Target.attachToTarget"
                [ ("targetId", member "targetId" target); ("flatten", `Bool true) ]))
      in
      ignore
        (call ~session c "Emulation.setDeviceMetricsOverride"
           [
             ("width", `Int 960);
             ("height", `Int 400);
             ("deviceScaleFactor", `Int 1);
             ("mobile", `Bool false);
           ]);
      ignore
        (call ~session c "Page.navigate"
           [ ("url", `String (Printf.sprintf "http://127.0.0.1:%d/" s.port)) ]);
      let finished = "document.getElementById('state').textContent.startsWith('done')" in
      until c session "the full image" finished;
      (* Where the picture is on the page. *)
      let rect =
        match
          eval c session
            "(() => { const r = document.getElementById('img').getBoundingClientRect(); \
             return [r.left, r.top, r.right, r.bottom].map(Math.round); })()"
        with
        | `List [ `Int x0; `Int y0; `Int x1; `Int y1 ] -> (x0, y0, x1, y1)
        | j -> failwith ("no picture on the page: " ^ Yojson.Safe.to_string j)
      in
      let x0, y0, x1, y1 = rect in
      Alcotest.(check (pair int int))
        "the picture at its size" (160, 120)
        (x1 - x0, y1 - y0);
      let red = screenshot c session dir "red.png" in
      let reddish r g b = r > g + 60 && r > b + 60
      and bluish r g b = b > r + 60 && b > g + 30 in
      Alcotest.(check bool)
        "the screenshot shows the red sphere" true
        (share red rect reddish > 0.15);
      (* Saved with another colour: the page changes by itself. *)
      let seq = eval c session "document.getElementById('img').src" in
      atomic_write path (scene "(0.1, 0.2, 0.9)");
      until c session "a new image"
        (Printf.sprintf "document.getElementById('img').src !== %s && %s"
           (Yojson.Safe.to_string seq) finished);
      let blue = screenshot c session dir "blue.png" in
      Alcotest.(check bool) "no red left" true (share blue rect reddish < 0.01);
      Alcotest.(check bool)
        "the screenshot shows the blue sphere" true
        (share blue rect bluish > 0.15);
      (* A broken scene: the error over the last good image. *)
      atomic_write path
        (scene "(0.1, 0.2, 0.9)" ^ "sphere { center: (0, 1, 0), radiu: 1 }\n");
      until c session "the error"
        "document.getElementById('err').style.display === 'block'";
      let text =
        to_string (eval c session "document.getElementById('err').textContent")
      in
      Alcotest.(check bool)
        ("the located error: " ^ text)
        true
        (Run_lancer.contains text "s.rts:7:"
        && Run_lancer.contains text "^^^^^"
        && Run_lancer.contains text "did you mean `radius`?");
      let state () =
        to_string (eval c session "document.getElementById('state').textContent")
      in
      Alcotest.(check bool)
        ("the status line says the scene has an error: " ^ state ())
        true
        (Run_lancer.contains (state ()) "the scene has an error");
      (* A page opened now gets the last image and the error together: once the image is
         in, the status line still names the error, not "done". *)
      ignore
        (call ~session c "Page.navigate"
           [ ("url", `String (Printf.sprintf "http://127.0.0.1:%d/" s.port)) ]);
      until c session "the image and the error on a new page"
        "document.getElementById('err').style.display === 'block' && \
         document.getElementById('img').src.includes('/image/') && \
         document.getElementById('img').complete";
      Alcotest.(check bool)
        ("the status line of a new page under the error: " ^ state ())
        true
        (Run_lancer.contains (state ()) "the scene has an error"
        && not (Run_lancer.contains (state ()) "done"));
      let broken = screenshot c session dir "error.png" in
      let panel r g b = r > 60 && r > g + 40 && r > b + 40 in
      let band = (x0, y1 - 20, x1, y1) in
      Alcotest.(check bool)
        "the screenshot shows the error panel" true
        (share broken band panel > 0.5);
      Alcotest.(check bool)
        "and the last good image above it" true
        (share broken (x0, y0, x1, y0 + 40) bluish +. share broken rect bluish > 0.05);
      (* Fixed: the panel goes. *)
      atomic_write path (scene "(0.1, 0.9, 0.1)");
      until c session "the error cleared"
        (Printf.sprintf "document.getElementById('err').style.display === 'none' && %s"
           finished);
      let fixed = screenshot c session dir "fixed.png" in
      Alcotest.(check bool) "no error panel" true (share fixed band panel < 0.05))

let () =
  Sys.set_signal Sys.sigpipe Sys.Signal_ignore;
  let can_start =
    Sys.command
      "command -v chromium >/dev/null 2>&1 && timeout 60 chromium --headless \
       --no-sandbox --disable-gpu --version >/dev/null 2>&1"
    = 0
  in
  if not can_start then (
    prerr_endline
      "the browser test of lancer watch: chromium cannot be started here (make deps \
       installs it)";
    exit 1)
  else
    Alcotest.run "browser"
      [
        ( "watch page",
          [ Alcotest.test_case "live update and the error panel in Chromium" `Quick test ]
        );
      ]
