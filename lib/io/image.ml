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

let describe_exn = function
  | Sys_error m | Failure m -> m
  | Unix.Unix_error (e, _, _) -> Unix.error_message e
  | e -> Printexc.to_string e

let check_writable = Safe_file.check_writable
let write_atomic = Safe_file.write

let write_ppm oc w h bytes =
  Printf.fprintf oc "P6\n%d %d\n255\n" w h;
  output_bytes oc bytes

let write_png oc raster = Png.encode raster (output_string oc)

let write_rgb8 path w h bytes =
  match format_of_path path with
  | Error e -> Error e
  | Ok Ppm -> write_atomic path (fun oc -> write_ppm oc w h bytes)
  | Ok Png -> write_atomic path (fun oc -> write_png oc (Raster.make ~width:w ~height:h ~channels:3 ~depth:8 bytes))

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
  if w < 1 || h < 1 || w > Settings.max_pixels / h then failwith (Printf.sprintf "unsupported PPM size %d×%d" w h);
  if maxv <> 255 && maxv <> 65535 then failwith (Printf.sprintf "unsupported PPM maximum value %d (lancer reads 255 and 65535)" maxv);
  let depth = if maxv = 255 then 8 else 16 in
  let bytes = Bytes.create (3 * w * h * (depth / 8)) in
  really_input ic bytes 0 (Bytes.length bytes);
  Raster.make ~width:w ~height:h ~channels:3 ~depth bytes

let read_png path =
  let size = (Unix.stat path).st_size in
  (* A PNG is compressed: a file larger than the largest raw image is not one lancer reads. *)
  if size > 4 * 8 * Settings.max_pixels then failwith (Printf.sprintf "the file is too large for an image (%d bytes)" size);
  match Png.decode (In_channel.with_open_bin path In_channel.input_all) with
  | Ok r -> r
  | Error m -> failwith m

let read_raster path =
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

let read_rgb8 path =
  Result.map (fun (r : Raster.t) -> (r.width, r.height, Raster.to_rgb8 r)) (read_raster path)
let srgb_to_linear v = if v <= 0.04045 then v /. 12.92 else Float.pow ((v +. 0.055) /. 1.055) 2.4

(* Every possible sample value decoded once: 256 or 65536 entries. *)
let linear_lut maxv = Float.Array.init (maxv + 1) (fun k -> srgb_to_linear (Float.of_int k /. Float.of_int maxv))

let of_raster (r : Raster.t) =
  let lut = linear_lut (Raster.max_value r) in
  let n = r.width * r.height in
  let data = Float.Array.create (3 * n) in
  let gray = r.channels < 3 in
  for p = 0 to n - 1 do
    let i = p mod r.width and j = p / r.width in
    for c = 0 to 2 do
      Float.Array.set data ((3 * p) + c) (Float.Array.get lut (Raster.get r i j (if gray then 0 else c)))
    done
  done;
  { width = r.width; height = r.height; data }

let read_linear path = Result.map of_raster (read_raster path)
