(* include "lancer/…" as a user meets it: found from the source tree's build, from an
   installed lancer's share/lancer/, from LANCER_PATH and, with none of those, from the
   copy built into lancer; a file beside the scene comes first. *)

open Run_lancer

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"

let scene =
  {|include "lancer/colors.rts"
include "lancer/materials.rts"
settings { width: 8, height: 6, background: red }
sphere { center: (0, 0, 0), radius: 1, material: glass }
|}

(* The background colour `lancer check --json` reports for [scene] run by [exe] in [dir]. *)
let background ?(prefix = "") ~exe dir =
  let st, out, err = run ~prefix ~exe ~dir [ "check"; "scene.rts"; "--json" ] in
  if st <> 0 then Alcotest.failf "lancer check failed (%d): %s" st err;
  let open Yojson.Safe.Util in
  match
    Yojson.Safe.from_string out |> member "settings" |> member "background" |> to_list
  with
  | [ r; g; b ] -> (to_number r, to_number g, to_number b)
  | _ -> Alcotest.fail "no background"

let with_scene () =
  let d = tmpdir "lancer-library" in
  write_file (Filename.concat d "scene.rts") scene;
  d

let rgb = Alcotest.(triple (float 0.) (float 0.) (float 0.))

let copy src dst =
  write_file dst (read_file src);
  Unix.chmod dst 0o755

(* A copy of lancer in PREFIX/bin, with [colors] as PREFIX/share/lancer/colors.rts. *)
let install ?colors () =
  let prefix = tmpdir "lancer-prefix" in
  Unix.mkdir (Filename.concat prefix "bin") 0o755;
  let lancer = Filename.concat prefix "bin/lancer" in
  copy exe lancer;
  Option.iter
    (fun text ->
      Unix.mkdir (Filename.concat prefix "share") 0o755;
      Unix.mkdir (Filename.concat prefix "share/lancer") 0o755;
      write_file (Filename.concat prefix "share/lancer/colors.rts") text)
    colors;
  lancer

let tests =
  [
    Alcotest.test_case
      "a scene anywhere includes lancer/colors.rts and lancer/materials.rts" `Quick
      (fun () -> Alcotest.check rgb "red" (1., 0., 0.) (background ~exe (with_scene ())));
    Alcotest.test_case "an installed lancer reads PREFIX/share/lancer/" `Quick (fun () ->
        let lancer = install ~colors:"let red = (0, 0, 1)\n" () in
        Alcotest.check rgb "the installed copy's red" (0., 0., 1.)
          (background ~exe:lancer (with_scene ())));
    Alcotest.test_case "with no library on disk, the built-in copy is used" `Quick
      (fun () ->
        let lancer = install () in
        Alcotest.check rgb "red" (1., 0., 0.) (background ~exe:lancer (with_scene ())));
    Alcotest.test_case "LANCER_PATH comes before the installed library" `Quick (fun () ->
        let lancer = install ~colors:"let red = (0, 0, 1)\n" () in
        let lib = tmpdir "lancer-path" in
        Unix.mkdir (Filename.concat lib "lancer") 0o755;
        write_file (Filename.concat lib "lancer/colors.rts") "let red = (0, 1, 0)\n";
        Alcotest.check rgb "LANCER_PATH's red" (0., 1., 0.)
          (background
             ~prefix:("LANCER_PATH=" ^ Filename.quote lib)
             ~exe:lancer (with_scene ())));
    Alcotest.test_case "a lancer/ folder beside the scene comes first" `Quick (fun () ->
        let d = with_scene () in
        Unix.mkdir (Filename.concat d "lancer") 0o755;
        write_file (Filename.concat d "lancer/colors.rts") "let red = (0.5, 0.5, 0.5)\n";
        Alcotest.check rgb "the local red" (0.5, 0.5, 0.5) (background ~exe d));
    Alcotest.test_case "a library file that does not exist is a located error" `Quick
      (fun () ->
        let d = tmpdir "lancer-library" in
        write_file (Filename.concat d "scene.rts") "include \"lancer/nothing.rts\"\n";
        let st, _, err = run ~exe ~dir:d [ "check"; "scene.rts" ] in
        Alcotest.(check int) ("exit 1: " ^ err) 1 st;
        Alcotest.(check bool)
          ("names the file: " ^ err) true
          (contains err
             "scene.rts:1:1: cannot read the included file \"lancer/nothing.rts\": no \
              such file"));
    Alcotest.test_case "every material of the library renders" `Quick (fun () ->
        let d = tmpdir "lancer-library" in
        let names =
          [
            "glass";
            "water";
            "ice";
            "diamond";
            "chrome";
            "silver";
            "gold";
            "copper";
            "mirror";
            "white_marble";
            "oak";
            "plastic";
            "rubber";
          ]
        in
        write_file (Filename.concat d "all.rts")
          ("include \"lancer/materials.rts\"\n\
            settings { width: 8, height: 6 }\n\
            light { position: (0, 5, -5) }\n"
          ^ String.concat ""
              (List.mapi
                 (fun i n ->
                   Printf.sprintf
                     "sphere { center: (%d, 0, 0), radius: 0.4, material: %s }\n" (i - 6)
                     n)
                 names));
        let st, _, err = run ~exe ~dir:d [ "render"; "all.rts"; "-o"; "all.png"; "-q" ] in
        Alcotest.(check int) ("render: " ^ err) 0 st);
  ]

let () = Alcotest.run "library" [ ("include lancer/", tests) ]
