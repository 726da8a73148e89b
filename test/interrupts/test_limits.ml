(* lancer's limits as a user meets them: memory limits set by a batch system, sizes and
   times past what lancer supports, inputs that are not plain files, outputs that cannot
   be written. Each is refused at once with a message, exit status 1, and no output, or
   works. *)

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"

open Run_lancer

let tmpdir () = tmpdir "lancer-limits"
let files d = List.sort compare (Array.to_list (Sys.readdir d))
let lancer ?prefix d args = run ?prefix ~exe ~dir:d args

let small =
  "settings { width: 32, height: 24 }\n\
   camera { position: (0, 1, -5), look_at: (0, 0.5, 0) }\n\
   light { position: (-3, 5, -4) }\n\
   plane { normal: (0, 1, 0), offset: 0 }\n\
   sphere { center: (0, 1, 0), radius: 1, material: material { reflection: 0.3 } }\n"

let refused ?prefix ~what d args expect =
  let st, _, e = lancer ?prefix d args in
  Alcotest.(check int) (what ^ ": exit 1\n" ^ e) 1 st;
  Alcotest.(check bool) (what ^ ": " ^ e) true (contains e expect);
  Alcotest.(check bool)
    (what ^ ": no internal error\n" ^ e)
    false
    (contains e "internal error" || contains e "Fatal error");
  e

let memory_tests =
  [
    Alcotest.test_case "under ulimit -v 1500000 a render on two domains works" `Quick
      (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts") small;
        let st, _, e =
          lancer ~prefix:"ulimit -v 1500000;" d
            [ "render"; "s.rts"; "-o"; "s.png"; "--domains"; "2"; "-q" ]
        in
        Alcotest.(check int) ("exit 0\n" ^ e) 0 st;
        Alcotest.(check bool)
          "the image" true
          (Sys.file_exists (Filename.concat d "s.png")));
    Alcotest.test_case
      "more objects than the memory limit can hold are refused before they are built, \
       located"
      `Quick (fun () ->
        let d = tmpdir () in
        write_file
          (Filename.concat d "many.rts")
          "for i in 0 to 3999999 { sphere { center: (i, 0, 0), radius: 0.5 } }\n";
        write_file
          (Filename.concat d "macro.rts")
          "fn ball(i) { sphere { center: (i, 0, 0), radius: 0.5 } }\n\
           for i in 0 to 3999999 { ball(i) }\n";
        let e =
          refused ~prefix:"ulimit -v 1000000;" ~what:"a loop" d [ "check"; "many.rts" ]
            "many.rts:1:1: 4.0 million objects need about"
        in
        Alcotest.(check bool) e true (contains e "ulimit -v");
        ignore
          (refused ~prefix:"ulimit -v 1000000;" ~what:"a macro in a loop" d
             [ "render"; "macro.rts"; "-o"; "m.png" ]
             "macro.rts:1:14: ");
        Alcotest.(check (list string)) "no output" [ "macro.rts"; "many.rts" ] (files d));
  ]

(* lancer [args] in [d] under ulimit -v [kib], its standard output thrown away: how it
   ended, and stderr. *)
let limited d kib args =
  let err = Filename.concat d "err.txt" in
  let null = Unix.openfile "/dev/null" [ Unix.O_RDWR ] 0 in
  let fd = Unix.openfile err [ Unix.O_WRONLY; Unix.O_CREAT; Unix.O_TRUNC ] 0o644 in
  let cwd = Sys.getcwd () in
  Sys.chdir d;
  let script = Printf.sprintf "ulimit -v %d; exec \"$0\" \"$@\"" kib in
  let pid =
    Unix.create_process "/bin/sh"
      (Array.of_list ("/bin/sh" :: "-c" :: script :: exe :: args))
      null null fd
  in
  Sys.chdir cwd;
  Unix.close fd;
  Unix.close null;
  let _, st = Unix.waitpid [] pid in
  let e = read_file err in
  Sys.remove err;
  (st, e)

let showcase = Filename.concat (Sys.getcwd ()) "../../scenes/showcase.rts"

let sweep_tests =
  [
    Alcotest.test_case
      "from 250 MB to 1 GB of ulimit -v, lancer works or says it is out of memory (exit \
       1), from start-up on"
      `Slow (fun () ->
        let d = tmpdir () in
        let commands =
          [
            [ "--version" ];
            [ "check"; showcase ];
            (* The built-in showcase. *)
            [
              "render";
              "--width";
              "640";
              "--height";
              "480";
              "--quality";
              "draft";
              "-o";
              "s.png";
            ];
            [
              "render";
              "--width";
              "8000";
              "--height";
              "8000";
              "--quality";
              "draft";
              "-o";
              "big.png";
            ];
            (* More domains than the limit has room for. *)
            [
              "render";
              "--width";
              "64";
              "--height";
              "48";
              "--domains";
              "64";
              "-o";
              "d.png";
            ];
          ]
        in
        let wrong = ref [] in
        for step = 0 to 15 do
          let kib = 250_000 + (step * 50_000) in
          List.iter
            (fun args ->
              let st, e = limited d kib args in
              let ok =
                match st with
                | Unix.WEXITED 0 -> not (contains e "Fatal error")
                | Unix.WEXITED 1 ->
                    String.starts_with ~prefix:"lancer: out of memory" e
                    && List.length (String.split_on_char '\n' (String.trim e)) = 1
                | _ -> false
              in
              if not ok then
                let how = status_text st in
                wrong :=
                  Printf.sprintf "ulimit -v %d; lancer %s: %s\n%s" kib
                    (String.concat " " args) how e
                  :: !wrong)
            commands
        done;
        Alcotest.(check (list string))
          "exit 0, or exit 1 with one line \"lancer: out of memory …\"" []
          (List.rev !wrong));
    Alcotest.test_case
      "under ulimit -v 250000 lancer starts; under 300000 a render asked for 8 domains \
       works"
      `Quick (fun () ->
        let d = tmpdir () in
        let st, e = limited d 250_000 [ "--version" ] in
        Alcotest.(check bool) ("--version: exit 0\n" ^ e) true (st = Unix.WEXITED 0);
        let st, e =
          limited d 300_000
            [
              "render"; "--width"; "64"; "--height"; "48"; "--domains"; "8"; "-o"; "s.png";
            ]
        in
        Alcotest.(check bool) ("render: exit 0\n" ^ e) true (st = Unix.WEXITED 0);
        match Lancer.Image.read_rgb8 (Filename.concat d "s.png") with
        | Ok (w, h, _) -> Alcotest.(check (pair int int)) "the image" (64, 48) (w, h)
        | Error m -> Alcotest.fail m);
  ]

let options_tests =
  [
    Alcotest.test_case
      "--width and --height above 65536 are refused as the options are read" `Quick
      (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts") small;
        ignore
          (refused ~what:"--width" d
             [ "render"; "s.rts"; "-o"; "s.png"; "--width"; "70000"; "--height"; "1" ]
             "must be 1 to 65536 pixels (got 70000)");
        ignore
          (refused ~what:"--height" d
             [ "render"; "s.rts"; "-o"; "s.png"; "--height"; "65537" ]
             "--height");
        Alcotest.(check (list string)) "no output" [ "s.rts" ] (files d));
    Alcotest.test_case "--time 2.3e18 is refused, not turned into a negative frame" `Quick
      (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts")
          ("animation { fps: 24, frames: 10 }\n" ^ small);
        ignore
          (refused ~what:"render" d
             [ "render"; "s.rts"; "-o"; "s.png"; "--time"; "2.3e18" ]
             "--time must be within");
        ignore
          (refused ~what:"check" d
             [ "check"; "s.rts"; "--time"; "2.3e18" ]
             "--time must be within");
        Alcotest.(check (list string)) "no output" [ "s.rts" ] (files d));
  ]

let input_tests =
  [
    Alcotest.test_case
      "an include of a device, a FIFO or a huge file is refused from its status, located"
      `Quick (fun () ->
        let d = tmpdir () in
        let p = Filename.concat d in
        Unix.mkfifo (p "fifo.rts") 0o644;
        (* Sparse: 100 MB that take no room, and that nobody reads. *)
        Unix.close (Unix.openfile (p "big.rts") [ Unix.O_WRONLY; Unix.O_CREAT ] 0o644);
        Unix.truncate (p "big.rts") 100_000_000;
        List.iter
          (fun (name, target, expect) ->
            write_file (p name)
              (Printf.sprintf "sphere { center: (0, 0, 0), radius: 1 }\ninclude \"%s\"\n"
                 target);
            ignore
              (refused ~what:name d [ "check"; name ]
                 (Printf.sprintf "%s:2:1: cannot read the included file \"%s\": %s" name
                    target expect)))
          [
            ("zero.rts", "/dev/zero", "it is a device");
            ("fifo_inc.rts", "fifo.rts", "it is a pipe (FIFO)");
            ("big_inc.rts", "big.rts", "it is 100 MB; a scene file may be at most 64 MB");
          ];
        ignore
          (refused ~what:"a FIFO as the scene" d [ "check"; "fifo.rts" ]
             "fifo.rts: cannot read the scene: it is a pipe");
        ignore
          (refused ~what:"a device as the scene" d
             [ "render"; "/dev/zero"; "-o"; "z.png" ]
             "/dev/zero: cannot read the scene: it is a device"));
    Alcotest.test_case
      "an output directory that cannot be written is refused before rendering" `Quick
      (fun () ->
        let d = tmpdir () in
        (* Long to render: the refusal must come first. *)
        write_file (Filename.concat d "s.rts") small;
        let t0 = Unix.gettimeofday () in
        (* No process may create files in /proc, not even root. *)
        ignore
          (refused ~what:"-o" d
             [
               "render";
               "s.rts";
               "-o";
               "/proc/lancer-out.png";
               "--width";
               "4000";
               "--height";
               "4000";
               "--samples";
               "4";
             ]
             "cannot write /proc/lancer-out.png");
        ignore
          (refused ~what:"--stats" d
             [
               "render";
               "s.rts";
               "-o";
               "s.png";
               "--stats";
               "/proc/lancer-stats.json";
               "--width";
               "4000";
               "--height";
               "4000";
             ]
             "cannot write /proc/lancer-stats.json");
        Alcotest.(check bool) "refused at once" true (Unix.gettimeofday () -. t0 < 10.);
        Alcotest.(check (list string)) "no output, no probe left" [ "s.rts" ] (files d));
  ]

let rays_tests =
  [
    Alcotest.test_case
      "the ray estimate of a branching scene stops at the bound on rays per sample" `Quick
      (fun () ->
        let text =
          "settings { width: 8, height: 6, depth: 1000 }\n\
           light { position: (0, 5, -0.5) }\n\
           let m = material { reflection: 0.5, transparency: 0.5, ior: 1 }\n\
           plane { normal: (0, 0, 1), offset: 0, material: m }\n"
        in
        match Lancer.Program.load_string text with
        | Error _ -> Alcotest.fail "the scene does not load"
        | Ok prog -> (
            match Lancer.Program.scene_at prog ~time:0. ~frame:0 with
            | Error _ -> Alcotest.fail "the scene does not evaluate"
            | Ok sc ->
                let c = Lancer.Cost.estimate sc in
                (* 48 camera rays, each with 65 536 secondary rays at most, every ray
                   casting its one shadow ray. *)
                Alcotest.(check (float 1.))
                  "bound"
                  (48. *. Float.of_int (1 + Lancer.Shade.max_secondary) *. 2.)
                  c.bound));
  ]

let () =
  Alcotest.run "limits"
    [
      ("rays", rays_tests);
      ("memory", memory_tests);
      ("memory from start-up", sweep_tests);
      ("options", options_tests);
      ("inputs and outputs", input_tests);
    ]
