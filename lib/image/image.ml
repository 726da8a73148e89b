(* The framebuffer's fields, for the encoders below. *)
type fb = Framebuffer.t = { width : int; height : int; data : Float.Array.t }
type gamma = Srgb | Power of float

let max_pixels = Raster.max_pixels

(* The encoding curve on a clamped value. *)
let[@inline] curve gamma v =
  (* Clamp first: NaN fails both tests below and must not reach int_of_float. *)
  let v = if v > 0. then if v < 1. then v else 1. else 0. in
  match gamma with
  | Srgb ->
      if v <= 0.0031308 then 12.92 *. v else (1.055 *. Float.pow v (1. /. 2.4)) -. 0.055
  | Power g -> Float.pow v (1. /. g)

let exact_channel gamma v = int_of_float (Float.floor ((255. *. curve gamma v) +. 0.5))

(* The 8-bit sRGB code without a pow per sample, the same byte as [exact_channel Srgb].
   The code steps from k − 1 to k where the curve reaches (k − 0.5)/255, at the value
   [srgb_edge k] (the curve's inverse there). [0, 1] is cut into 4096 bins, narrower than
   the closest two steps (1/3295 apart, where the curve is steepest): each bin holds the
   code at its start and the first step after its start, so a value's code is one
   comparison. A value within [near] of a step is encoded the exact way: the steps
   computed here and the rounding of the exact formula are each a few ulps off, far below
   [near], so every other value gets the exact formula's code. *)
let srgb_edge k =
  let c = (Float.of_int k -. 0.5) /. 255. in
  if c <= 0.04045 then c /. 12.92 else Float.pow ((c +. 0.055) /. 1.055) 2.4

let bins = 4096
let near = 1e-9

(* Per bin: the code at its start, the last step at or before its start and the first
   after it (the infinities where there is none). A bin that would hold two steps gets
   +∞ as its last step, so that every value in it is encoded the exact way. *)
let srgb_base, srgb_before, srgb_after =
  let edge k =
    if k <= 0 then Float.neg_infinity
    else if k >= 256 then Float.infinity
    else srgb_edge k
  in
  let base = Bytes.create (bins + 1)
  and before = Float.Array.make (bins + 1) 0.
  and after = Float.Array.make (bins + 1) 0. in
  let k = ref 0 in
  for b = 0 to bins do
    let start = Float.of_int b /. Float.of_int bins
    and stop = Float.of_int (b + 1) /. Float.of_int bins in
    while edge (!k + 1) <= start do
      incr k
    done;
    Bytes.set_uint8 base b !k;
    Float.Array.set before b (if edge (!k + 2) < stop then Float.infinity else edge !k);
    Float.Array.set after b (edge (!k + 1))
  done;
  (base, before, after)

let[@inline] srgb_channel v =
  let v = if v > 0. then if v < 1. then v else 1. else 0. in
  let b = int_of_float (v *. 4096.) in
  let after = Float.Array.unsafe_get srgb_after b in
  if v -. Float.Array.unsafe_get srgb_before b < near || Float.abs (after -. v) < near
  then exact_channel Srgb v
  else
    let k = Char.code (Bytes.unsafe_get srgb_base b) in
    if v >= after then k + 1 else k

let encode_channel gamma v =
  match gamma with Srgb -> srgb_channel v | g -> exact_channel g v

let encode_channel16 gamma v =
  int_of_float (Float.floor ((65535. *. curve gamma v) +. 0.5))

(* Alpha is a linear share, never gamma-encoded. *)
let quantise maxv a =
  let a = if a > 0. then if a < 1. then a else 1. else 0. in
  int_of_float (Float.floor ((Float.of_int maxv *. a) +. 0.5))

let to_bytes gamma fb =
  let n = 3 * fb.width * fb.height in
  let b = Bytes.create n in
  (match gamma with
  | Srgb ->
      let data = fb.data in
      if Float.Array.length data < n then invalid_arg "Image.to_bytes";
      for k = 0 to n - 1 do
        Bytes.unsafe_set b k
          (Char.unsafe_chr (srgb_channel (Float.Array.unsafe_get data k)))
      done
  | g ->
      for k = 0 to n - 1 do
        Bytes.unsafe_set b k
          (Char.unsafe_chr (exact_channel g (Float.Array.get fb.data k)))
      done);
  b

type format = Png | Ppm | Exr | Hdr | Pfm

let linear = function Exr | Hdr | Pfm -> true | Png | Ppm -> false
let keeps_record = function Png | Exr -> true | Ppm | Hdr | Pfm -> false

let format_name = function
  | Png -> "png"
  | Ppm -> "ppm"
  | Exr -> "exr"
  | Hdr -> "hdr"
  | Pfm -> "pfm"

let format_of_path path =
  match String.lowercase_ascii (Filename.extension path) with
  | ".png" -> Ok Png
  | ".ppm" -> Ok Ppm
  | ".exr" -> Ok Exr
  | ".hdr" -> Ok Hdr
  | ".pfm" -> Ok Pfm
  | "" ->
      Error
        (Printf.sprintf "%s: no file extension; use .png, .ppm, .exr, .hdr or .pfm" path)
  | e ->
      Error
        (Printf.sprintf
           "%s: unsupported image format %s; use .png, .ppm, .exr, .hdr or .pfm" path e)

let describe_exn = function
  | Sys_error m | Failure m -> m
  | Unix.Unix_error (e, _, _) -> Unix.error_message e
  | e -> Printexc.to_string e

let check_writable path =
  match format_of_path path with
  | Ok Exr when Result.is_error Lancer_exr.Exr.available ->
      Result.map_error
        (Printf.sprintf "cannot write %s: %s" path)
        Lancer_exr.Exr.available
  | _ -> Safe_file.check_writable path

let write_atomic = Safe_file.write

let write_ppm oc w h bytes =
  Printf.fprintf oc "P6\n%d %d\n255\n" w h;
  output_bytes oc bytes

let write_png oc raster = Png.encode raster (output_string oc)

let png_bytes ?text raster =
  let b = Buffer.create (max 4096 (Bytes.length raster.Raster.samples / 4)) in
  Png.encode ?text raster (Buffer.add_string b);
  Buffer.contents b

let write_rgb8 path w h bytes =
  match format_of_path path with
  | Error e -> Error e
  | Ok Ppm -> write_atomic path (fun oc -> write_ppm oc w h bytes)
  | Ok Png ->
      let png = png_bytes (Raster.make ~width:w ~height:h ~channels:3 ~depth:8 bytes) in
      write_atomic path (fun oc -> output_string oc png)
  | Ok (Exr | Hdr | Pfm) ->
      Error
        (Printf.sprintf "cannot write %s: 8-bit pixels go to a .png or .ppm file" path)

type region = { x0 : int; y0 : int; x1 : int; y1 : int }

let encode ?(gamma = Srgb) ?(bits = 8) ?alpha ?crop fb =
  if bits <> 8 && bits <> 16 then invalid_arg "Image.encode: bits must be 8 or 16";
  (match alpha with
  | Some a when Float.Array.length a <> fb.width * fb.height ->
      invalid_arg "Image.encode: alpha has the wrong size"
  | _ -> ());
  let r =
    match crop with
    | Some r -> r
    | None -> { x0 = 0; y0 = 0; x1 = fb.width; y1 = fb.height }
  in
  if
    r.x0 < 0 || r.y0 < 0 || r.x1 > fb.width || r.y1 > fb.height || r.x0 >= r.x1
    || r.y0 >= r.y1
  then invalid_arg "Image.encode: the crop region is not inside the image";
  let w = r.x1 - r.x0 and h = r.y1 - r.y0 in
  if bits = 8 && Option.is_none alpha && w = fb.width && h = fb.height then
    Raster.make ~width:w ~height:h ~channels:3 ~depth:8 (to_bytes gamma fb)
  else
    let channels = if alpha = None then 3 else 4 in
    let b = Bytes.create (w * h * channels * (bits / 8)) in
    let put k v =
      if bits = 8 then Bytes.set_uint8 b k v else Bytes.set_uint16_be b (2 * k) v
    in
    let enc = if bits = 8 then encode_channel gamma else encode_channel16 gamma in
    let maxv = if bits = 8 then 255 else 65535 in
    for j = 0 to h - 1 do
      for i = 0 to w - 1 do
        let src = ((r.y0 + j) * fb.width) + r.x0 + i and dst = ((j * w) + i) * channels in
        for c = 0 to 2 do
          put (dst + c) (enc (Float.Array.get fb.data ((3 * src) + c)))
        done;
        match alpha with
        | Some a -> put (dst + 3) (quantise maxv (Float.Array.get a src))
        | None -> ()
      done
    done;
    Raster.make ~width:w ~height:h ~channels ~depth:bits b

let write_ppm_raster oc (r : Raster.t) =
  Printf.fprintf oc "P6\n%d %d\n%d\n" r.width r.height (Raster.max_value r);
  output_bytes oc r.samples

let output_raster fmt oc (r : Raster.t) =
  match fmt with
  | Ppm when r.channels <> 3 ->
      invalid_arg "Image.output_raster: a PPM file holds RGB only"
  | Ppm -> write_ppm_raster oc r
  | Png -> write_png oc r
  | Exr | Hdr | Pfm -> invalid_arg "Image.output_raster: a linear format holds no raster"

(* A file's bytes in memory first, so that the temporary file exists only while its
   bytes are written: a process killed while it compresses (as mpirun kills its ranks
   half a second after it asks them to stop) leaves nothing behind; and what is recorded
   of the file is digested from these very bytes. *)
let file_bytes path (r : Raster.t) =
  match format_of_path path with
  | Error e -> Error e
  | Ok Ppm when r.channels <> 3 ->
      Error
        (Printf.sprintf
           "cannot write %s: a PPM file holds RGB only (no alpha, no gray); write a .png"
           path)
  | Ok Ppm ->
      let header =
        Printf.sprintf "P6\n%d %d\n%d\n" r.width r.height (Raster.max_value r)
      in
      Ok (header ^ Bytes.unsafe_to_string r.samples)
  | Ok Png -> Ok (png_bytes r)
  | Ok (Exr | Hdr | Pfm) ->
      invalid_arg "Image.file_bytes: a linear format is written from the framebuffer"

(* ---- Linear images: the framebuffer's values themselves, before any curve ---- *)

(* The region's pixels, row-major from the top: its width, height, the three channels of
   each and, with [alpha], the alpha of each. *)
let cropped ?alpha ?crop fb =
  let r =
    match crop with
    | Some r -> r
    | None -> { x0 = 0; y0 = 0; x1 = fb.width; y1 = fb.height }
  in
  let w = r.x1 - r.x0 and h = r.y1 - r.y0 in
  let rgb = Float.Array.create (3 * w * h) in
  let a = Option.map (fun _ -> Float.Array.create (w * h)) alpha in
  for j = 0 to h - 1 do
    for i = 0 to w - 1 do
      let src = ((r.y0 + j) * fb.width) + r.x0 + i and dst = (j * w) + i in
      for c = 0 to 2 do
        Float.Array.set rgb ((3 * dst) + c) (Float.Array.get fb.data ((3 * src) + c))
      done;
      match (alpha, a) with
      | Some al, Some a -> Float.Array.set a dst (Float.Array.get al src)
      | _ -> ()
    done
  done;
  (w, h, rgb, a)

(* Portable float map: "PF", the size, −1 (little-endian), then 32-bit floats, rows from
   the bottom. *)
let pfm_bytes w h rgb =
  let header = Printf.sprintf "PF\n%d %d\n-1.0\n" w h in
  let n = String.length header in
  let b = Bytes.create (n + (12 * w * h)) in
  Bytes.blit_string header 0 b 0 n;
  for j = 0 to h - 1 do
    let row = h - 1 - j in
    for i = 0 to w - 1 do
      for c = 0 to 2 do
        Bytes.set_int32_le b
          (n + (4 * ((3 * ((j * w) + i)) + c)))
          (Int32.bits_of_float (Float.Array.get rgb ((3 * ((row * w) + i)) + c)))
      done
    done
  done;
  Bytes.unsafe_to_string b

(* Radiance RGBE: a shared exponent per pixel, mantissas of 8 bits; flat scanlines (no
   run-length encoding), which every reader takes. Negative and NaN values are 0. *)
let rgbe r g b =
  let pos x =
    if x > 0. && x <= Float.max_float then x else if x > 0. then Float.max_float else 0.
  in
  let r = pos r and g = pos g and b = pos b in
  let v = Float.max r (Float.max g b) in
  if v < 1e-32 then (0, 0, 0, 0)
  else
    let m, e = Float.frexp v in
    let scale = m *. 256. /. v in
    let q x = min 255 (int_of_float (x *. scale)) in
    (q r, q g, q b, min 255 (e + 128))

let hdr_bytes w h rgb =
  let header = Printf.sprintf "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" h w in
  let n = String.length header in
  let b = Bytes.create (n + (4 * w * h)) in
  Bytes.blit_string header 0 b 0 n;
  for p = 0 to (w * h) - 1 do
    let r, g, bl, e =
      rgbe
        (Float.Array.get rgb (3 * p))
        (Float.Array.get rgb ((3 * p) + 1))
        (Float.Array.get rgb ((3 * p) + 2))
    in
    let o = n + (4 * p) in
    Bytes.set_uint8 b o r;
    Bytes.set_uint8 b (o + 1) g;
    Bytes.set_uint8 b (o + 2) bl;
    Bytes.set_uint8 b (o + 3) e
  done;
  Bytes.unsafe_to_string b

let linear_bytes fmt ?(bits = 16) ?alpha ?crop ?record fb =
  let w, h, rgb, a = cropped ?alpha ?crop fb in
  match fmt with
  | Exr ->
      Lancer_exr.Exr.encode ?record ~width:w ~height:h ~half:(bits <> 32) ~rgb ~alpha:a ()
  | Pfm when alpha <> None -> Error "a PFM file holds RGB only (no alpha); write a .exr"
  | Hdr when alpha <> None -> Error "a Radiance .hdr file has no alpha; write a .exr"
  | Pfm -> Ok (pfm_bytes w h rgb)
  | Hdr -> Ok (hdr_bytes w h rgb)
  | Png | Ppm -> invalid_arg "Image.linear_bytes: not a linear format"

type written = { size : int; md5 : string Lazy.t }

(* The MD5 of the very bytes written (an immutable string), taken where it is asked for:
   a frame's record asks, a still does not (a 1920×1080 PPM's MD5 is about 1.5 % of the
   100 000-sphere field's render). *)
let write_file path bytes =
  Result.map
    (fun () ->
      { size = String.length bytes; md5 = lazy (Digest.to_hex (Digest.string bytes)) })
    (write_atomic path (fun oc -> output_string oc bytes))

let write_raster path (r : Raster.t) =
  Result.map ignore (Result.bind (file_bytes path r) (write_file path))

let bits_problem fmt bits =
  match (fmt, bits) with
  | _, None | (Png | Ppm), Some (8 | 16) | Exr, Some (16 | 32) -> None
  | (Png | Ppm), Some b ->
      Some (Printf.sprintf "%d bits: a PNG or PPM image holds 8 or 16 bits a channel" b)
  | Exr, Some b ->
      Some
        (Printf.sprintf
           "%d bits: an EXR image holds 16-bit half floats (the default) or 32-bit floats"
           b)
  | (Hdr | Pfm), Some b ->
      Some
        (Printf.sprintf "%d bits: a %s image has one depth of its own" b
           (if fmt = Hdr then "Radiance .hdr" else "PFM"))

(* A 32-bit digest of bytes [off, off + len) of [s] folded into [h]: FNV-1a over 4-byte
   words (then the bytes left), in native ints, so that nothing is allocated. Each step is
   a bijection of the digest for a given word, so a change within one word always changes
   it. *)
external get32u : string -> int -> int32 = "%caml_string_get32u"
external get64u : string -> int -> int64 = "%caml_string_get64u"
external swap32 : int32 -> int32 = "%bswap_int32"
external swap64 : int64 -> int64 = "%bswap_int64"

(* Only the low 32 bits of [h] matter: those of a product depend only on those of its
   factors, so the masking waits for the end, and a 64-bit load gives two words. *)
let fold_words h s off len =
  if off < 0 || len < 0 || off + len > String.length s then invalid_arg "Image.fold_words";
  let p = 0x01000193 in
  let h = ref h and i = ref off in
  let stop = off + len in
  while !i + 8 <= stop do
    (* Little-endian words on every machine. *)
    let w = get64u s !i in
    let w = if Sys.big_endian then swap64 w else w in
    h := !h lxor Int64.to_int w * p;
    h := !h lxor Int64.to_int (Int64.shift_right_logical w 32) * p;
    i := !i + 8
  done;
  if !i + 4 <= stop then (
    let w = get32u s !i in
    let w = if Sys.big_endian then swap32 w else w in
    h := !h lxor Int32.to_int w * p;
    i := !i + 4);
  while !i < stop do
    h := !h lxor Char.code (String.unsafe_get s !i) * p;
    incr i
  done;
  !h land 0xFFFF_FFFF

let block_digests ~size (r : Raster.t) =
  let nx = (r.width + size - 1) / size and ny = (r.height + size - 1) / size in
  let px = r.channels * (r.depth / 8) in
  let s = Bytes.unsafe_to_string r.samples in
  let b = Buffer.create (8 * nx * ny) in
  for by = 0 to ny - 1 do
    for bx = 0 to nx - 1 do
      let x0 = bx * size in
      let len = min size (r.width - x0) * px in
      let h = ref 0x811C9DC5 in
      for j = by * size to min r.height ((by + 1) * size) - 1 do
        h := fold_words !h s (((j * r.width) + x0) * px) len
      done;
      Buffer.add_string b (Printf.sprintf "%08x" !h)
    done
  done;
  Buffer.contents b

let record_keyword = "lancer"

let file_of fmt ?gamma ?bits ?alpha ?crop ?text fb =
  match bits_problem fmt bits with
  | Some m -> Error m
  | None when linear fmt ->
      (* An EXR header keeps the record (without blocks: they are digests of samples). *)
      let record = Option.bind text (fun f -> List.assoc_opt record_keyword (f None)) in
      linear_bytes fmt ?bits ?alpha ?crop ?record fb
  | None -> (
      let r = encode ?gamma ?bits ?alpha ?crop fb in
      match fmt with
      | Ppm when r.channels <> 3 -> Error "a PPM file holds RGB only (no alpha, no gray)"
      | Ppm ->
          Ok
            (Printf.sprintf "P6\n%d %d\n%d\n" r.width r.height (Raster.max_value r)
            ^ Bytes.unsafe_to_string r.samples)
      | _ -> Ok (png_bytes ?text:(Option.map (fun f -> f (Some r)) text) r))

let save_written ?gamma ?bits ?alpha ?crop ?text path fb =
  Result.bind (format_of_path path) (fun fmt ->
      Result.bind
        (Result.map_error
           (fun m -> Printf.sprintf "cannot write %s: %s" path m)
           (file_of fmt ?gamma ?bits ?alpha ?crop ?text fb))
        (write_file path))

let save ?gamma ?bits ?alpha ?crop path fb =
  Result.map ignore (save_written ?gamma ?bits ?alpha ?crop path fb)

(* A binary PPM's header (magic, width, height, maximum value, each after white space or
   comments) and its samples, from the file's bytes. *)
let ppm_of_string text =
  let len = String.length text in
  let pos = ref 0 in
  let next () =
    if !pos >= len then raise End_of_file;
    let c = text.[!pos] in
    incr pos;
    c
  in
  let token () =
    let b = Buffer.create 8 in
    let rec skip () =
      match next () with
      | '#' ->
          while next () <> '\n' do
            ()
          done;
          skip ()
      | ' ' | '\n' | '\r' | '\t' -> skip ()
      | c -> Buffer.add_char b c
    in
    skip ();
    let rec more () =
      match next () with
      | ' ' | '\n' | '\r' | '\t' -> ()
      | c ->
          Buffer.add_char b c;
          more ()
    in
    more ();
    Buffer.contents b
  in
  let int_token () =
    match int_of_string_opt (token ()) with
    | Some n -> n
    | None -> failwith "not a PPM file"
  in
  if token () <> "P6" then failwith "not a binary (P6) PPM file";
  let w = int_token () in
  let h = int_token () in
  let maxv = int_token () in
  if w < 1 || h < 1 || w > max_pixels / h then
    failwith (Printf.sprintf "unsupported PPM size %d×%d" w h);
  if maxv <> 255 && maxv <> 65535 then
    failwith
      (Printf.sprintf "unsupported PPM maximum value %d (lancer reads 255 and 65535)" maxv);
  let depth = if maxv = 255 then 8 else 16 in
  let n = 3 * w * h * (depth / 8) in
  if len - !pos < n then raise End_of_file;
  Raster.make ~width:w ~height:h ~channels:3 ~depth
    (Bytes.of_string (String.sub text !pos n))

let png_of_string text = match Png.decode text with Ok r -> r | Error m -> failwith m

(* A PNG is compressed: a file larger than the largest raw image is not one lancer reads. *)
let max_png_bytes = 4 * 8 * max_pixels

let raster_of_string ~path text =
  match format_of_path path with
  | Error e -> Error e
  | Ok fmt -> (
      match
        match fmt with
        | Png ->
            if String.length text > max_png_bytes then
              failwith
                (Printf.sprintf "the file is too large for an image (%d bytes)"
                   (String.length text));
            png_of_string text
        | Ppm -> ppm_of_string text
        | Exr | Hdr | Pfm ->
            failwith "lancer reads PNG and PPM images (textures, height fields, goldens)"
      with
      | r -> Ok r
      | exception End_of_file -> Error (Printf.sprintf "%s: truncated image file" path)
      | exception e -> Error (Printf.sprintf "%s: %s" path (describe_exn e)))

let read_bytes path =
  match format_of_path path with
  | Error _ | Ok (Exr | Hdr | Pfm) ->
      Error
        (Printf.sprintf
           "%s: unsupported image format %s; lancer reads .png and .ppm images" path
           (match Filename.extension path with "" -> "(no extension)" | e -> e))
  | Ok fmt -> (
      if not (Sys.file_exists path) then Error (Printf.sprintf "%s: no such file" path)
      else if Sys.is_directory path then
        Error (Printf.sprintf "%s: is a directory, not an image" path)
      else
        match Unix.stat path with
        | exception Unix.Unix_error (e, _, _) ->
            Error (Printf.sprintf "%s: %s" path (Unix.error_message e))
        | { st_kind = Unix.S_REG; st_size; _ } -> (
            if fmt = Png && st_size > max_png_bytes then
              Error
                (Printf.sprintf "%s: the file is too large for an image (%d bytes)" path
                   st_size)
            else
              match In_channel.with_open_bin path In_channel.input_all with
              | text -> Ok text
              | exception e -> Error (Printf.sprintf "%s: %s" path (describe_exn e)))
        | _ ->
            (* A device or a pipe could be endless (/dev/zero) or block forever (a FIFO). *)
            Error
              (Printf.sprintf "%s: not a regular file (a device or a pipe), not an image"
                 path))

let read_raster path = Result.bind (read_bytes path) (raster_of_string ~path)

let read_rgb8 path =
  Result.map
    (fun (r : Raster.t) -> (r.width, r.height, Raster.to_rgb8 r))
    (read_raster path)

let srgb_to_linear v =
  if v <= 0.04045 then v /. 12.92 else Float.pow ((v +. 0.055) /. 1.055) 2.4

(* Every possible sample value decoded once: 256 or 65536 entries. *)
let linear_lut maxv =
  Float.Array.init (maxv + 1) (fun k ->
      srgb_to_linear (Float.of_int k /. Float.of_int maxv))

let of_raster (r : Raster.t) =
  let lut = linear_lut (Raster.max_value r) in
  let n = r.width * r.height in
  let data = Float.Array.create (3 * n) in
  let gray = r.channels < 3 in
  for p = 0 to n - 1 do
    let i = p mod r.width and j = p / r.width in
    for c = 0 to 2 do
      Float.Array.set data
        ((3 * p) + c)
        (Float.Array.get lut (Raster.get r i j (if gray then 0 else c)))
    done
  done;
  { width = r.width; height = r.height; data }

let read_linear path = Result.map of_raster (read_raster path)
let linear_of_string ~path text = Result.map of_raster (raster_of_string ~path text)
