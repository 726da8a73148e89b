(* Inputs for the robustness tests and for `make fuzz`: random and mutated OBJ text, image
   bytes and scene text, and the oracles that judge what the loaders do with them. Every
   generator is a function of a Random.State.t, so a seed replays a case. *)
open Lancer
module Dsl = Lancer_dsl.Dsl

let contains s sub =
  let n = String.length s and m = String.length sub in
  let rec go i = i + m <= n && (String.sub s i m = sub || go (i + 1)) in
  go 0

let pick st a = a.(Random.State.int st (Array.length a))

(* ---- mutations of any text or bytes ---- *)

let mutate_once st alphabet s =
  let n = String.length s in
  let pos () = if n = 0 then 0 else Random.State.int st (n + 1) in
  match Random.State.int st 7 with
  | 0 when n > 0 ->
      (* delete a short range *)
      let i = Random.State.int st n in
      let k = min (n - i) (1 + Random.State.int st 8) in
      String.sub s 0 i ^ String.sub s (i + k) (n - i - k)
  | 1 ->
      (* insert a piece of the alphabet *)
      let i = pos () in
      String.sub s 0 i ^ pick st alphabet ^ String.sub s i (n - i)
  | 2 when n > 0 ->
      (* overwrite a byte with any byte *)
      let b = Bytes.of_string s in
      Bytes.set b (Random.State.int st n) (Char.chr (Random.State.int st 256));
      Bytes.to_string b
  | 3 when n > 0 ->
      (* duplicate a range *)
      let i = Random.State.int st n in
      let k = min (n - i) (1 + Random.State.int st 64) in
      let i' = pos () in
      String.sub s 0 i' ^ String.sub s i k ^ String.sub s i' (n - i')
  | 4 when n > 0 -> (* truncate *) String.sub s 0 (Random.State.int st n)
  | 5 when n > 0 ->
      (* flip one bit *)
      let b = Bytes.of_string s in
      let i = Random.State.int st n in
      Bytes.set b i
        (Char.chr (Char.code (Bytes.get b i) lxor (1 lsl Random.State.int st 8)));
      Bytes.to_string b
  | _ ->
      (* swap two ranges' order around a cut *)
      let i = pos () in
      String.sub s i (n - i) ^ String.sub s 0 i

let mutate st alphabet s =
  let rec go k s = if k = 0 then s else go (k - 1) (mutate_once st alphabet s) in
  go (1 + Random.State.int st 6) s

(* ---- OBJ ---- *)

let obj_numbers =
  [|
    "0";
    "1";
    "-1";
    "0.5";
    "-0";
    "1e-7";
    "3.25";
    "1e300";
    "-1e300";
    "1e400";
    "nan";
    "inf";
    "-inf";
    "0x1p3";
    "1_0";
    "1e-320";
    ".";
    "-";
    "+2";
    "1e";
    "12345678901234567890";
  |]

let obj_number st =
  if Random.State.bool st then Printf.sprintf "%g" (Random.State.float st 4. -. 2.)
  else pick st obj_numbers

let obj_index st =
  match Random.State.int st 6 with
  | 0 -> "0"
  | 1 -> string_of_int (-1 - Random.State.int st 6)
  | 2 ->
      pick st
        [| "x"; ""; "-"; "1.5"; "99999999999999999999"; "-4611686018427387904"; "0x2" |]
  | _ -> string_of_int (1 + Random.State.int st 10)

let obj_corner st =
  match Random.State.int st 6 with
  | 0 | 1 | 2 -> obj_index st
  | 3 -> obj_index st ^ "/" ^ obj_index st
  | 4 -> obj_index st ^ "//" ^ obj_index st
  | _ -> obj_index st ^ "/" ^ obj_index st ^ "/" ^ obj_index st

let repeat st lo hi f =
  String.concat " " (List.init (lo + Random.State.int st (hi - lo + 1)) (fun _ -> f st))

let obj_line st =
  match Random.State.int st 14 with
  | 0 | 1 | 2 | 3 -> "v " ^ repeat st 2 5 obj_number
  | 4 -> "vt " ^ repeat st 0 4 obj_number
  | 5 -> "vn " ^ repeat st 2 4 obj_number
  | 6 | 7 | 8 | 9 -> "f " ^ repeat st 1 7 obj_corner
  | 10 ->
      pick st
        [|
          "o thing";
          "g a b";
          "s off";
          "usemtl red";
          "mtllib x.mtl";
          "# a comment";
          "";
          "l 1 2";
        |]
  | 11 ->
      pick st
        [|
          "vx 1 2 3";
          "F 1 2 3";
          "\t";
          "v\t1\t2\t3";
          "f 1 2 3 # tail";
          "\r";
          "\xef\xbb\xbfv 1 2 3";
        |]
  | 12 ->
      String.init (Random.State.int st 12) (fun _ ->
          Char.chr (32 + Random.State.int st 95))
  | _ ->
      pick st
        [|
          "v 0 0 0";
          "v 1 0 0";
          "v 0 1 0";
          "v 0 0 1";
          "f 1 2 3";
          "f -1 -2 -3";
          "vn 0 0 1";
          "vt 0.5 0.5";
        |]

let random_obj st =
  let eol = if Random.State.int st 8 = 0 then "\r\n" else "\n" in
  String.concat eol (List.init (Random.State.int st 40) (fun _ -> obj_line st))

(* A small valid mesh using every statement the loader knows. *)
let seed_obj =
  String.concat "\n"
    [
      "# cube with texture coordinates and normals";
      "o cube";
      "v -1 -1 -1";
      "v 1 -1 -1";
      "v 1 1 -1";
      "v -1 1 -1";
      "v -1 -1 1";
      "v 1 -1 1";
      "v 1 1 1";
      "v -1 1 1";
      "vt 0 0";
      "vt 1 0";
      "vt 1 1";
      "vt 0 1";
      "vn 0 0 -1";
      "vn 0 0 1";
      "vn 0 -1 0";
      "vn 0 1 0";
      "vn -1 0 0";
      "vn 1 0 0";
      "usemtl grey";
      "s 1";
      "f 1/1/1 2/2/1 3/3/1 4/4/1";
      "f 5/1/2 8/4/2 7/3/2 6/2/2";
      "f 1//3 5//3 6//3 2//3";
      "f 4 3 7 8";
      "f -8/-4 -4/-3 -1/-2 -5/-1";
      "f 2 6 7 3";
      "";
    ]

let obj_alphabet =
  [|
    " ";
    "\n";
    "/";
    "//";
    "-";
    ".";
    "e";
    "0";
    "1";
    "9";
    "f ";
    "v ";
    "vn ";
    "vt ";
    "#";
    "\t";
    "\r";
    "\000";
    "nan";
    "1e308";
    "99999999999999999999";
  |]

let mutated_obj st = mutate st obj_alphabet seed_obj

(* The loader's contract: Ok with finite, bounded triangles, or one "file:line: message"
   line. Anything else (an exception, an unlocated or multi-line message) is a failure. *)
let check_obj text =
  match Obj_file.parse ~file:"fuzz.obj" text with
  | exception e -> Error ("raised " ^ Printexc.to_string e)
  | Error m ->
      let located = String.length m > 9 && String.sub m 0 9 = "fuzz.obj:" in
      if not located then Error ("unlocated message: " ^ m)
      else if String.contains m '\n' then Error ("message on several lines: " ^ m)
      else Ok ()
  | Ok [] -> Error "Ok with no triangles"
  | Ok tris ->
      let finite (p : Vec3.t) =
        Float.is_finite p.x && Float.is_finite p.y && Float.is_finite p.z
      in
      if
        List.for_all
          (fun s ->
            match Shape.bbox s with
            | Some b -> finite b.min && finite b.max
            | None -> false)
          tris
      then Ok ()
      else Error "a triangle with non-finite bounds"

let indented text = " " ^ String.concat "\n " (String.split_on_char '\n' text)

let describe_faces = function
  | Error m -> "Error " ^ m
  | Ok tris ->
      let b = Buffer.create 256 in
      let v (p : Vec3.t) = Printf.bprintf b "%h %h %h " p.x p.y p.z in
      List.iter
        (function
          | Shape.Triangle { a; b = pb; c; tn; normals; uvs } ->
              List.iter v [ a; pb; c; tn ];
              Option.iter (fun (x, y, z) -> List.iter v [ x; y; z ]) normals;
              Option.iter
                (fun ((u0, v0), (u1, v1), (u2, v2)) ->
                  List.iter (Printf.bprintf b "%h ") [ u0; v0; u1; v1; u2; v2 ])
                uvs;
              Buffer.add_char b '\n'
          | s -> Buffer.add_string b (Shape.name s ^ "\n"))
        tris;
      Buffer.contents b

let check_obj_lines text =
  let parse t =
    try Obj_file.parse ~file:"fuzz.obj" t with e -> Error (Printexc.to_string e)
  in
  let direct = describe_faces (parse text)
  and by_words = describe_faces (parse (indented text)) in
  if String.equal direct by_words then Ok ()
  else Error (Printf.sprintf "one pass:\n%s\nword by word:\n%s" direct by_words)

(* ---- PLY ---- *)

(* A random mesh (vertices, optional normals and (u, v), polygons of 3 to 6 corners) as
   ASCII, binary little-endian and binary big-endian PLY, written here byte by byte
   (independently of the reader), with extra properties and an extra element to read
   past. *)
type ply_mesh = {
  verts : (float * float * float) array;
  normals : (float * float * float) array option;
  uvs : (float * float) array option;
  polys : int array array;
}

let random_ply_mesh st =
  let n = 3 + Random.State.int st 30 in
  (* Eighths in [−4, 4]: every format holds them exactly, in binary as in decimal. *)
  let f () = Float.of_int (Random.State.int st 65 - 32) /. 8. in
  let verts = Array.init n (fun _ -> (f (), f (), f ())) in
  let normals =
    if Random.State.bool st then Some (Array.init n (fun _ -> (f (), f (), f ())))
    else None
  in
  let uvs =
    if Random.State.bool st then Some (Array.init n (fun _ -> (f (), f ()))) else None
  in
  let polys =
    Array.init
      (1 + Random.State.int st 20)
      (fun _ -> Array.init (3 + Random.State.int st 4) (fun _ -> Random.State.int st n))
  in
  { verts; normals; uvs; polys }

let ply_text fmt (m : ply_mesh) =
  let b = Buffer.create 1024 in
  let add = Buffer.add_string b in
  add "ply\n";
  add (Printf.sprintf "format %s 1.0\n" fmt);
  add "comment written by the fuzzer\n";
  add (Printf.sprintf "element vertex %d\n" (Array.length m.verts));
  add "property float x\nproperty float y\nproperty float z\n";
  add "property uchar quality\n";
  if m.normals <> None then
    add "property float nx\nproperty float ny\nproperty float nz\n";
  if m.uvs <> None then add "property float u\nproperty float v\n";
  add "element edge 1\nproperty int vertex1\nproperty int vertex2\n";
  add (Printf.sprintf "element face %d\n" (Array.length m.polys));
  add "property list uchar uint vertex_indices\nproperty list uchar float texcoord\n";
  add "end_header\n";
  let ascii = fmt = "ascii" and le = fmt = "binary_little_endian" in
  let float x =
    if ascii then add (Printf.sprintf "%g " x)
    else
      let by = Bytes.create 4 in
      let bits = Int32.bits_of_float x in
      if le then Bytes.set_int32_le by 0 bits else Bytes.set_int32_be by 0 bits;
      Buffer.add_bytes b by
  in
  let int32 v =
    if ascii then add (Printf.sprintf "%d " v)
    else
      let by = Bytes.create 4 in
      if le then Bytes.set_int32_le by 0 (Int32.of_int v)
      else Bytes.set_int32_be by 0 (Int32.of_int v);
      Buffer.add_bytes b by
  in
  let uchar v = if ascii then add (Printf.sprintf "%d " v) else Buffer.add_uint8 b v in
  let eol () = if ascii then add "\n" in
  Array.iteri
    (fun i (x, y, z) ->
      float x;
      float y;
      float z;
      uchar (i land 255);
      Option.iter
        (fun ns ->
          let x, y, z = ns.(i) in
          float x;
          float y;
          float z)
        m.normals;
      Option.iter
        (fun us ->
          let u, v = us.(i) in
          float u;
          float v)
        m.uvs;
      eol ())
    m.verts;
  int32 0;
  int32 1;
  eol ();
  Array.iter
    (fun p ->
      uchar (Array.length p);
      Array.iter int32 p;
      uchar 2;
      float 0.25;
      float 0.75;
      eol ())
    m.polys;
  Buffer.contents b

(* The same mesh as OBJ text (the normals and (u, v) indexed with the vertices). *)
let obj_of_ply (m : ply_mesh) =
  let b = Buffer.create 1024 in
  Array.iter (fun (x, y, z) -> Printf.bprintf b "v %g %g %g\n" x y z) m.verts;
  Option.iter
    (Array.iter (fun (x, y, z) -> Printf.bprintf b "vn %g %g %g\n" x y z))
    m.normals;
  Option.iter (Array.iter (fun (u, v) -> Printf.bprintf b "vt %g %g\n" u v)) m.uvs;
  Array.iter
    (fun p ->
      Buffer.add_string b "f";
      Array.iter
        (fun k ->
          let k = k + 1 in
          match (m.uvs, m.normals) with
          | None, None -> Printf.bprintf b " %d" k
          | Some _, None -> Printf.bprintf b " %d/%d" k k
          | None, Some _ -> Printf.bprintf b " %d//%d" k k
          | Some _, Some _ -> Printf.bprintf b " %d/%d/%d" k k k)
        p;
      Buffer.add_char b '\n')
    m.polys;
  Buffer.contents b

let ply_formats = [ "ascii"; "binary_little_endian"; "binary_big_endian" ]
let random_ply st = random_ply_mesh st

let mutated_ply st =
  let m = random_ply_mesh st in
  let fmt = List.nth ply_formats (Random.State.int st 3) in
  mutate st
    [| " "; "\n"; "0"; "-1"; "255"; "list"; "float"; "end_header"; "\000"; "\255" |]
    (ply_text fmt m)

let ply_faces text = Result.map Shape.faces (Ply.parse_mesh ~file:"fuzz.ply" text)

(* The reader's contract: Ok with finite triangles, or one located line. *)
let check_ply text =
  match ply_faces text with
  | exception e -> Error ("raised " ^ Printexc.to_string e)
  | Error m ->
      if not (String.length m > 9 && String.sub m 0 9 = "fuzz.ply:") then
        Error ("unlocated message: " ^ m)
      else if String.contains m '\n' then Error ("message on several lines: " ^ m)
      else Ok ()
  | Ok [] -> Error "Ok with no triangles"
  | Ok _ -> Ok ()

(* A mesh reads to the same triangles, bit for bit, from each PLY format and from OBJ. *)
let check_ply_formats (m : ply_mesh) =
  (* An error's place differs between the formats (a line of OBJ, the whole PLY file):
     its message must not. *)
  let unplaced = function
    | Error msg -> (
        match String.index_opt msg ' ' with
        | Some i -> Error (String.sub msg i (String.length msg - i))
        | None -> Error msg)
    | ok -> ok
  in
  let describe_faces r = describe_faces (unplaced r) in
  let obj =
    describe_faces
      (try Obj_file.parse ~file:"fuzz.ply" (obj_of_ply m)
       with e -> Error (Printexc.to_string e))
  in
  List.fold_left
    (fun acc fmt ->
      Result.bind acc (fun () ->
          let got =
            describe_faces
              (try ply_faces (ply_text fmt m) with e -> Error (Printexc.to_string e))
          in
          if String.equal got obj then Ok ()
          else Error (Printf.sprintf "%s PLY:\n%s\nOBJ:\n%s" fmt got obj)))
    (Ok ()) ply_formats

(* ---- images ---- *)

let tmp_counter = ref 0

let with_temp_file ext contents f =
  incr tmp_counter;
  let path =
    Filename.concat
      (Filename.get_temp_dir_name ())
      (Printf.sprintf "lancer-fuzz-%d-%d%s" (Unix.getpid ()) !tmp_counter ext)
  in
  Out_channel.with_open_bin path (fun oc -> output_string oc contents);
  Fun.protect
    ~finally:(fun () -> try Sys.remove path with Sys_error _ -> ())
    (fun () -> f path)

(* Valid files to mutate: a 5×3 gradient as PNG and as PPM, written by the library. *)
let seed_images =
  lazy
    (let w = 5 and h = 3 in
     let bytes = Bytes.init (3 * w * h) (fun k -> Char.chr (k * 17 land 255)) in
     List.map
       (fun ext ->
         let path = Filename.temp_file "lancer-seed" ext in
         (match Image.write_rgb8 path w h bytes with
         | Ok () -> ()
         | Error m -> failwith m);
         let s = In_channel.with_open_bin path In_channel.input_all in
         Sys.remove path;
         (ext, s))
       [ ".png"; ".ppm" ])

let image_alphabet =
  [|
    "\000";
    "\255";
    "P6";
    "\n";
    " ";
    "255";
    "65535";
    "99999";
    "#";
    "\137PNG\r\n\026\n";
    "IHDR";
    "IDAT";
    "IEND";
  |]

(* (extension, file contents): mostly mutated valid files, some random bytes. *)
let image_case st =
  match Random.State.int st 5 with
  | 0 ->
      let ext = pick st [| ".png"; ".ppm" |] in
      let header = if ext = ".png" then "\137PNG\r\n\026\n" else "P6\n" in
      ( ext,
        (if Random.State.bool st then header else "")
        ^ String.init (Random.State.int st 200) (fun _ ->
              Char.chr (Random.State.int st 256)) )
  | _ ->
      let ext, s = pick st (Array.of_list (Lazy.force seed_images)) in
      (ext, mutate st image_alphabet s)

(* What an unexpected exception looks like once the reader has turned it into a message:
   the decoder crashed, however the crash was reported. *)
let crash_names =
  [
    "internal error";
    "Invalid_argument";
    "Not_found";
    "Assert_failure";
    "Match_failure";
    "Division_by_zero";
    "Stack_overflow";
    "Out_of_memory";
    "Stdlib.";
  ]

(* The decoder's contract: Error with a one-line reason, or a framebuffer of the stated
   size with finite values in [0, 1]; never an exception, nor a crash reported as an
   Error. *)
let judge_image_error m =
  if List.exists (contains m) crash_names then Error ("crashed: " ^ m)
  else if String.contains m '\n' then Error ("message on several lines: " ^ m)
  else Ok ()

let check_image (ext, contents) =
  with_temp_file ext contents (fun path ->
      match Image.read_linear path with
      | exception e -> Error ("raised " ^ Printexc.to_string e)
      | Error m -> judge_image_error m
      | Ok fb ->
          if
            fb.width < 1 || fb.height < 1
            || Float.Array.length fb.data <> 3 * fb.width * fb.height
          then Error "inconsistent size"
          else if Float.Array.exists (fun v -> not (v >= 0. && v <= 1.)) fb.data then
            Error "a value outside [0, 1]"
          else Ok ())

let crc_table =
  lazy
    (Array.init 256 (fun n ->
         let c = ref n in
         for _ = 0 to 7 do
           c := if !c land 1 = 1 then 0xedb88320 lxor (!c lsr 1) else !c lsr 1
         done;
         !c))

let crc32 s =
  let t = Lazy.force crc_table in
  let c = ref 0xffffffff in
  String.iter (fun ch -> c := t.(!c lxor Char.code ch land 0xff) lxor (!c lsr 8)) s;
  !c lxor 0xffffffff

let be32 n = String.init 4 (fun i -> Char.chr ((n lsr (8 * (3 - i))) land 0xff))
let chunk kind data = be32 (String.length data) ^ kind ^ data ^ be32 (crc32 (kind ^ data))

(* Hand-made PNG files with valid checksums (random mutation rarely keeps a CRC right).
   A PNG whose header claims w×h 8-bit RGB pixels, with the data of one black pixel. *)
let png_claiming w h =
  "\137PNG\r\n\026\n"
  ^ chunk "IHDR" (be32 w ^ be32 h ^ "\008\002\000\000\000")
  ^ chunk "IDAT" "\120\156\099\096\096\096\000\000\000\004\000\001"
  ^ chunk "IEND" ""

let png_one_pixel () = png_claiming 1 1

(* ---- scenes ---- *)

(* The words and symbols random scenes are made of; the language's own properties use them too. *)
let dsl_tokens =
  [|
    "let";
    "fn";
    "for";
    "in";
    "to";
    "step";
    "if";
    "then";
    "else";
    "include";
    "body";
    "material";
    "and";
    "or";
    "not";
    "true";
    "false";
    "(";
    ")";
    "{";
    "}";
    ",";
    ":";
    ".";
    "=";
    "==";
    "!=";
    "<";
    "<=";
    ">";
    ">=";
    "+";
    "-";
    "*";
    "/";
    "%";
    "^";
    "x";
    "i";
    "f";
    "sphere";
    "plane";
    "box";
    "mesh";
    "group";
    "union";
    "merge";
    "intersection";
    "difference";
    "cone";
    "torus";
    "height_field";
    "major";
    "minor";
    "caps";
    "settings";
    "camera";
    "light";
    "animation";
    "physics";
    "center";
    "radius";
    "normal";
    "offset";
    "min";
    "max";
    "file";
    "position";
    "width";
    "depth";
    "samples";
    "0";
    "1";
    "2";
    "-2.5";
    ".5";
    "1e300";
    "1e-300";
    "1e400";
    "\"a.rts\"";
    "\"srgb\"";
    "\"x.png\"";
    "\"x.obj\"";
    "sin";
    "sqrt";
    "rand";
    "checker";
    "image";
    "noise";
    "pi";
    "time";
    "frame";
    "rgb";
    "translate";
    "rotate";
    "scale";
    "//";
    "/*";
    "*/";
    "\n";
    "\"";
    "\000";
    "\xc3\xa9";
    "\xff";
  |]

let random_tokens st =
  String.concat " " (List.init (Random.State.int st 30) (fun _ -> pick st dsl_tokens))

(* The scenes of scenes/, relative to [root], with their file names (includes, meshes and
   images resolve beside them). *)
let scene_seeds root =
  let dir = Filename.concat root "scenes" in
  match Sys.readdir dir with
  | exception Sys_error _ -> [||]
  | files ->
      Array.to_list files |> List.sort compare
      |> List.filter (fun f -> Filename.check_suffix f ".rts")
      |> List.map (fun f ->
             let p = Filename.concat dir f in
             (p, In_channel.with_open_bin p In_channel.input_all))
      |> Array.of_list

let scene_case seeds st =
  if Array.length seeds = 0 || Random.State.int st 3 = 0 then
    ("fuzz.rts", random_tokens st)
  else
    let file, text = pick st seeds in
    (file, mutate st dsl_tokens text)

(* An error that reports a crash: the boundary turns an unexpected exception into an
   "internal error" message, which is a bug however well it is worded. *)
let crash (es : Lancer_dsl.Error.t list) =
  List.find_opt (fun (e : Lancer_dsl.Error.t) -> contains e.message "internal error") es

let judge_scene_errors es =
  match crash es with
  | Some e -> Error ("crashed: " ^ e.message)
  | None -> if es = [] then Error "Error with no message" else Ok ()

(* The language's contract (dsl.mli): Ok or located errors, never an exception nor an
   internal error, at load and at evaluation. *)
let check_scene (file, text) =
  match Program.load_string ~filename:file text with
  | exception e -> Error ("load raised " ^ Printexc.to_string e)
  | Error es -> (
      match List.iter (fun e -> ignore (Lancer_dsl.Error.to_string e)) es with
      | exception e -> Error ("printing an error raised " ^ Printexc.to_string e)
      | () -> Result.map_error (fun m -> "load " ^ m) (judge_scene_errors es))
  | Ok p -> (
      match Program.scene_at p ~time:0.5 ~frame:12 with
      | exception e -> Error ("evaluation raised " ^ Printexc.to_string e)
      | Error es -> Result.map_error (fun m -> "evaluation " ^ m) (judge_scene_errors es)
      | Ok sc -> (
          match Program.to_json p sc with
          | exception e -> Error ("to_json raised " ^ Printexc.to_string e)
          | _ -> Ok ()))
