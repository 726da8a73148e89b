type t = { width : int; height : int; data : Float.Array.t }

let create width height = { width; height; data = Float.Array.make (3 * width * height) 0. }

let get fb i j =
  let k = 3 * ((j * fb.width) + i) in
  Color.v (Float.Array.get fb.data k) (Float.Array.get fb.data (k + 1)) (Float.Array.get fb.data (k + 2))

let set fb i j (c : Color.t) =
  let k = 3 * ((j * fb.width) + i) in
  Float.Array.set fb.data k c.r;
  Float.Array.set fb.data (k + 1) c.g;
  Float.Array.set fb.data (k + 2) c.b

let encode_channel gamma v =
  (* Clamp first: NaN fails both tests below and must not reach int_of_float. *)
  let v = if v > 0. then (if v < 1. then v else 1.) else 0. in
  let v =
    match gamma with
    | Settings.Srgb -> if v <= 0.0031308 then 12.92 *. v else (1.055 *. Float.pow v (1. /. 2.4)) -. 0.055
    | Settings.Power g -> Float.pow v (1. /. g)
  in
  int_of_float (Float.floor ((255. *. v) +. 0.5))

let to_bytes gamma fb =
  let n = 3 * fb.width * fb.height in
  Bytes.init n (fun k -> Char.unsafe_chr (encode_channel gamma (Float.Array.get fb.data k)))

type format = Png | Ppm

let format_of_path path =
  match String.lowercase_ascii (Filename.extension path) with
  | ".png" -> Ok Png
  | ".ppm" -> Ok Ppm
  | "" -> Error (Printf.sprintf "%s: no file extension; use .png or .ppm" path)
  | e -> Error (Printf.sprintf "%s: unsupported image format %s; use .png or .ppm" path e)

let temp_path path =
  let dir = Filename.dirname path and base = Filename.basename path in
  Filename.concat dir (Printf.sprintf ".%s.tmp-%d-%d" base (Unix.getpid ()) (Random.State.bits (Random.State.make_self_init ())))

(* The reason of a failure, without the name of the temporary file: the user only knows
   the path they asked for. *)
let describe_exn ?tmp = function
  | Sys_error m -> (
      match tmp with
      | Some t when String.length m > String.length t + 2 && String.sub m 0 (String.length t + 2) = t ^ ": " ->
          String.sub m (String.length t + 2) (String.length m - String.length t - 2)
      | _ -> m)
  | Unix.Unix_error (e, f, a) -> Printf.sprintf "%s%s: %s" f (if a = "" then "" else " " ^ a) (Unix.error_message e)
  | Failure m -> m
  | e -> Printexc.to_string e

let remove_quietly p = try Sys.remove p with _ -> ()

(* What can be refused before a temporary file exists. *)
let check_writable path =
  let dir = Filename.dirname path in
  if Sys.file_exists path && Sys.is_directory path then Error (Printf.sprintf "cannot write %s: is a directory" path)
  else if not (Sys.file_exists dir) then Error (Printf.sprintf "cannot write %s: directory %s does not exist" path dir)
  else if not (Sys.is_directory dir) then Error (Printf.sprintf "cannot write %s: %s is not a directory" path dir)
  else Ok ()

(* A device or a pipe (/dev/stdout, /dev/null, a FIFO) cannot be replaced by a rename,
   and must not be: running as root, that would swap the device node for a file. *)
let is_special path =
  match (Unix.stat path).st_kind with
  | Unix.S_CHR | Unix.S_BLK | Unix.S_FIFO | Unix.S_SOCK -> true
  | _ -> false
  | exception Unix.Unix_error _ -> false

(* Write through [f tmp] into a temporary file beside [path], then rename it into place;
   on any failure (a full disk included) the temporary file is removed. A device or pipe
   is written in place. *)
let atomically path f =
  match check_writable path with
  | Error e -> Error e
  | Ok () when is_special path -> (
      match f path with
      | () -> Ok ()
      | exception Sys.Break -> raise Sys.Break
      | exception e -> Error (Printf.sprintf "cannot write %s: %s" path (describe_exn ~tmp:path e)))
  | Ok () -> (
      let tmp = temp_path path in
      match f tmp; Unix.rename tmp path with
      | () -> Ok ()
      | exception e ->
          remove_quietly tmp;
          (match e with Sys.Break -> raise e | _ -> ());
          Error (Printf.sprintf "cannot write %s: %s" path (describe_exn ~tmp e)))

let write_atomic path f =
  atomically path (fun tmp ->
      let oc = open_out_bin tmp in
      Fun.protect ~finally:(fun () -> close_out_noerr oc) (fun () -> f oc; close_out oc))

let write_ppm oc w h bytes =
  Printf.fprintf oc "P6\n%d %d\n255\n" w h;
  output_bytes oc bytes

(* camlimages writes PNG to a path, not a channel: it writes the temporary file itself
   and the rename makes it appear atomically. The file is created first so that a refusal
   by the system comes with its reason rather than libpng's "png file open failed". *)
let write_png_atomic path w h bytes =
  atomically path (fun tmp ->
      close_out (open_out_bin tmp);
      let img = Rgb24.create_with w h [] bytes in
      match Png.save tmp [] (Images.Rgb24 img) with
      | () -> ()
      | exception Failure _ -> failwith "the PNG encoder could not write the file (is the disk full?)")

let write_rgb8 path w h bytes =
  match format_of_path path with
  | Error e -> Error e
  | Ok Ppm -> write_atomic path (fun oc -> write_ppm oc w h bytes)
  | Ok Png -> write_png_atomic path w h bytes

let save ?(gamma = Settings.Srgb) path fb = write_rgb8 path fb.width fb.height (to_bytes gamma fb)

let read_ppm path =
  let ic = open_in_bin path in
  Fun.protect ~finally:(fun () -> close_in_noerr ic) @@ fun () ->
  let rec token () =
    let b = Buffer.create 8 in
    let rec skip () =
      match input_char ic with
      | '#' -> ignore (input_line ic); skip ()
      | ' ' | '\n' | '\r' | '\t' -> skip ()
      | c -> Buffer.add_char b c
    in
    skip ();
    let rec more () =
      match input_char ic with
      | ' ' | '\n' | '\r' | '\t' -> ()
      | c -> Buffer.add_char b c; more ()
    in
    more ();
    Buffer.contents b
  and int_token () = match int_of_string_opt (token ()) with Some n -> n | None -> failwith "not a PPM file" in
  if token () <> "P6" then failwith "not a binary (P6) PPM file";
  let w = int_token () in
  let h = int_token () in
  let maxv = int_token () in
  if w < 1 || h < 1 || maxv <> 255 || w > Settings.max_pixels / h then failwith "unsupported PPM header";
  let bytes = Bytes.create (3 * w * h) in
  really_input ic bytes 0 (3 * w * h);
  (w, h, bytes)

let png_signature = "\137PNG\r\n\026\n"

(* What the decoder would find out only after allocating: the signature, and the size in
   the IHDR chunk, which the PNG specification puts first. *)
let check_png_header path =
  let head = In_channel.with_open_bin path (fun ic -> In_channel.really_input_string ic 24) in
  match head with
  | Some h when String.sub h 0 8 = png_signature && String.sub h 12 4 = "IHDR" ->
      let be32 o = (Char.code h.[o] lsl 24) lor (Char.code h.[o + 1] lsl 16) lor (Char.code h.[o + 2] lsl 8) lor Char.code h.[o + 3] in
      let w = be32 16 and h = be32 20 in
      if w < 1 || h < 1 then failwith (Printf.sprintf "a PNG image of %d×%d pixels is empty" w h)
      else if w > Settings.max_pixels / h then
        failwith (Printf.sprintf "image %d×%d is larger than the limit of %d pixels" w h Settings.max_pixels)
  | Some h when String.sub h 0 8 = png_signature -> failwith "not a PNG file (its first chunk is not IHDR)"
  | _ -> failwith "not a PNG file"

let read_png path =
  check_png_header path;
  let load () =
    try Png.load path []
    with Failure m when m <> "" && m.[0] <> '#' -> failwith (Printf.sprintf "corrupt or truncated PNG data (%s)" m)
       | Failure _ -> failwith "corrupt PNG data"
  in
  let rgb =
    match load () with
    | Images.Rgb24 i -> i
    | Images.Rgba32 i -> Rgb24.of_rgba32 i
    | Images.Index8 i -> Index8.to_rgb24 i
    | Images.Index16 i -> Index16.to_rgb24 i
    | Images.Cmyk32 _ -> failwith "CMYK PNG images are not supported"
  in
  let w = rgb.Rgb24.width and h = rgb.Rgb24.height in
  let bytes = Bytes.create (3 * w * h) in
  for j = 0 to h - 1 do
    Bytes.blit (Rgb24.get_scanline rgb j) 0 bytes (3 * w * j) (3 * w)
  done;
  (w, h, bytes)

let read_rgb8 path =
  match format_of_path path with
  | Error e -> Error e
  | Ok fmt -> (
      if not (Sys.file_exists path) then Error (Printf.sprintf "%s: no such file" path)
      else if Sys.is_directory path then Error (Printf.sprintf "%s: is a directory, not an image" path)
      else
        match (match fmt with Png -> read_png path | Ppm -> read_ppm path) with
        | r -> Ok r
        | exception End_of_file -> Error (Printf.sprintf "%s: truncated image file" path)
        | exception e -> Error (Printf.sprintf "%s: cannot read image: %s" path (describe_exn e)))

let srgb_to_linear b =
  let v = Float.of_int b /. 255. in
  if v <= 0.04045 then v /. 12.92 else Float.pow ((v +. 0.055) /. 1.055) 2.4

let read_linear path =
  match read_rgb8 path with
  | Error e -> Error e
  | Ok (w, h, bytes) ->
      let lut = Float.Array.init 256 srgb_to_linear in
      Ok { width = w; height = h; data = Float.Array.init (3 * w * h) (fun k -> Float.Array.get lut (Char.code (Bytes.get bytes k))) }
