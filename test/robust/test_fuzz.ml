(* The OBJ loader and the image decoder under random and mutated input (fixed seeds):
   whatever the bytes, an Ok that makes sense or a one-line error, never an exception.
   Plus hand-made hostile files that random mutation is unlikely to produce: PNG headers
   with valid checksums and absurd sizes, PPM headers that lie about their size. *)
open Lancer
module G = Fuzz_gen

let seeded seed t = QCheck_alcotest.to_alcotest ~rand:(Random.State.make [| seed |]) t

(* A property over a seed: the generator runs from its own state, so a failing case is
   reported with the seed that replays it (FUZZ_SEED=<seed> FUZZ_SECONDS=0 fuzz.exe). *)
let prop ~name ~count gen check =
  QCheck.Test.make ~name ~count
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let input = gen (Random.State.make [| seed |]) in
      match check input with
      | Ok () -> true
      | Error m -> QCheck.Test.fail_reportf "seed %d: %s" seed m)

let obj_props =
  [
    prop ~name:"random OBJ text gives triangles or a located one-line error" ~count:4000
      G.random_obj G.check_obj;
    prop ~name:"mutated OBJ files give triangles or a located one-line error" ~count:4000
      G.mutated_obj G.check_obj;
    prop ~name:"random OBJ text reads the same in one pass as word by word" ~count:3000
      G.random_obj G.check_obj_lines;
    prop ~name:"mutated OBJ files read the same in one pass as word by word" ~count:3000
      G.mutated_obj G.check_obj_lines;
  ]

let ply_props =
  [
    prop ~name:"a random mesh reads the same from ASCII, binary PLY (both orders) and OBJ"
      ~count:1500 G.random_ply G.check_ply_formats;
    prop ~name:"mutated PLY files give triangles or a located one-line error" ~count:4000
      G.mutated_ply G.check_ply;
  ]

let ply_error text fragment =
  match Ply.parse_mesh ~file:"m.ply" text with
  | Ok _ -> Alcotest.failf "expected an error containing %S" fragment
  | Error m ->
      if not (G.contains m fragment) then
        Alcotest.failf "expected %S in the message, got %S" fragment m

let ply_head ?(format = "ascii") ?(vertices = 3) ?(faces = 1) () =
  Printf.sprintf
    "ply\n\
     format %s 1.0\n\
     element vertex %d\n\
     property float x\n\
     property float y\n\
     property float z\n\
     element face %d\n\
     property list uchar int vertex_indices\n\
     end_header\n"
    format vertices faces

let ply_cases =
  [
    Alcotest.test_case "a file that is not PLY says so at line 1" `Quick (fun () ->
        ply_error "solid cube\n" "m.ply:1: not a PLY file");
    Alcotest.test_case "a header without end_header names its last line" `Quick (fun () ->
        ply_error "ply\nformat ascii 1.0\nelement vertex 3\n" "m.ply:4:");
    Alcotest.test_case "an unknown format and type are named with the choices" `Quick
      (fun () ->
        ply_error "ply\nformat binary_middle_endian 1.0\nend_header\n"
          "m.ply:2: unknown format \"binary_middle_endian\" (expected ascii";
        ply_error "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n"
          "m.ply:4: property x: unknown type");
    Alcotest.test_case "a bad number in an ASCII body is located at its line" `Quick
      (fun () ->
        ply_error
          (ply_head () ^ "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n")
          "m.ply:11: expected a number, got \"zero\"");
    Alcotest.test_case "an index out of range is located" `Quick (fun () ->
        ply_error
          (ply_head () ^ "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n")
          "m.ply:13: vertex index 7 is out of range (3 vertices)");
    Alcotest.test_case "a truncated binary body is located at its byte" `Quick (fun () ->
        let head = ply_head ~format:"binary_little_endian" () in
        ply_error
          (head ^ String.make 20 '\000')
          (Printf.sprintf "m.ply: byte %d: the file ends before its last element"
             (String.length head + 20)));
    Alcotest.test_case "a face of two corners, and no vertex element, are refused" `Quick
      (fun () ->
        ply_error
          (ply_head () ^ "0 0 0\n1 0 0\n0 1 0\n2 0 1\n")
          "a face needs at least 3 corners, got 2";
        ply_error "ply\nformat ascii 1.0\nelement face 0\nend_header\n"
          "the file has no faces");
    Alcotest.test_case "values past the elements the header declares are refused" `Quick
      (fun () ->
        ply_error
          (ply_head () ^ "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n")
          "m.ply:14: more values than the header's elements hold");
  ]

let image_props =
  [
    prop ~name:"random and mutated PNG/PPM bytes decode or give an Error" ~count:1500
      G.image_case G.check_image;
  ]

(* ---- hand-made OBJ cases ---- *)

let obj_error text fragment =
  match Obj_file.parse ~file:"m.obj" text with
  | Ok _ -> Alcotest.failf "expected an error containing %S" fragment
  | Error m ->
      if not (G.contains m fragment) then
        Alcotest.failf "expected %S in the message, got %S" fragment m

let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"

let obj_cases =
  [
    Alcotest.test_case "coordinates beyond ±1e150 are refused at their line" `Quick
      (fun () -> obj_error (tri ^ "v 1e200 0 0\nf 1 2 4\n") "m.obj:4:");
    Alcotest.test_case "a mesh whose faces all have zero area says so" `Quick (fun () ->
        obj_error "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n" "zero area");
    Alcotest.test_case "an index beyond the integers is out of range, not a crash" `Quick
      (fun () -> obj_error (tri ^ "f 1 2 99999999999999999999\n") "m.obj:4:");
    Alcotest.test_case "a million-corner face and a megabyte line load" `Quick (fun () ->
        let corners =
          String.concat " "
            (List.init 1_000_000 (fun i -> if i mod 2 = 0 then "1" else "2"))
        in
        match Obj_file.parse ~file:"m.obj" (tri ^ "f 3 " ^ corners ^ "\n") with
        | Ok ts -> Alcotest.(check bool) "some triangles" true (ts <> [])
        | Error m -> Alcotest.fail m);
    Alcotest.test_case "face lines read in one pass as word by word" `Quick (fun () ->
        (* Plain triangles, the lines that go on past three plain corners, and those
           that leave the plain form after one, two or three corners. *)
        let square = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n" in
        List.iter
          (fun faces ->
            match G.check_obj_lines (square ^ faces) with
            | Ok () -> ()
            | Error m -> Alcotest.failf "%S: %s" faces m)
          [
            "f 1 2 3\n";
            "f 1 2 3";
            "f 1 2 3 4\n";
            "f 1 2 3 4 1 2\nf 2 3 4\n";
            "f 1 2 3/1\n";
            "f 1 2 3//1 4\n";
            "f 1 2/1 3\n";
            "f 1/1 2 3\n";
            "f 1 2 3 # a note\n";
            "f\t1  2\t3 \r\n";
            "f 1 2 5\n";
            "f 1 2 0\n";
            "f 1 2 3x\n";
            "f 1 2 -1\n";
            "f 1 2\n";
            "f1 2 3\n";
            "f 1 2 3 4x\n";
            "f 1 1 1\nf 1 2 3\n";
          ]);
    Alcotest.test_case "NUL bytes, a UTF-16 file and CRLF line ends" `Quick (fun () ->
        obj_error (tri ^ "f 1 2\0003\n") "not a text file";
        obj_error "\255\254v\000 \0001\000" "m.obj:1:";
        match
          Obj_file.parse ~file:"m.obj" "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n"
        with
        | Ok [ _ ] -> ()
        | Ok _ -> Alcotest.fail "one triangle expected"
        | Error m -> Alcotest.fail m);
  ]

(* ---- hand-made image cases ---- *)

let png_claiming = G.png_claiming

let decode_error ext contents fragment =
  G.with_temp_file ext contents (fun path ->
      let t0 = Unix.gettimeofday () in
      (match Image.read_linear path with
      | Ok fb -> Alcotest.failf "expected an error, got a %d×%d image" fb.width fb.height
      | Error m ->
          if not (G.contains m fragment) then
            Alcotest.failf "expected %S in %S" fragment m
      | exception e -> Alcotest.failf "raised %s" (Printexc.to_string e));
      let dt = Unix.gettimeofday () -. t0 in
      if dt > 2. then Alcotest.failf "took %.1f s to refuse" dt)

let image_cases =
  [
    Alcotest.test_case "the checksums of the hand-made PNG are right (a 1×1 one decodes)"
      `Quick (fun () ->
        (* Guards the cases below: they must be refused for their size, not their CRC. *)
        G.with_temp_file ".png" (png_claiming 1 1) (fun path ->
            match Image.read_linear path with
            | Ok fb -> Alcotest.(check (pair int int)) "size" (1, 1) (fb.width, fb.height)
            | Error m -> Alcotest.fail m));
    Alcotest.test_case "a PNG claiming 100000×100000 pixels is refused before decoding"
      `Quick (fun () ->
        decode_error ".png" (png_claiming 100_000 100_000) "larger than the limit");
    Alcotest.test_case
      "a PNG claiming 20000×20000 pixels (1.2 GB) is refused before allocating" `Quick
      (fun () -> decode_error ".png" (png_claiming 20_000 20_000) "larger than the limit");
    Alcotest.test_case "a PNG claiming 2^31−1 × 2^31−1 pixels is refused" `Quick
      (fun () ->
        decode_error ".png" (png_claiming 0x7fffffff 0x7fffffff) "larger than the limit");
    Alcotest.test_case "a PNG of zero width is refused" `Quick (fun () ->
        decode_error ".png" (png_claiming 0 5) "");
    Alcotest.test_case "a file that is not a PNG says so" `Quick (fun () ->
        decode_error ".png" "GIF89a\001\000\001\000" "not a PNG file";
        decode_error ".png" "" "not a PNG file");
    Alcotest.test_case
      "a PPM claiming more pixels than the limit is refused before reading" `Quick
      (fun () -> decode_error ".ppm" "P6\n100000 100000\n255\n\000\000\000" "");
    Alcotest.test_case "a PPM claiming more pixels than it holds is truncated" `Quick
      (fun () -> decode_error ".ppm" "P6\n4 4\n255\n\000\000\000" "truncated");
    Alcotest.test_case "a PPM with a header of a megabyte of digits is refused" `Quick
      (fun () -> decode_error ".ppm" ("P6\n" ^ String.make 1_000_000 '9') "");
    Alcotest.test_case "a directory named like an image is refused" `Quick (fun () ->
        let d =
          Filename.concat
            (Filename.get_temp_dir_name ())
            (Printf.sprintf "lancer-dir-%d.png" (Unix.getpid ()))
        in
        Unix.mkdir d 0o755;
        Fun.protect
          ~finally:(fun () -> Unix.rmdir d)
          (fun () ->
            match Image.read_linear d with
            | Ok _ -> Alcotest.fail "a directory decoded"
            | Error m ->
                Alcotest.(check bool) ("says so: " ^ m) true (G.contains m "directory")
            | exception e -> Alcotest.failf "raised %s" (Printexc.to_string e)));
  ]

(* ---- the oracles themselves ---- *)

(* A crash that the boundary turned into a message must fail a case, not pass it. *)
let oracle_cases =
  let module E = Lancer_dsl.Error in
  let fails what = function Ok () -> Alcotest.failf "%s passed" what | Error _ -> () in
  let passes what = function
    | Ok () -> ()
    | Error m -> Alcotest.failf "%s failed: %s" what m
  in
  [
    Alcotest.test_case
      "the scene oracle rejects an internal error and accepts a located one" `Quick
      (fun () ->
        fails "an internal error"
          (G.judge_scene_errors
             [ E.file_error "fuzz.rts" "internal error: Not_found (please report it)" ]);
        fails "no error at all" (G.judge_scene_errors []);
        match Lancer_dsl.Dsl.load_string ~filename:"fuzz.rts" "sphere { radius: -1 }" with
        | Ok _ -> Alcotest.fail "a negative radius loaded"
        | Error es -> passes "a located error" (G.judge_scene_errors es));
    Alcotest.test_case "the image oracle rejects a crash reported as an error" `Quick
      (fun () ->
        fails "Invalid_argument"
          (G.judge_image_error
             "x.png: cannot read image: Invalid_argument(\"index out of bounds\")");
        fails "Not_found" (G.judge_image_error "x.png: cannot read image: Not_found");
        fails "two lines" (G.judge_image_error "x.png: one\ntwo");
        passes "a reason" (G.judge_image_error "x.png: not a PNG file"));
  ]

let () =
  Alcotest.run "fuzz"
    [
      ("obj", List.map (seeded 20240611) obj_props @ obj_cases);
      ("ply", List.map (seeded 20261203) ply_props @ ply_cases);
      ("image", List.map (seeded 20240612) image_props @ image_cases);
      ("oracles", oracle_cases);
    ]
