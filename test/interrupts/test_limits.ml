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
  "settings { width: 32, height: 24 }\ncamera { position: (0, 1, -5), look_at: (0, 0.5, 0) }\n\
   light { position: (-3, 5, -4) }\nplane { normal: (0, 1, 0), offset: 0 }\n\
   sphere { center: (0, 1, 0), radius: 1, material: material { reflection: 0.3 } }\n"

let refused ?prefix ~what d args expect =
  let st, _, e = lancer ?prefix d args in
  Alcotest.(check int) (what ^ ": exit 1\n" ^ e) 1 st;
  Alcotest.(check bool) (what ^ ": " ^ e) true (contains e expect);
  Alcotest.(check bool) (what ^ ": no internal error\n" ^ e) false (contains e "internal error" || contains e "Fatal error");
  e

let memory_tests =
  [ Alcotest.test_case "under ulimit -v 1500000 a render on two domains works" `Quick (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "s.rts") small;
        let st, _, e = lancer ~prefix:"ulimit -v 1500000;" d [ "render"; "s.rts"; "-o"; "s.png"; "--domains"; "2"; "-q" ] in
        Alcotest.(check int) ("exit 0\n" ^ e) 0 st;
        Alcotest.(check bool) "the image" true (Sys.file_exists (Filename.concat d "s.png")));
    Alcotest.test_case "more objects than the memory limit can hold are refused before they are built, located" `Quick (fun () ->
        let d = tmpdir () in
        write_file (Filename.concat d "many.rts") "for i in 0 to 3999999 { sphere { center: (i, 0, 0), radius: 0.5 } }\n";
        write_file (Filename.concat d "macro.rts")
          "fn ball(i) { sphere { center: (i, 0, 0), radius: 0.5 } }\nfor i in 0 to 3999999 { ball(i) }\n";
        let e = refused ~prefix:"ulimit -v 1000000;" ~what:"a loop" d [ "check"; "many.rts" ] "many.rts:1:1: 4.0 million objects need about" in
        Alcotest.(check bool) e true (contains e "ulimit -v");
        ignore (refused ~prefix:"ulimit -v 1000000;" ~what:"a macro in a loop" d [ "render"; "macro.rts"; "-o"; "m.png" ] "macro.rts:1:14: ");
        Alcotest.(check (list string)) "no output" [ "macro.rts"; "many.rts" ] (files d)) ]

let () = Alcotest.run "limits" [ ("memory", memory_tests) ]
