(* Stopping lancer as a user does, with Ctrl-C (SIGINT) or a batch system's SIGTERM: the
   status is 130, the message says it was interrupted, no output or temporary file is left,
   and the stop comes within a couple of seconds whatever the scene. *)

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"

open Run_lancer

let tmpdir () = tmpdir "lancer-intr"
let files d = List.sort compare (Array.to_list (Sys.readdir d))

(* Three parallel half-mirror, half-glass planes at depth 1000: every ray that meets the
   middle one splits into two that stay trapped, so a sample's rays double at every
   bounce. *)
let branching =
  {|settings { width: 64, height: 48, depth: 1000 }
camera { position: (0, 0, -0.5), look_at: (1, 0.3, 0) }
light { position: (0, 5, -0.5) }
let m = material { reflection: 0.5, transparency: 0.5, ior: 1 }
plane { normal: (0, 0, 1), offset: -1, material: m }
plane { normal: (0, 0, 1), offset: 0, material: m }
plane { normal: (0, 0, 1), offset: 1, material: m }
|}

(* lancer in [d] with its stderr in a file; the pid and that file. *)
let spawn d args =
  let err =
    Filename.concat
      (Filename.get_temp_dir_name ())
      (Printf.sprintf "intr-%d-%d.err" (Unix.getpid ()) (Random.bits ()))
  in
  let fd = Unix.openfile err [ Unix.O_WRONLY; Unix.O_CREAT; Unix.O_TRUNC ] 0o644 in
  let null = Unix.openfile "/dev/null" [ Unix.O_RDWR ] 0 in
  let cwd = Sys.getcwd () in
  Sys.chdir d;
  let pid = Unix.create_process exe (Array.of_list (exe :: args)) null null fd in
  Sys.chdir cwd;
  Unix.close fd;
  Unix.close null;
  (pid, err)

(* The threads of a process: a pool of domains adds some once the scene is loaded. *)
let threads pid =
  try Array.length (Sys.readdir (Printf.sprintf "/proc/%d/task" pid))
  with Sys_error _ -> 0

let rec wait_until ?(timeout = 60.) cond =
  if cond () then true
  else if timeout <= 0. then false
  else (
    Unix.sleepf 0.01;
    wait_until ~timeout:(timeout -. 0.01) cond)

(* Wait for [pid] at most [limit] seconds: its status, or None (then it is killed). *)
let wait_for pid limit =
  let t0 = Unix.gettimeofday () in
  let rec go () =
    match Unix.waitpid [ Unix.WNOHANG ] pid with
    | 0, _ when Unix.gettimeofday () -. t0 < limit ->
        Unix.sleepf 0.02;
        go ()
    | 0, _ ->
        Unix.kill pid Sys.sigkill;
        ignore (Unix.waitpid [] pid);
        None
    | _, st -> Some (st, Unix.gettimeofday () -. t0)
  in
  go ()

let interrupted ?(limit = 2.) ~what pid err signal =
  Unix.kill pid signal;
  let r = wait_for pid limit in
  let e = read_file err in
  Sys.remove err;
  match r with
  | None -> Alcotest.failf "%s: still running %.0f s after the signal\n%s" what limit e
  | Some (st, took) ->
      Alcotest.(check bool)
        (Printf.sprintf "%s: exit 130 (stopped in %.2f s)\n%s" what took e)
        true (st = Unix.WEXITED 130);
      Alcotest.(check bool)
        ("says it was interrupted: " ^ e)
        true
        (contains e "lancer: interrupted");
      Alcotest.(check bool)
        ("no internal error: " ^ e) false
        (contains e "internal error" || contains e "Raised at");
      e

let branching_case (name, signal, domains) =
  Alcotest.test_case
    (Printf.sprintf "%s stops rays that double at every bounce within 2 s (%s domain%s)"
       name domains
       (if domains = "1" then "" else "s"))
    `Slow
    (fun () ->
      let d = tmpdir () in
      write_file (Filename.concat d "b.rts") branching;
      let pid, err = spawn d [ "render"; "b.rts"; "-o"; "b.png"; "--domains"; domains ] in
      (* Into the render: the pool's domains have started (or, with one domain, the scene
         has had time to load). *)
      if domains = "1" then Unix.sleepf 1.0
      else ignore (wait_until (fun () -> threads pid > 1));
      Unix.sleepf 0.3;
      ignore (interrupted ~what:name pid err signal);
      Alcotest.(check (list string)) "no output, no temporary file" [ "b.rts" ] (files d))

(* Rays that cost up to seconds each, through CSG objects that fill the picture: polled
   every 4096 rays, such a render would not look at its token again for minutes. The
   intersection of 10 000 spheres a hair apart: a ray through it meets 20 000 surfaces
   and may test the inside of thousands of members between each two. *)
let csg_intersection =
  "camera { position: (0, 0, -6), look_at: (0, 0, 0) }\n\
   light { position: (-3, 5, -5) }\n\
   intersection {\n\
  \  for i in 0 to 9999 { sphere { center: (i * 0.000001, 0, 0), radius: 4.5 } }\n\
   }\n"

(* A slab with [n] small spheres taken out of its front one level at a time, on a
   spiral: a difference nested [n] deep, at 4×4 samples a pixel. *)
let csg_nested n =
  let b = Buffer.create (n * 64) in
  Buffer.add_string b
    "settings { samples: 4 }\n\
     camera { position: (0, 0, -6), look_at: (0, 0, 0) }\n\
     light { position: (-3, 5, -5) }\n";
  for _ = 1 to n do
    Buffer.add_string b "difference {\n"
  done;
  Buffer.add_string b "box { min: (-5, -4, -1), max: (5, 4, 1) }\n";
  for k = 1 to n do
    let a = 2.399963 *. Float.of_int k
    and r = 3.2 *. Float.sqrt (Float.of_int k /. Float.of_int n) in
    Printf.bprintf b "sphere { center: (%.6f, %.6f, -1), radius: 0.15 } }\n"
      (r *. Float.cos a)
      (r *. Float.sin a)
  done;
  Buffer.contents b

(* Whether process [pid] is running (neither gone nor a zombie). *)
let running pid =
  match read_file (Printf.sprintf "/proc/%d/stat" pid) with
  | exception Sys_error _ -> false
  | s -> (
      match String.rindex_opt s ')' with
      | Some i -> i + 2 < String.length s && s.[i + 2] <> 'Z'
      | None -> false)

(* On one domain the signal handler raises at once, wherever the render is; with a pool
   of domains it only cancels the token (see Render.with_pool), and the render stops where
   it next polls it. *)
let csg_case (what, scene) =
  Alcotest.test_case
    (Printf.sprintf "Ctrl-C stops a render through %s within 2 s (2 domains)" what) `Slow
    (fun () ->
      let d = tmpdir () in
      write_file (Filename.concat d "c.rts") scene;
      let pid, err =
        spawn d
          (String.split_on_char ' '
             "render c.rts -o c.png --width 48 --height 36 --domains 2")
      in
      (* Into the render (the pool's domains have started), which takes seconds more. *)
      Alcotest.(check bool)
        "the render starts" true
        (wait_until (fun () -> threads pid > 1));
      Unix.sleepf 0.3;
      Alcotest.(check bool) "still rendering when interrupted" true (running pid);
      ignore (interrupted ~what pid err Sys.sigint);
      Alcotest.(check (list string)) "no output" [ "c.rts" ] (files d))

let tests =
  List.map branching_case
    [
      ("SIGINT", Sys.sigint, "2");
      ("SIGTERM", Sys.sigterm, "2");
      ("SIGINT", Sys.sigint, "1");
    ]
  @ List.map csg_case
      [
        ("an intersection of 10 000 spheres", csg_intersection);
        ("a difference nested 2000 deep", csg_nested 2000);
      ]
  @ [
      Alcotest.test_case
        "Ctrl-C while a scene is evaluated exits 130, not with an internal error" `Slow
        (fun () ->
          let d = tmpdir () in
          write_file
            (Filename.concat d "loop.rts")
            "for i in 0 to 15000000 { let x = sin(i) + cos(i) + sin(i + 1) + cos(i + 1) \
             + sin(i + 2) + cos(i + 2) }\n\
             sphere { center: (0, 0, 0), radius: 1 }\n";
          List.iter
            (fun args ->
              let cmd = List.hd args in
              let pid, err = spawn d args in
              Unix.sleepf 0.5;
              ignore (interrupted ~what:cmd pid err Sys.sigint))
            [ [ "render"; "loop.rts"; "-o"; "loop.png" ]; [ "check"; "loop.rts" ] ];
          Alcotest.(check (list string)) "no output" [ "loop.rts" ] (files d));
      Alcotest.test_case
        "Ctrl-C while animate evaluates a frame's scene stops it within 2 s" `Slow
        (fun () ->
          let d = tmpdir () in
          (* Frame 0 (what loading checks) is instant; frame 1 takes 15 M loop iterations
             of six calls of sin and cos each (seconds), evaluated once the pool of domains
             is running. *)
          write_file (Filename.concat d "a.rts")
            "animation { fps: 10, frames: 3 }\n\
             settings { width: 8, height: 6 }\n\
             for i in 1 to frame * 15000000 { let x = sin(i) + cos(i) + sin(i + 1) + \
             cos(i + 1) + sin(i + 2) + cos(i + 2) }\n\
             sphere { center: (0, 0, 0), radius: 1 }\n";
          let pid, err =
            spawn d
              [ "animate"; "a.rts"; "-o"; "out"; "--frames"; "1..1"; "--domains"; "2" ]
          in
          Alcotest.(check bool)
            "the pool starts" true
            (wait_until (fun () -> threads pid > 1));
          Unix.sleepf 0.3;
          ignore (interrupted ~what:"SIGINT" pid err Sys.sigint);
          Alcotest.(check bool)
            "no frame" false
            (Sys.file_exists (Filename.concat d "out/frame_0001.png")));
      Alcotest.test_case "Ctrl-C stops a render with 200 000 lights within 2 s" `Slow
        (fun () ->
          let d = tmpdir () in
          write_file (Filename.concat d "l.rts")
            "settings { width: 64, height: 48 }\n\
             camera { position: (0, 2, -6), look_at: (0, 0, 0) }\n\
             for i in 1 to 200000 { light { position: (i * 0.001, 5, -5), intensity: \
             0.000001 } }\n\
             plane { normal: (0, 1, 0), offset: 0 }\n";
          let pid, err = spawn d [ "render"; "l.rts"; "-o"; "l.png"; "--domains"; "2" ] in
          Alcotest.(check bool)
            "the render starts" true
            (wait_until (fun () -> threads pid > 1));
          Unix.sleepf 0.3;
          ignore (interrupted ~what:"SIGINT" pid err Sys.sigint);
          Alcotest.(check (list string)) "no output" [ "l.rts" ] (files d));
      Alcotest.test_case "--domains beyond 128 is refused at once, with the bound" `Quick
        (fun () ->
          let ((st, _, e) as _r) =
            run ~exe ~dir:(Sys.getcwd ())
              [ "render"; "--domains"; "100000"; "-o"; "x.png" ]
          in
          Alcotest.(check int) ("exit 1\n" ^ e) 1 st;
          Alcotest.(check bool) e true (contains e "--domains must be at most 128");
          Alcotest.(check bool) "nothing written" false (Sys.file_exists "x.png"));
    ]

(* The address space of a running process in KiB; None once it has ended. *)
let vm_kib pid =
  match
    In_channel.with_open_text (Printf.sprintf "/proc/%d/status" pid) In_channel.input_all
  with
  | exception Sys_error _ -> None
  | text ->
      List.find_map
        (fun l -> Scanf.sscanf_opt l "VmSize: %d kB" Fun.id)
        (String.split_on_char '\n' text)

let showcase = Filename.concat (Sys.getcwd ()) "../../scenes/showcase.rts"

let early_tests =
  [
    Alcotest.test_case
      "SIGINT or SIGTERM within 5 ms of start-up (300 runs): exit 130, or 0 when done \
       first; never the signal's death"
      `Slow (fun () ->
        let d = tmpdir () in
        (* Evaluated for some 40 ms: a signal within 5 ms of start-up comes while it runs,
           however busy the machine, where --version or the showcase may be over. *)
        let slow = Filename.concat d "slow.rts" in
        write_file slow
          "for i in 0 to 400000 { let x = sin(i) + cos(i) }\n\
           sphere { center: (0, 0, 0), radius: 1 }\n";
        let rng = Random.State.make [| 13 |] in
        let null = Unix.openfile "/dev/null" [ Unix.O_RDWR ] 0 in
        let slow_interrupted = ref 0 and wrong = ref [] in
        for k = 1 to 300 do
          let args =
            match k mod 3 with
            | 0 -> [ "--version" ]
            | 1 -> [ "check"; showcase ]
            | _ -> [ "check"; slow ]
          in
          let signal, name =
            if Random.State.bool rng then (Sys.sigint, "SIGINT")
            else (Sys.sigterm, "SIGTERM")
          in
          let delay = Random.State.float rng 0.005 in
          let pid =
            Unix.create_process exe (Array.of_list (exe :: args)) null null null
          in
          (* The delay counts from the moment the OCaml runtime has started (it reserves
             256 MiB for the domains' minor heaps when no ulimit -v is set): before
             lancer's own code runs, the kernel and the dynamic loader are still loading
             it, and there no program can handle a signal. The libraries' initialisation,
             then lancer's, follow within these milliseconds. *)
          let t0 = Unix.gettimeofday () in
          let rec started () =
            match vm_kib pid with
            | Some kib when kib < 131072 && Unix.gettimeofday () -. t0 < 5. -> started ()
            | _ -> ()
          in
          started ();
          Unix.sleepf delay;
          Unix.kill pid signal;
          match snd (Unix.waitpid [] pid) with
          | Unix.WEXITED 130 -> if k mod 3 = 2 then incr slow_interrupted
          | Unix.WEXITED 0 -> ()
          | st ->
              let how = status_text st in
              wrong :=
                Printf.sprintf "%s %s after %.2f ms: %s" (String.concat " " args) name
                  (delay *. 1000.) how
                :: !wrong
        done;
        Unix.close null;
        Alcotest.(check (list string)) "every run exits 130 or 0" [] (List.rev !wrong);
        (* Signals that came while lancer ran, not only after it had finished. *)
        Alcotest.(check bool)
          (Printf.sprintf "most of the slow scene's 100 runs interrupted (%d)"
             !slow_interrupted)
          true (!slow_interrupted >= 50));
  ]

let is_temp f = String.length f > 0 && f.[0] = '.' && contains f ".tmp"

let write_tests =
  [
    Alcotest.test_case
      "Ctrl-C while the PNG is written: exit 130, a whole image, no temporary file" `Slow
      (fun () ->
        let d = tmpdir () in
        (* Nothing to hit: the render is quick and the encoder has 9 M pixels to compress
           (for seconds) before the file's bytes are written. The last tile's progress line
           says the render is over and the write has begun. *)
        write_file (Filename.concat d "e.rts")
          "settings { width: 3000, height: 3000, background: (0.2, 0.4, 0.6) }\n";
        let pid, err =
          spawn d [ "render"; "e.rts"; "-o"; "e.png"; "--domains"; "1"; "--progress" ]
        in
        let writing () = contains (read_file err) "(100%)" in
        Alcotest.(check bool) "the write starts" true (wait_until ~timeout:60. writing);
        Unix.sleepf 0.2;
        let e = interrupted ~limit:20. ~what:"SIGINT" pid err Sys.sigint in
        Alcotest.(check bool)
          ("no Finally_raised: " ^ e) false (contains e "Finally_raised");
        Alcotest.(check (list string))
          "the image, no temporary file" [ "e.png"; "e.rts" ] (files d);
        match Lancer.Image.read_rgb8 (Filename.concat d "e.png") with
        | Ok (w, h, _) -> Alcotest.(check (pair int int)) "whole" (3000, 3000) (w, h)
        | Error m -> Alcotest.fail m);
  ]

let stdout_tests =
  [
    Alcotest.test_case
      "standard output on a full device is a user error, exit 1, with the reason" `Quick
      (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts") "sphere { center: (0, 0, 0), radius: 1 }\n";
        List.iter
          (fun args ->
            let cmd =
              Printf.sprintf "cd %s && %s %s >/dev/full 2>err.txt" (Filename.quote d)
                (Filename.quote exe) (String.concat " " args)
            in
            let st = Sys.command cmd in
            let e = read_file (Filename.concat d "err.txt") in
            Alcotest.(check int) (String.concat " " args ^ ": exit 1\n" ^ e) 1 st;
            Alcotest.(check bool)
              e true
              (contains e
                 "lancer: cannot write to standard output: No space left on device");
            Alcotest.(check bool)
              e false
              (contains e "internal error" || contains e "Fatal error"))
          [
            [ "check"; "s.rts" ];
            [ "check"; "s.rts"; "--json" ];
            [ "render"; "s.rts"; "-o"; "s.png"; "--width"; "8"; "--height"; "6" ];
          ]);
  ]

(* lancer in [d] through the shell, with [redirect] (">/dev/full", ">&-") on its standard
   output and stderr in a file: the status as [Sys.command] gives it (255 for a death by
   signal, 2 for OCaml's "Fatal error") and stderr. *)
let shell d redirect args =
  let err = Filename.concat d "err.txt" in
  let st =
    Sys.command
      (Printf.sprintf "cd %s && TERM=dumb %s %s %s 2>%s" (Filename.quote d)
         (Filename.quote exe)
         (String.concat " " (List.map Filename.quote args))
         redirect (Filename.quote err))
  in
  let e = read_file err in
  Sys.remove err;
  (st, e)

let stdout_refused ~what (st, e) =
  Alcotest.(check int) (what ^ ": exit 1\n" ^ e) 1 st;
  Alcotest.(check bool)
    (what ^ ": says that standard output cannot be written\n" ^ e)
    true
    (String.starts_with ~prefix:"lancer: cannot write" e && contains e "standard output");
  Alcotest.(check bool)
    (what ^ ": one message, no Fatal error\n" ^ e)
    false
    (contains e "Fatal error" || contains e "internal error" || contains e "exception")

let closed_stdout_tests =
  (* Lit, so that render has no warning to print before the message looked for. *)
  let scene d =
    write_file (Filename.concat d "s.rts")
      "light { position: (0, 5, -5) }\nsphere { center: (0, 0, 0), radius: 1 }\n"
  in
  [
    Alcotest.test_case
      "--help, --version and -o - on a full or closed standard output: exit 1, one line"
      `Quick (fun () ->
        let d = tmpdir () in
        scene d;
        List.iter
          (fun redirect ->
            List.iter
              (fun args ->
                stdout_refused
                  ~what:(String.concat " " args ^ " " ^ redirect)
                  (shell d redirect args))
              [
                [ "--version" ];
                [ "--help" ];
                [ "--help=plain" ];
                [ "render"; "--help=plain" ];
                [ "check"; "s.rts" ];
                [ "render"; "s.rts"; "-o"; "-"; "--width"; "8"; "--height"; "6" ];
              ])
          [ ">/dev/full"; ">&-" ]);
    Alcotest.test_case
      "with standard output closed, descriptor 1 stays unused and the summary is refused"
      `Slow (fun () ->
        let d = tmpdir () in
        let err = Filename.concat d "err.txt" in
        let fd = Unix.openfile err [ Unix.O_WRONLY; Unix.O_CREAT; Unix.O_TRUNC ] 0o644 in
        let null = Unix.openfile "/dev/null" [ Unix.O_RDWR ] 0 in
        let pid =
          Unix.create_process "/bin/sh"
            [|
              "/bin/sh";
              "-c";
              "exec \"$0\" \"$@\" >&-";
              exe;
              "render";
              "-o";
              Filename.concat d "s.png";
              "--width";
              "320";
              "--height";
              "240";
              "--domains";
              "2";
            |]
            null null fd
        in
        Unix.close fd;
        Unix.close null;
        (* Once the render runs, every library has started and opened what it keeps
           open: a descriptor it took while 1 was free would be 1. *)
        Alcotest.(check bool)
          "the render starts" true
          (wait_until (fun () -> threads pid > 1));
        let one =
          try Unix.readlink (Printf.sprintf "/proc/%d/fd/1" pid) with _ -> "?"
        in
        let _, st = Unix.waitpid [] pid in
        let e = read_file err in
        Alcotest.(check string) "descriptor 1 is /dev/null" "/dev/null" one;
        Alcotest.(check bool) ("exit 1\n" ^ e) true (st = Unix.WEXITED 1);
        Alcotest.(check string)
          "the message" "lancer: cannot write to standard output: it is closed\n" e;
        (match Lancer.Image.read_rgb8 (Filename.concat d "s.png") with
        | Ok (w, h, _) ->
            Alcotest.(check (pair int int)) "the whole image" (320, 240) (w, h)
        | Error m -> Alcotest.fail ("s.png: " ^ m));
        Alcotest.(check (list string)) "no other file" [ "err.txt"; "s.png" ] (files d));
  ]

let () =
  Alcotest.run "interrupts"
    [
      ("stopping", tests);
      ("starting", early_tests);
      ("writing", write_tests);
      ("stdout", stdout_tests @ closed_stdout_tests);
    ]
