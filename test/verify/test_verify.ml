(* lancer verify, run as a user runs it, on images lancer rendered in a fresh directory. *)

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"

open Run_lancer

let lancer ~dir args = run ~exe ~dir args
let ( // ) = Filename.concat

(* A scene with a texture, a soft shadow, jitter and a moving sphere blurred by an open
   shutter: every stochastic part of a render, from a file it reads. *)
let scene =
  {|settings { width: 72, height: 40, samples: 2, jitter: true }
animation { fps: 10, frames: 3 }
camera { position: (0, 2, -6), look_at: (0, 0.5, 0), shutter: (0, 0.5), shutter_samples: 2 }
light { position: (-3, 5, -4), radius: 0.5, samples: 2 }
plane { normal: (0, 1, 0), offset: 0, material: material { texture: image("tex.ppm", 1) } }
sphere { center: (time, 1, 0), radius: 1, material: material { color: (0.9, 0.2, 0.2) } }
|}

(* A 2×2 PPM texture of four colours. *)
let texture colour = "P6\n2 2\n255\n" ^ colour ^ "\x00\xff\x00\x00\x00\xff\xff\xff\x00"

let fresh () =
  let d = tmpdir "lancer-verify" in
  write_file (d // "s.rts") scene;
  write_file (d // "tex.ppm") (texture "\xff\x00\x00");
  d

let render d args =
  check_status "render" 0 (lancer ~dir:d ([ "render"; "s.rts"; "-q" ] @ args))

let reproduced d image =
  let r = lancer ~dir:d [ "verify"; image ] in
  check_status ("verify " ^ image) 0 r;
  says "reproduced" r "reproduced: "

let not_reproduced d args =
  let r = lancer ~dir:d ("verify" :: args) in
  check_status "verify" 1 r;
  says "not reproduced" r "not reproduced";
  r

(* The image with sample [c] of pixel (x, y) changed by one, written again with its text
   chunks kept. *)
let change_pixel path x y =
  let bytes = read_file path in
  let texts = Result.get_ok (Lancer.Png.texts bytes) in
  let r = Result.get_ok (Lancer.Png.decode bytes) in
  let k = (((y * r.width) + x) * r.channels) + 1 in
  let v = Bytes.get_uint8 r.samples k in
  Bytes.set_uint8 r.samples k (if v = 255 then 254 else v + 1);
  let b = Buffer.create 4096 in
  Lancer.Png.encode ~text:texts r (Buffer.add_string b);
  write_file path (Buffer.contents b)

let test_reproduced () =
  let d = fresh () in
  render d [ "-o"; "a.png" ];
  reproduced d "a.png";
  let r = lancer ~dir:d [ "verify"; "a.png"; "--tiles"; "all" ] in
  check_status "--tiles all" 0 r;
  says "every block" r "6 of the 6 blocks";
  (* From another directory: the record names the scene from the image's directory. *)
  let up = Filename.dirname d in
  check_status "from elsewhere" 0
    (lancer ~dir:up [ "verify"; Filename.basename d // "a.png" ]);
  (* Every frame of an animation. *)
  check_status "animate" 0 (lancer ~dir:d [ "animate"; "s.rts"; "-o"; "fr"; "-q" ]);
  List.iter (fun k -> reproduced d (Printf.sprintf "fr/frame_%04d.png" k)) [ 0; 1; 2 ];
  (* A region, cropped, with alpha, at 16 bits; and the built-in showcase. *)
  render d
    [ "-o"; "c.png"; "--region"; "10,5,50,30"; "--crop"; "--alpha"; "--bits"; "16" ];
  reproduced d "c.png";
  render d [ "-o"; "g.png"; "--region"; "10,5,50,30"; "--time"; "0.1" ];
  reproduced d "g.png";
  check_status "showcase" 0
    (lancer ~dir:d
       [ "render"; "-o"; "show.png"; "--width"; "64"; "--height"; "48"; "-q" ]);
  reproduced d "show.png"

let test_same_bytes () =
  (* The record depends neither on the domains nor on where the command runs from. *)
  let d = fresh () in
  render d [ "-o"; "one.png"; "--domains"; "1" ];
  render d [ "-o"; "two.png"; "--domains"; "2" ];
  Alcotest.(check bool)
    "1 and 2 domains" true
    (read_file (d // "one.png") = read_file (d // "two.png"));
  let up = Filename.dirname d and base = Filename.basename d in
  check_status "from the parent" 0
    (lancer ~dir:up [ "render"; base // "s.rts"; "-o"; base // "up.png"; "-q" ]);
  Alcotest.(check bool)
    "from another directory" true
    (read_file (d // "one.png") = read_file (d // "up.png"))

let test_pixel_changed () =
  let d = fresh () in
  render d [ "-o"; "a.png" ];
  (* Pixel (40, 35) lies in block 4: the second block of the second row of 32×32. *)
  change_pixel (d // "a.png") 40 35;
  let r = not_reproduced d [ "a.png" ] in
  says "names the block" r "block 4 (pixels 32–63 × 32–39) was edited";
  says "names the pixel" r "1 pixel differs, first (40, 35)"

let test_inputs_changed () =
  let d = fresh () in
  render d [ "-o"; "a.png" ];
  write_file (d // "tex.ppm") (texture "\x00\x00\xff");
  let r = not_reproduced d [ "a.png" ] in
  says "the texture" r "tex.ppm has changed since the image was written";
  Sys.remove (d // "tex.ppm");
  says "the texture gone" (not_reproduced d [ "a.png" ]) "tex.ppm is missing";
  write_file (d // "tex.ppm") (texture "\xff\x00\x00");
  reproduced d "a.png";
  write_file (d // "s.rts") (scene ^ "sphere { center: (2, 1, 0), radius: 0.5 }\n");
  says "the scene" (not_reproduced d [ "a.png" ]) "s.rts has changed since the image";
  Sys.remove (d // "s.rts");
  says "the scene gone" (not_reproduced d [ "a.png" ]) "s.rts, the scene, is missing"

let test_refusals () =
  let d = fresh () in
  (* An image lancer did not render: no record. *)
  let bytes = "P6\n1 1\n255\n\x01\x02\x03" in
  write_file (d // "x.ppm") bytes;
  let raster = Result.get_ok (Lancer.Image.read_raster (d // "x.ppm")) in
  let b = Buffer.create 64 in
  Lancer.Png.encode raster (Buffer.add_string b);
  write_file (d // "other.png") (Buffer.contents b);
  let r = lancer ~dir:d [ "verify"; "other.png" ] in
  check_status "no record" 1 r;
  says "no record" r "holds no lancer record";
  (* A record that is not lancer's: a message, never an exception. *)
  let b = Buffer.create 64 in
  Lancer.Png.encode ~text:[ ("lancer", "{\"lancer\": 3") ] raster (Buffer.add_string b);
  write_file (d // "bad.png") (Buffer.contents b);
  let r = lancer ~dir:d [ "verify"; "bad.png" ] in
  check_status "bad record" 1 r;
  says "bad record" r "its record is not JSON";
  let r = lancer ~dir:d [ "verify"; "missing.png" ] in
  check_status "missing" 1 r

(* make demo's own commands (read from the Makefile), then lancer verify on every image
   they wrote. *)
let test_demo () =
  let root = Filename.concat (Sys.getcwd ()) "../.." in
  let make = read_file (root // "Makefile") in
  let lines = String.split_on_char '\n' make in
  let rec demo = function
    | l :: rest when String.starts_with ~prefix:"demo:" l -> body rest
    | _ :: rest -> demo rest
    | [] -> []
  and body = function
    | l :: rest when String.length l > 0 && l.[0] = '\t' -> l :: body rest
    | _ -> []
  in
  let prefix = "\tout/bin/lancer " in
  let commands =
    List.filter_map
      (fun l ->
        if String.starts_with ~prefix l then
          Some
            (String.sub l (String.length prefix) (String.length l - String.length prefix))
        else None)
      (demo lines)
  in
  Alcotest.(check bool) "make demo runs lancer" true (List.length commands >= 2);
  let d = tmpdir "lancer-verify-demo" in
  Unix.symlink (root // "scenes") (d // "scenes");
  Unix.mkdir (d // "out") 0o755;
  List.iter
    (fun c ->
      let st =
        Sys.command (Printf.sprintf "cd %s && %s %s -q" (Filename.quote d) exe c)
      in
      Alcotest.(check int) c 0 st)
    commands;
  let images =
    "out/showcase.png"
    :: List.map
         (fun f -> "out/bounce" // f)
         (List.filter
            (fun f -> Filename.check_suffix f ".png")
            (Array.to_list (Sys.readdir (d // "out/bounce"))))
  in
  Alcotest.(check bool) "the frames" true (List.length images > 100);
  List.iter (reproduced d) images

let () =
  Alcotest.run "verify"
    [
      ( "verify",
        [
          Alcotest.test_case "what lancer wrote is reproduced" `Quick test_reproduced;
          Alcotest.test_case "the record keeps the bytes deterministic" `Quick
            test_same_bytes;
          Alcotest.test_case "a changed pixel is named with its block" `Quick
            test_pixel_changed;
          Alcotest.test_case "a changed or missing input is named" `Quick
            test_inputs_changed;
          Alcotest.test_case "an image without a record, or with a bad one" `Quick
            test_refusals;
          Alcotest.test_case "every image make demo writes is reproduced" `Slow test_demo;
        ] );
    ]
