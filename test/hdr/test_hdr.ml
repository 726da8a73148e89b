(* Linear images as a compositing pipeline takes them: lancer's EXR, HDR and PFM files,
   read back by a reader of their own (OpenEXR's C++ library for EXR), hold the linear
   values that the 16-bit PNG of the same render encodes, to within each format's
   precision; a write cut short leaves nothing under the final name. *)

open Run_lancer

let exe = Filename.concat (Sys.getcwd ()) "../../bin/main.exe"
let reader = Filename.concat (Sys.getcwd ()) "read_linear.exe"
let lancer ?prefix ~dir args = run ?prefix ~exe ~dir args
let path = Filename.concat

(* A scene with values below, near and above 1 (a bright light on a white sphere), a
   texture and a background gradient. *)
let scene =
  {|settings { width: 40, height: 30, background: gradient((0.1, 0.2, 0.4), (0.9, 0.95, 1)) }
camera { position: (0, 1, -5), look_at: (0, 0.5, 0) }
light { position: (-3, 5, -4), intensity: 3 }
plane { normal: (0, 1, 0), offset: 0, material: material { texture: checker((1, 1, 1), (0.05, 0.05, 0.05), 0.5) } }
sphere { center: (0, 1, 0), radius: 1, material: material { color: (0.9, 0.6, 0.3), specular: 0.8 } }
sphere { center: (1.6, 0.4, -0.5), radius: 0.4 }
|}

(* What the last EXR read holds: "half" or "float". *)
let depth = ref ""

(* The values a reader of its own gives: width, height, channels and each pixel's. *)
let read kind file =
  let out = Filename.temp_file "linear" ".txt" in
  let st =
    Sys.command
      (Printf.sprintf "%s %s %s > %s" (Filename.quote reader) kind (Filename.quote file)
         (Filename.quote out))
  in
  if st <> 0 then Alcotest.failf "the reader refused %s" file;
  let lines = String.split_on_char '\n' (String.trim (read_file out)) in
  Sys.remove out;
  match lines with
  | head :: pixels ->
      let w, h, c = Scanf.sscanf head "%d %d %d" (fun w h c -> (w, h, c)) in
      (depth := match String.split_on_char ' ' head with [ _; _; _; d ] -> d | _ -> "");
      let values =
        Array.of_list
          (List.concat_map
             (fun l ->
               List.map float_of_string
                 (List.filter (( <> ) "") (String.split_on_char ' ' l)))
             pixels)
      in
      Alcotest.(check int) "every value" (w * h * c) (Array.length values);
      (w, h, c, values)
  | [] -> Alcotest.fail "no output"

(* The linear values a 16-bit sRGB PNG encodes, and whether each was clamped at 1. *)
let png16 file =
  match Lancer.Image.read_raster file with
  | Error m -> Alcotest.fail m
  | Ok r ->
      let lin v =
        let v = Float.of_int v /. 65535. in
        if v <= 0.04045 then v /. 12.92 else Float.pow ((v +. 0.055) /. 1.055) 2.4
      in
      ( r.width,
        r.height,
        Array.init
          (r.width * r.height * r.channels)
          (fun k ->
            let p = k / r.channels and c = k mod r.channels in
            let s = Lancer.Raster.get r (p mod r.width) (p / r.width) c in
            if c = 3 then (Float.of_int s /. 65535., s = 65535) else (lin s, s = 65535)),
        r.channels )

let render d args =
  match lancer ~dir:d ([ "render"; "s.rts"; "-q" ] @ args) with
  | 0, _, _ -> ()
  | st, _, e -> Alcotest.failf "render %s: exit %d\n%s" (String.concat " " args) st e

(* Each value of [got] against the PNG's: within [tolerance value] where the PNG did not
   clamp it; at least 1 where it did. *)
let agree what (w, h, c, got) (pw, ph, png, pc) ~channels tolerance =
  Alcotest.(check (pair int int)) (what ^ ": the size") (pw, ph) (w, h);
  for p = 0 to (w * h) - 1 do
    let brightest =
      Float.max got.(p * c) (Float.max got.((p * c) + 1) got.((p * c) + 2))
    in
    let tolerance v = tolerance ~brightest v in
    for k = 0 to channels - 1 do
      let v = got.((p * c) + k) and expected, clamped = png.((p * pc) + k) in
      if clamped then (
        if v < 1. -. tolerance 1. then
          Alcotest.failf "%s: pixel %d channel %d is %g, the PNG's is 1 or more" what p k
            v)
      else if Float.abs (v -. expected) > tolerance expected then
        Alcotest.failf "%s: pixel %d channel %d is %.9g, the PNG encodes %.9g" what p k v
          expected
    done
  done

(* 16 bits of sRGB: a step of 1/65535 in the encoded value is at most 2.3/65535 in linear
   value; each format adds its own rounding. *)
let png_step = 2.3 /. 65535. /. 2.

let exr_half () =
  let d = tmpdir "lancer-hdr" in
  write_file (path d "s.rts") scene;
  render d [ "-o"; "s.png"; "--bits"; "16" ];
  render d [ "-o"; "s.exr" ];
  let png = png16 (path d "s.png") in
  (* Half floats: 11 significant bits, a relative error of at most 2^-11. *)
  agree "half EXR"
    (read "exr" (path d "s.exr"))
    png ~channels:3
    (fun ~brightest:_ v -> (Float.abs v *. Float.pow 2. (-11.)) +. png_step +. 6e-8)

let exr_float () =
  let d = tmpdir "lancer-hdr" in
  write_file (path d "s.rts") scene;
  render d [ "-o"; "s.png"; "--bits"; "16" ];
  render d [ "-o"; "s.exr"; "--bits"; "32" ];
  let got = read "exr" (path d "s.exr") in
  Alcotest.(check string) "float channels" "float" !depth;
  agree "float EXR" got
    (png16 (path d "s.png"))
    ~channels:3
    (fun ~brightest:_ v -> (Float.abs v *. 1e-7) +. png_step)

(* The record of where an EXR came from: the header's string attribute "lancer" (name,
   NUL, type "string", NUL, a 32-bit little-endian size, the text). *)
let exr_record () =
  let d = tmpdir "lancer-hdr" in
  write_file (path d "s.rts") scene;
  render d [ "-o"; "s.exr" ];
  let bytes = read_file (path d "s.exr") in
  let key = "lancer\000string\000" in
  let rec find i =
    if i + String.length key > String.length bytes then
      Alcotest.fail "no attribute lancer in the EXR header"
    else if String.sub bytes i (String.length key) = key then i + String.length key
    else find (i + 1)
  in
  let at = find 0 in
  let n = Int32.to_int (String.get_int32_le bytes at) in
  match Lancer.Provenance.of_text (String.sub bytes (at + 4) n) with
  | Error m -> Alcotest.fail m
  | Ok r ->
      Alcotest.(check (option string)) "the scene" (Some "s.rts") r.scene;
      Alcotest.(check string) "no blocks" "" r.blocks;
      Alcotest.(check string) "the version" Lancer.Version.v r.version

(* An animation's frames as EXR: frame_0000.exr …, each the still of its instant, and a
   resumed run finds them done. *)
let exr_frames () =
  let d = tmpdir "lancer-hdr" in
  write_file (path d "a.rts")
    (scene
   ^ "animation { fps: 10, frames: 3 }\n\
      sphere { center: (-1.5, 0.3 + time, 0), radius: 0.3 }\n");
  (match lancer ~dir:d [ "animate"; "a.rts"; "-o"; "fr"; "--format"; "exr"; "-q" ] with
  | 0, _, _ -> ()
  | st, _, e -> Alcotest.failf "animate: exit %d\n%s" st e);
  List.iter
    (fun k ->
      let f = path (path d "fr") (Printf.sprintf "frame_%04d.exr" k) in
      (match
         lancer ~dir:d
           [ "render"; "a.rts"; "--frame"; string_of_int k; "-q"; "-o"; "still.exr" ]
       with
      | 0, _, _ -> ()
      | st, _, e -> Alcotest.failf "render: exit %d\n%s" st e);
      Alcotest.(check bool)
        (Printf.sprintf "frame %d is the still of its instant" k)
        true
        (read "exr" f = read "exr" (path d "still.exr")))
    [ 0; 1; 2 ];
  let ((st, out, _) as r) =
    lancer ~dir:d [ "animate"; "a.rts"; "-o"; "fr"; "--format"; "exr"; "--resume" ]
  in
  Alcotest.(check int) "resumed" 0 st;
  says "every frame found done" r "3 frames already rendered, 0 to go";
  ignore out;
  let st, _, e =
    lancer ~dir:d
      [ "animate"; "a.rts"; "-o"; "vid"; "--format"; "exr"; "--video"; "v.mp4" ]
  in
  Alcotest.(check int) "a video of EXR frames is refused" 1 st;
  Alcotest.(check bool) "before any frame" false (Sys.file_exists (path d "vid"));
  Alcotest.(check bool)
    ("says why: " ^ e) true
    (contains e "a video is made from PNG frames")

let exr_alpha () =
  let d = tmpdir "lancer-hdr" in
  write_file (path d "s.rts") scene;
  render d [ "-o"; "s.png"; "--bits"; "16"; "--alpha" ];
  render d [ "-o"; "s.exr"; "--alpha" ];
  let ((_, _, c, _) as exr) = read "exr" (path d "s.exr") in
  Alcotest.(check int) "four channels" 4 c;
  agree "half EXR with alpha" exr
    (png16 (path d "s.png"))
    ~channels:4
    (fun ~brightest:_ v -> (Float.abs v *. Float.pow 2. (-11.)) +. png_step +. 6e-8)

let pfm () =
  let d = tmpdir "lancer-hdr" in
  write_file (path d "s.rts") scene;
  render d [ "-o"; "s.png"; "--bits"; "16" ];
  render d [ "-o"; "s.pfm" ];
  agree "PFM"
    (read "pfm" (path d "s.pfm"))
    (png16 (path d "s.png"))
    ~channels:3
    (fun ~brightest:_ v -> (Float.abs v *. 1e-7) +. png_step)

let hdr () =
  let d = tmpdir "lancer-hdr" in
  write_file (path d "s.rts") scene;
  render d [ "-o"; "s.png"; "--bits"; "16" ];
  render d [ "-o"; "s.hdr" ];
  (* RGBE: 8 bits of mantissa under the pixel's brightest channel, the value cut, not
     rounded: each channel within 2^-7 of the brightest. *)
  agree "HDR"
    (read "hdr" (path d "s.hdr"))
    (png16 (path d "s.png"))
    ~channels:3
    (fun ~brightest _ -> (brightest *. Float.pow 2. (-7.)) +. png_step)

(* Past a file-size limit the write fails: exit 1, the system's reason, and no file
   under the final name nor a temporary one beside it. *)
let cut_short () =
  let d = tmpdir "lancer-hdr" in
  write_file (path d "s.rts")
    "settings { width: 400, height: 300 }\n\
     light { position: (0, 5, -5) }\n\
     plane { normal: (0, 1, 0), offset: -1, material: material { texture: noise((1, 1, \
     1), (0, 0, 0), 0.05) } }\n";
  List.iter
    (fun out ->
      let st, _, e =
        lancer ~prefix:"ulimit -f 2;" ~dir:d [ "render"; "s.rts"; "-q"; "-o"; out ]
      in
      Alcotest.(check int) (out ^ ": exit 1\n" ^ e) 1 st;
      Alcotest.(check (list string))
        (out ^ ": nothing written") [ "s.rts" ]
        (List.sort compare (Array.to_list (Sys.readdir d))))
    [ "big.exr"; "big.pfm"; "big.hdr" ]

let () =
  Alcotest.run "linear images"
    [
      ( "formats",
        [
          Alcotest.test_case "a half-float EXR holds the 16-bit PNG's linear values"
            `Quick exr_half;
          Alcotest.test_case "an EXR's alpha is the PNG's coverage" `Quick exr_alpha;
          Alcotest.test_case "--bits 32 makes a float EXR with the PNG's values" `Quick
            exr_float;
          Alcotest.test_case "an animation's frames as EXR, resumed" `Quick exr_frames;
          Alcotest.test_case "an EXR's header keeps the record of where it came from"
            `Quick exr_record;
          Alcotest.test_case "a PFM holds the PNG's linear values as 32-bit floats" `Quick
            pfm;
          Alcotest.test_case "a Radiance .hdr holds them in RGBE" `Quick hdr;
          Alcotest.test_case "a write cut short leaves no file" `Quick cut_short;
        ] );
    ]
