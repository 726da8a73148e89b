(* lancer render --aov and lancer golden's cause, run as a user runs them, in a fresh
   directory. *)

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"

open Run_lancer

let lancer ~dir args = run ~exe ~dir args
let ( // ) = Filename.concat

(* An odd size, so that the centre pixel's ray is the camera's axis. The vertical field of
   view is 2·atan(0.5): at distance 10 the image spans 10 units, 49 pixels. Sphere A (line
   6) faces the camera on its axis, its front 9 from the camera; sphere B (line 7) lies
   above it; the plane (line 5) is under both. *)
let scene =
  {|settings { width: 65, height: 49, background: (0, 0, 0) }
camera { position: (0, 0, -10), look_at: (0, 0, 0), fov: 53.13010235415598 }
light { position: (-3, 6, -6) }
// the floor
plane { normal: (0, 1, 0), offset: -4, material: material { color: (0.8, 0.8, 0.8) } }
sphere { center: (0, 0, 0), radius: 1, material: material { color: (0.9, 0.2, 0.2) } }
sphere { center: (0, 3, 0), radius: 1, material: material { color: (0.2, 0.2, 0.9) } }
|}

(* Pixel row of a point at height y on the plane z = 0: 49 pixels span 10 units. *)
let row y = int_of_float (24.5 -. (y *. 4.9))
let centre = (32, 24)

let fresh () =
  let d = tmpdir "lancer-aov" in
  write_file (d // "s.rts") scene;
  d

let render d args =
  check_status "render" 0 (lancer ~dir:d ([ "render"; "s.rts"; "-q" ] @ args))

let decode path =
  match Lancer.Png.decode (read_file path) with
  | Ok r -> r
  | Error m -> Alcotest.failf "%s: %s" path m

let test_objects () =
  let d = fresh () in
  render d [ "-o"; "a.png"; "--aov"; "object" ];
  let r = decode (d // "a.object.png") in
  Alcotest.(check (pair int int)) "one 16-bit channel" (1, 16) (r.channels, r.depth);
  let id (i, j) = Lancer.Raster.get r i j 0 in
  Alcotest.(check int) "sphere A's centre" 2 (id centre);
  Alcotest.(check int) "sphere B's centre" 3 (id (32, row 3.));
  Alcotest.(check int) "the top corner: nothing" 0 (id (0, 0));
  Alcotest.(check int) "the bottom corner: the plane" 1 (id (0, 48));
  Alcotest.(check bool)
    "no depth or normal image" false
    (Sys.file_exists (d // "a.depth.pfm") || Sys.file_exists (d // "a.normal.png"));
  let j = Yojson.Safe.from_file (d // "a.objects.json") in
  let open Yojson.Safe.Util in
  let objs = j |> member "objects" |> to_list in
  let row o =
    ( o |> member "id" |> to_int,
      o |> member "kind" |> to_string,
      o |> member "file" |> to_string,
      o |> member "line" |> to_int )
  in
  Alcotest.(check (list (pair int (pair string (pair string int)))))
    "each object with its file:line"
    [
      (1, ("plane", ("s.rts", 5)));
      (2, ("sphere", ("s.rts", 6)));
      (3, ("sphere", ("s.rts", 7)));
    ]
    (List.map
       (fun o ->
         let i, k, f, l = row o in
         (i, (k, (f, l))))
       objs)

(* A height field is many primitives, a CSG object one: the ids still count objects. *)
let test_many_primitives () =
  let d = tmpdir "lancer-aov" in
  write_file (d // "h.ppm")
    "P6\n\
     3 3\n\
     255\n\
     \x00\x00\x00\x10\x10\x10\x20\x20\x20\x30\x30\x30\x40\x40\x40\x50\x50\x50\x60\x60\x60\x70\x70\x70\x80\x80\x80";
  write_file (d // "s.rts")
    {|settings { width: 65, height: 49 }
camera { position: (0, 0, -10), look_at: (0, 0, 0), fov: 53.13010235415598 }
height_field { file: "h.ppm", origin: (-5, -6, -3), size: (10, 1, 10) }
difference { box { min: (-1, -1, -1), max: (1, 1, 1) } sphere { center: (0, 0, -1), radius: 0.5 } }
sphere { center: (0, 3, 0), radius: 1 }
|};
  render d [ "-o"; "a.png"; "--aov"; "object" ];
  let r = decode (d // "a.object.png") in
  let id (i, j) = Lancer.Raster.get r i j 0 in
  Alcotest.(check int) "the CSG object's centre" 2 (id centre);
  Alcotest.(check int) "the sphere after both" 3 (id (32, row 3.));
  Alcotest.(check int) "the height field at the bottom" 1 (id (32, 48))

(* An animation's frame joins its static objects, built once, with those that move: the
   ids still follow the program's order. *)
let test_animation () =
  let d = tmpdir "lancer-aov" in
  write_file (d // "s.rts")
    {|settings { width: 65, height: 49 }
animation { fps: 10, frames: 3 }
camera { position: (0, 0, -10), look_at: (0, 0, 0), fov: 53.13010235415598 }
plane { normal: (0, 1, 0), offset: -4 }
sphere { center: (time, 0, 0), radius: 1 }
sphere { center: (0, 3, 0), radius: 1 }
|};
  render d [ "-o"; "a.png"; "--frame"; "2"; "--aov"; "object" ];
  let r = decode (d // "a.object.png") in
  let id (i, j) = Lancer.Raster.get r i j 0 in
  Alcotest.(check int) "the moving sphere" 2 (id centre);
  Alcotest.(check int) "the sphere after it" 3 (id (32, row 3.));
  Alcotest.(check int) "the plane before it" 1 (id (0, 48))

let read_pfm path =
  let s = read_file path in
  (* "PF\n65 49\n-1.0\n", then little-endian floats from the bottom row up. *)
  let header_end =
    let rec nth_newline i k =
      if s.[i] = '\n' then if k = 2 then i + 1 else nth_newline (i + 1) (k + 1)
      else nth_newline (i + 1) k
    in
    nth_newline 0 0
  in
  Alcotest.(check string) "PFM header" "PF\n65 49\n-1.0\n" (String.sub s 0 header_end);
  fun (i, j) c ->
    let off = header_end + (4 * ((3 * (((48 - j) * 65) + i)) + c)) in
    Int32.float_of_bits (String.get_int32_le s off)

let test_depth_normal () =
  let d = fresh () in
  render d [ "-o"; "a.png"; "--aov"; "normal,depth" ];
  let depth = read_pfm (d // "a.depth.pfm") in
  Alcotest.(check (float 1e-5)) "sphere A's front: 10 − 1" 9. (depth centre 0);
  Alcotest.(check (float 1e-5)) "in every channel" 9. (depth centre 2);
  Alcotest.(check bool) "nothing: infinity" true (depth (0, 0) 0 = Float.infinity);
  let n = decode (d // "a.normal.png") in
  let px (i, j) = List.init 3 (fun c -> Lancer.Raster.get n i j c) in
  Alcotest.(check (list int))
    "facing the camera: (0, 0, −1) as (n + 1)/2" [ 128; 128; 0 ] (px centre);
  Alcotest.(check (list int)) "the plane: (0, 1, 0)" [ 128; 255; 128 ] (px (0, 48));
  Alcotest.(check (list int)) "nothing: black" [ 0; 0; 0 ] (px (0, 0));
  Alcotest.(check bool) "no object image" false (Sys.file_exists (d // "a.object.png"))

let test_same_image () =
  let d = fresh () in
  render d [ "-o"; "plain.png" ];
  render d [ "-o"; "with.png"; "--aov"; "object,depth,normal" ];
  Alcotest.(check bool)
    "the same pixels" true
    (pixels (d // "plain.png") = pixels (d // "with.png"));
  (* The records name the file, so the bytes are compared with the same name. *)
  let plain = read_file (d // "plain.png") in
  render d [ "-o"; "plain.png"; "--aov"; "depth" ];
  Alcotest.(check bool) "the same bytes" true (plain = read_file (d // "plain.png"))

let test_bad_names () =
  let d = fresh () in
  let r = lancer ~dir:d [ "render"; "s.rts"; "-o"; "a.png"; "--aov"; "object,colour" ] in
  check_status "unknown" 1 r;
  says "unknown" r "--aov: unknown image \"colour\"; the images are object, depth, normal";
  Alcotest.(check bool) "nothing written" false (Sys.file_exists (d // "a.png"));
  let r = lancer ~dir:d [ "render"; "s.rts"; "-o"; "-"; "--aov"; "depth" ] in
  check_status "to standard output" 1 r;
  says "stdout" r "cannot be combined with -o -"

(* [s] with the first [sub] replaced by [by]. *)
let replace s ~sub ~by =
  let n = String.length sub in
  let rec find i =
    if i + n > String.length s then Alcotest.failf "no %S in the scene" sub
    else if String.sub s i n = sub then i
    else find (i + 1)
  in
  let i = find 0 in
  String.sub s 0 i ^ by ^ String.sub s (i + n) (String.length s - i - n)

(* The first entry of the line "most changed pixels: …" of [out]. *)
let first_cause out =
  let mark = "most changed pixels: " in
  let line =
    List.find_opt (String.starts_with ~prefix:mark) (String.split_on_char '\n' out)
  in
  match line with
  | None -> Alcotest.failf "no cause in %S" out
  | Some l ->
      let rest =
        String.sub l (String.length mark) (String.length l - String.length mark)
      in
      List.hd (String.split_on_char ',' rest)

let test_golden_names_the_object () =
  let d = fresh () in
  check_status "golden --update" 0
    (lancer ~dir:d [ "golden"; "s.rts"; "g.png"; "--update"; "-q" ]);
  (* Sphere B turns green. *)
  write_file (d // "s.rts") (replace scene ~sub:"(0.2, 0.2, 0.9)" ~by:"(0.2, 0.9, 0.2)");
  let r = lancer ~dir:d [ "golden"; "s.rts"; "g.png" ] in
  check_status "golden" 1 r;
  let _, out, _ = r in
  let first = first_cause out in
  Alcotest.(check bool)
    (Printf.sprintf "sphere B first: %S" first)
    true
    (String.ends_with ~suffix:" on sphere at s.rts:7" first);
  (* Within tolerance again: no cause to name. *)
  write_file (d // "s.rts") scene;
  let r = lancer ~dir:d [ "golden"; "s.rts"; "g.png" ] in
  check_status "golden again" 0 r;
  let _, out, _ = r in
  Alcotest.(check bool) "no cause" false (contains out "most changed pixels")

(* The pass itself, as a library call: its loop over the pixels allocates nothing (its
   arrays, larger than the minor heap takes, go straight to the major heap). *)
let test_no_allocation () =
  let open Lancer in
  let sc =
    match Program.load_string ~filename:"s.rts" scene with
    | Error _ -> Alcotest.fail "the scene does not load"
    | Ok p -> (
        match Program.scene p ~time:0. ~frame:0 with
        | Ok sc -> sc
        | Error _ -> Alcotest.fail "the scene does not compile")
  in
  ignore (Aov.primary sc);
  let before = Gc.minor_words () in
  let a = Aov.primary sc in
  let words = Gc.minor_words () -. before in
  Alcotest.(check int) "sphere A at the centre" 1 a.item.((24 * 65) + 32);
  Alcotest.(check bool)
    (Printf.sprintf "%.0f words for %d pixels" words (65 * 49))
    true (words < 200.)

let () =
  Alcotest.run "aov"
    [
      ( "render --aov",
        [
          Alcotest.test_case "object ids and their list" `Quick test_objects;
          Alcotest.test_case "ids of objects of many primitives" `Quick
            test_many_primitives;
          Alcotest.test_case "ids in an animation's frame" `Quick test_animation;
          Alcotest.test_case "depth and normals" `Quick test_depth_normal;
          Alcotest.test_case "the image unchanged" `Quick test_same_image;
          Alcotest.test_case "bad names" `Quick test_bad_names;
          Alcotest.test_case "no allocation per pixel" `Quick test_no_allocation;
        ] );
      ( "golden",
        [
          Alcotest.test_case "a failure names the object" `Quick
            test_golden_names_the_object;
        ] );
    ]
