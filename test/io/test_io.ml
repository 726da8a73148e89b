(* Image files as other programs write and read them. *)
open Lancer

let tmpdir () =
  let d =
    Filename.concat
      (Filename.get_temp_dir_name ())
      (Printf.sprintf "lancer-io-%d-%d" (Unix.getpid ()) (Random.bits ()))
  in
  Unix.mkdir d 0o755;
  d

let read_file p = In_channel.with_open_bin p In_channel.input_all
let write_file p s = Out_channel.with_open_bin p (fun oc -> output_string oc s)

(* A raster of pseudo-random samples (a fixed seed), with smooth parts and edges. *)
let sample_raster ~width ~height ~channels ~depth =
  let st = Random.State.make [| width; height; channels; depth |] in
  let maxv = (1 lsl depth) - 1 in
  let n = width * height * channels in
  let b = Bytes.create (n * (depth / 8)) in
  for k = 0 to n - 1 do
    let v =
      if k mod 7 < 3 then k * 37 mod (maxv + 1) else Random.State.int st (maxv + 1)
    in
    if depth = 8 then Bytes.set_uint8 b k v else Bytes.set_uint16_be b (2 * k) v
  done;
  Raster.make ~width ~height ~channels ~depth b

let encode r =
  let b = Buffer.create 1024 in
  Png.encode r (Buffer.add_string b);
  Buffer.contents b

let check_raster msg (a : Raster.t) (b : Raster.t) =
  Alcotest.(check (list int))
    (msg ^ ": size, channels, depth")
    [ a.width; a.height; a.channels; a.depth ]
    [ b.width; b.height; b.channels; b.depth ];
  Alcotest.(check bool) (msg ^ ": samples") true (Bytes.equal a.samples b.samples)

(* ---- A second, independent PNG writer (for the tests only): Adam7 interlacing, packed
   samples of 1, 2 and 4 bits, palettes, and every filter type, none of which lancer's
   writer makes. *)

let crc32 s =
  let table =
    Array.init 256 (fun n ->
        let c = ref n in
        for _ = 0 to 7 do
          c := if !c land 1 = 1 then 0xEDB88320 lxor (!c lsr 1) else !c lsr 1
        done;
        !c)
  in
  let c = ref 0xFFFFFFFF in
  String.iter (fun ch -> c := table.(!c lxor Char.code ch land 0xFF) lxor (!c lsr 8)) s;
  !c lxor 0xFFFFFFFF

let be32 n =
  let b = Bytes.create 4 in
  Bytes.set_int32_be b 0 (Int32.of_int n);
  Bytes.to_string b

let chunk kind data = be32 (String.length data) ^ kind ^ data ^ be32 (crc32 (kind ^ data))

let deflate s =
  let b = Buffer.create 256 and pos = ref 0 in
  Zlib.compress
    (fun buf ->
      let n = min (Bytes.length buf) (String.length s - !pos) in
      Bytes.blit_string s !pos buf 0 n;
      pos := !pos + n;
      n)
    (fun buf n -> Buffer.add_subbytes b buf 0 n);
  Buffer.contents b

(* [values.(j).(i)] are the samples of pixel (i, j) (one per channel), each < 2^depth. *)
let png_of ~ctype ~depth ~interlaced ?(extra = "") w h (values : int array array array) =
  let channels = match ctype with 0 | 3 -> 1 | 2 -> 3 | 4 -> 2 | _ -> 4 in
  let passes =
    if interlaced then
      [
        (0, 0, 8, 8);
        (4, 0, 8, 8);
        (0, 4, 4, 8);
        (2, 0, 4, 4);
        (0, 2, 2, 4);
        (1, 0, 2, 2);
        (0, 1, 1, 2);
      ]
    else [ (0, 0, 1, 1) ]
  in
  let raw = Buffer.create 1024 in
  let row_no = ref 0 in
  List.iter
    (fun (x0, y0, dx, dy) ->
      let pw = (w - x0 + dx - 1) / dx and ph = (h - y0 + dy - 1) / dy in
      if pw > 0 && ph > 0 then
        let stride = ((pw * channels * depth) + 7) / 8 in
        let bpp = max 1 (channels * depth / 8) in
        let prev = ref (Bytes.make stride '\000') in
        for y = 0 to ph - 1 do
          let row = Bytes.make stride '\000' in
          let bit = ref 0 in
          for x = 0 to pw - 1 do
            Array.iter
              (fun v ->
                (if depth = 16 then Bytes.set_uint16_be row (!bit / 8) v
                 else if depth = 8 then Bytes.set_uint8 row (!bit / 8) v
                 else
                   let k = !bit / 8 in
                   Bytes.set_uint8 row k
                     (Bytes.get_uint8 row k lor (v lsl (8 - depth - (!bit mod 8)))));
                bit := !bit + depth)
              values.(y0 + (y * dy)).(x0 + (x * dx))
          done;
          (* Every filter in turn, row after row. *)
          let ft = !row_no mod 5 in
          incr row_no;
          Buffer.add_char raw (Char.chr ft);
          for k = 0 to stride - 1 do
            let x = Bytes.get_uint8 row k and b = Bytes.get_uint8 !prev k in
            let a = if k >= bpp then Bytes.get_uint8 row (k - bpp) else 0 in
            let c = if k >= bpp then Bytes.get_uint8 !prev (k - bpp) else 0 in
            let pr =
              let p = a + b - c in
              let pa = abs (p - a) and pb = abs (p - b) and pc = abs (p - c) in
              if pa <= pb && pa <= pc then a else if pb <= pc then b else c
            in
            let f =
              match ft with 0 -> 0 | 1 -> a | 2 -> b | 3 -> (a + b) / 2 | _ -> pr
            in
            Buffer.add_char raw (Char.chr ((x - f) land 255))
          done;
          prev := row
        done)
    passes;
  let ihdr =
    be32 w ^ be32 h
    ^ String.init 5 (fun k ->
          Char.chr [| depth; ctype; 0; 0; (if interlaced then 1 else 0) |].(k))
  in
  "\137PNG\r\n\026\n" ^ chunk "IHDR" ihdr ^ extra
  ^ chunk "tEXt" "Comment\000made by the test"
  ^ chunk "IDAT" (deflate (Buffer.contents raw))
  ^ chunk "IEND" ""

let decode_ok msg s =
  match Png.decode s with Ok r -> r | Error m -> Alcotest.failf "%s: %s" msg m

let grid w h f = Array.init h (fun j -> Array.init w (fun i -> f i j))

let reader_tests =
  let w = 13 and h = 11 in
  List.concat_map
    (fun interlaced ->
      let il = if interlaced then "interlaced" else "plain" in
      List.map
        (fun (ctype, depth, name) ->
          Alcotest.test_case
            (Printf.sprintf "a %s %d-bit %s PNG reads as written" il depth name) `Quick
            (fun () ->
              let channels = match ctype with 0 | 3 -> 1 | 2 -> 3 | 4 -> 2 | _ -> 4 in
              let maxv = (1 lsl depth) - 1 in
              let values =
                grid w h (fun i j ->
                    Array.init channels (fun c ->
                        ((i * 7) + (j * 13) + (c * 5) + (i * j))
                        * 2654435761 mod (maxv + 1)))
              in
              let palette =
                String.init (3 * (maxv + 1)) (fun k -> Char.chr (k * 11 land 255))
              in
              let extra = if ctype = 3 then chunk "PLTE" palette else "" in
              let r =
                decode_ok name (png_of ~ctype ~depth ~interlaced ~extra w h values)
              in
              Alcotest.(check (pair int int)) "size" (w, h) (r.width, r.height);
              for j = 0 to h - 1 do
                for i = 0 to w - 1 do
                  let v = values.(j).(i) in
                  let expect =
                    if ctype = 3 then
                      Array.init 3 (fun c -> Char.code palette.[(3 * v.(0)) + c])
                    else if depth < 8 then [| v.(0) * 255 / maxv |]
                    else v
                  in
                  Alcotest.(check (array int))
                    (Printf.sprintf "pixel %d,%d" i j)
                    expect
                    (Array.init r.channels (Raster.get r i j))
                done
              done))
        [
          (0, 1, "gray");
          (0, 2, "gray");
          (0, 4, "gray");
          (0, 8, "gray");
          (0, 16, "gray");
          (4, 8, "gray+alpha");
          (4, 16, "gray+alpha");
          (2, 8, "RGB");
          (2, 16, "RGB");
          (6, 8, "RGBA");
          (6, 16, "RGBA");
          (3, 1, "palette");
          (3, 4, "palette");
          (3, 8, "palette");
        ])
    [ false; true ]
  @ [
      Alcotest.test_case "a palette PNG with a transparency chunk reads as RGBA" `Quick
        (fun () ->
          let values = grid 3 2 (fun i j -> [| (i + j) mod 3 |]) in
          let extra =
            chunk "PLTE" "\255\000\000\000\255\000\000\000\255" ^ chunk "tRNS" "\000\128"
          in
          let r =
            decode_ok "tRNS"
              (png_of ~ctype:3 ~depth:8 ~interlaced:false ~extra 3 2 values)
          in
          Alcotest.(check int) "4 channels" 4 r.channels;
          Alcotest.(check (array int))
            "pixel 0,0" [| 255; 0; 0; 0 |]
            (Array.init 4 (Raster.get r 0 0));
          Alcotest.(check (array int))
            "pixel 1,0" [| 0; 255; 0; 128 |]
            (Array.init 4 (Raster.get r 1 0));
          Alcotest.(check (array int))
            "pixel 2,0: opaque" [| 0; 0; 255; 255 |]
            (Array.init 4 (Raster.get r 2 0)));
      Alcotest.test_case
        "the goldens written by the former (interlaced, libpng) writer still read" `Quick
        (fun () ->
          let dir = "../golden" in
          (* Those the former writer made are interlaced; goldens added since are
             lancer's own. *)
          let pngs =
            List.filter_map
              (fun f ->
                if not (Filename.check_suffix f ".png") then None
                else
                  let s = read_file (Filename.concat dir f) in
                  if Char.code s.[28] = 1 then Some (f, s) else None)
              (Array.to_list (Sys.readdir dir))
          in
          Alcotest.(check bool) "some goldens" true (List.length pngs > 5);
          List.iter
            (fun (f, s) ->
              let r = decode_ok f s in
              (* Re-encoded plainly, it decodes to the same samples. *)
              check_raster f r (decode_ok (f ^ " re-encoded") (encode r)))
            pngs);
    ]

let writer_tests =
  [
    Alcotest.test_case "every colour type at 8 and 16 bits round-trips through the writer"
      `Quick (fun () ->
        List.iter
          (fun (channels, depth) ->
            let r = sample_raster ~width:37 ~height:23 ~channels ~depth in
            let s = encode r in
            Alcotest.(check int) "not interlaced" 0 (Char.code s.[28]);
            check_raster
              (Printf.sprintf "%d channels, %d bits" channels depth)
              r (decode_ok "round trip" s))
          [ (1, 8); (1, 16); (2, 8); (2, 16); (3, 8); (3, 16); (4, 8); (4, 16) ]);
    Alcotest.test_case
      "a one-pixel image and an image wider than deflate's buffer round-trip" `Quick
      (fun () ->
        List.iter
          (fun (w, h) ->
            let r = sample_raster ~width:w ~height:h ~channels:3 ~depth:16 in
            check_raster (Printf.sprintf "%d×%d" w h) r
              (decode_ok "round trip" (encode r)))
          [ (1, 1); (12000, 2); (3, 400) ]);
  ]

let corrupt_tests =
  let good = encode (sample_raster ~width:20 ~height:10 ~channels:3 ~depth:8) in
  let refused name s expect =
    Alcotest.test_case ("refused with a plain message: " ^ name) `Quick (fun () ->
        match Png.decode s with
        | Ok _ -> Alcotest.fail "decoded"
        | Error m ->
            let contains s sub =
              let n = String.length s and k = String.length sub in
              let rec go i = i + k <= n && (String.sub s i k = sub || go (i + 1)) in
              go 0
            in
            Alcotest.(check bool)
              (Printf.sprintf "%S mentions %S" m expect)
              true (contains m expect))
  in
  let flip s k =
    String.mapi (fun i c -> if i = k then Char.chr (Char.code c lxor 0x40) else c) s
  in
  let idat_at =
    let rec find i = if String.sub good i 4 = "IDAT" then i else find (i + 1) in
    find 8
  in
  [
    refused "an empty file" "" "not a PNG file";
    refused "a text file" "hello, world\n" "not a PNG file";
    refused "a truncated file" (String.sub good 0 (String.length good - 20)) "truncated";
    refused "a file cut inside its header" (String.sub good 0 20) "truncated";
    refused "a flipped bit in the image data"
      (flip good (idat_at + 10))
      "bad checksum in chunk IDAT";
    refused "a flipped bit in the header" (flip good 18) "bad checksum in chunk IHDR";
    refused "data that does not inflate"
      ("\137PNG\r\n\026\n"
      ^ chunk "IHDR" (be32 2 ^ be32 2 ^ "\008\002\000\000\000")
      ^ chunk "IDAT" "not zlib at all"
      ^ chunk "IEND" "")
      "corrupt PNG image data";
    refused "too little image data"
      ("\137PNG\r\n\026\n"
      ^ chunk "IHDR" (be32 4 ^ be32 4 ^ "\008\002\000\000\000")
      ^ chunk "IDAT" (deflate "\000\001\002")
      ^ chunk "IEND" "")
      "truncated PNG image data";
    refused "a bad filter type"
      ("\137PNG\r\n\026\n"
      ^ chunk "IHDR" (be32 1 ^ be32 1 ^ "\008\000\000\000\000")
      ^ chunk "IDAT" (deflate "\009\000")
      ^ chunk "IEND" "")
      "filter type 9";
    refused "an unknown colour type"
      ("\137PNG\r\n\026\n" ^ chunk "IHDR" (be32 1 ^ be32 1 ^ "\008\005\000\000\000"))
      "colour type 5";
    refused "a bit depth the colour type cannot have"
      ("\137PNG\r\n\026\n" ^ chunk "IHDR" (be32 1 ^ be32 1 ^ "\004\002\000\000\000"))
      "cannot have 4 bits";
    refused "an unknown interlace method"
      ("\137PNG\r\n\026\n" ^ chunk "IHDR" (be32 1 ^ be32 1 ^ "\008\002\000\000\002"))
      "interlace method 2";
    refused "a huge size before any allocation"
      ("\137PNG\r\n\026\n"
      ^ chunk "IHDR" (be32 100000 ^ be32 100000 ^ "\008\002\000\000\000"))
      "larger than the limit";
    refused "an unknown critical chunk"
      ("\137PNG\r\n\026\n"
      ^ chunk "IHDR" (be32 1 ^ be32 1 ^ "\008\000\000\000\000")
      ^ chunk "ABCD" "" ^ chunk "IEND" "")
      "unsupported critical PNG chunk ABCD";
    refused "a palette image without a palette"
      ("\137PNG\r\n\026\n"
      ^ chunk "IHDR" (be32 1 ^ be32 1 ^ "\008\003\000\000\000")
      ^ chunk "IDAT" (deflate "\000\000")
      ^ chunk "IEND" "")
      "without a PLTE chunk";
  ]

let texture_tests =
  [
    Alcotest.test_case
      "a pipe or a device named like an image is refused at once, not read" `Quick
      (fun () ->
        let d = tmpdir () in
        Unix.mkfifo (Filename.concat d "fifo.png") 0o644;
        List.iter
          (fun p ->
            match Image.read_raster p with
            | Ok _ -> Alcotest.fail "read"
            | Error m ->
                Alcotest.(check bool)
                  m true
                  (String.length m > 0
                  && String.sub m 0 (String.length p) = p
                  && String.ends_with
                       ~suffix:"not a regular file (a device or a pipe), not an image" m))
          [ Filename.concat d "fifo.png" ]);
    Alcotest.test_case
      "an 8- and a 16-bit gray PNG read as linear textures with their full precision"
      `Quick (fun () ->
        let d = tmpdir () in
        let srgb v =
          if v <= 0.04045 then v /. 12.92 else Float.pow ((v +. 0.055) /. 1.055) 2.4
        in
        List.iter
          (fun depth ->
            let maxv = (1 lsl depth) - 1 in
            (* Two neighbouring 16-bit values that 8 bits cannot tell apart. *)
            let vs = [| 0; maxv / 3; (maxv / 3) + 1; maxv |] in
            let p = Filename.concat d (Printf.sprintf "h%d.png" depth) in
            write_file p
              (png_of ~ctype:0 ~depth ~interlaced:false 4 1
                 (grid 4 1 (fun i _ -> [| vs.(i) |])));
            match Image.read_linear p with
            | Error m -> Alcotest.fail m
            | Ok fb ->
                Array.iteri
                  (fun i v ->
                    let c = Framebuffer.get fb i 0 in
                    let e = srgb (Float.of_int v /. Float.of_int maxv) in
                    Alcotest.(check (float 1e-12))
                      (Printf.sprintf "%d-bit gray %d" depth v)
                      e c.r;
                    Alcotest.(check bool)
                      "gray in all three channels" true
                      (Float.equal c.r c.g && Float.equal c.g c.b))
                  vs;
                if depth = 16 then
                  Alcotest.(check bool)
                    "16 bits kept" true
                    ((Framebuffer.get fb 1 0).r < (Framebuffer.get fb 2 0).r))
          [ 8; 16 ]);
  ]

let sixteen_tests =
  [
    Alcotest.test_case "16-bit encoding: the same curve, quantised to 65535" `Quick
      (fun () ->
        let e = Image.encode_channel16 Settings.Srgb in
        List.iter
          (fun (v, expect) ->
            Alcotest.(check int) (Printf.sprintf "sRGB %g" v) expect (e v))
          [
            (0., 0);
            (1., 65535);
            (0.5, 48192);
            (0.25, 35199);
            (0.001, 847);
            (0.2, 31754);
            (-1., 0);
            (2., 65535);
            (Float.nan, 0);
          ];
        Alcotest.(check int)
          "gamma 2.2 at 0.5" 47824
          (Image.encode_channel16 (Settings.Power 2.2) 0.5));
    Alcotest.test_case "a 16-bit RGBA image written and read back is what was encoded"
      `Quick (fun () ->
        let d = tmpdir () in
        let fb = Framebuffer.create 9 7 in
        let alpha = Float.Array.init (9 * 7) (fun k -> Float.of_int k /. 62.) in
        for j = 0 to 6 do
          for i = 0 to 8 do
            Framebuffer.set fb i j
              (Color.v
                 (Float.of_int i /. 8.)
                 (Float.of_int j /. 6.)
                 (Float.of_int (i * j) /. 48.))
          done
        done;
        List.iter
          (fun (bits, alpha, ext) ->
            let p = Filename.concat d ("x" ^ ext) in
            let expect = Image.encode ~bits ?alpha fb in
            (match Image.save ~bits ?alpha p fb with
            | Ok () -> ()
            | Error m -> Alcotest.fail m);
            match Image.read_raster p with
            | Error m -> Alcotest.fail m
            | Ok r ->
                check_raster
                  (Printf.sprintf "%d bits%s %s" bits
                     (if alpha = None then "" else " + alpha")
                     ext)
                  expect r;
                Alcotest.(check int) "top-left red" 0 (Raster.get r 0 0 0);
                Alcotest.(check int) "right red" (Raster.max_value r) (Raster.get r 8 0 0);
                if alpha <> None then
                  Alcotest.(check int)
                    "last alpha" (Raster.max_value r) (Raster.get r 8 6 3))
          [
            (16, None, ".png");
            (16, Some alpha, ".png");
            (16, None, ".ppm");
            (8, Some alpha, ".png");
          ];
        let r = Image.encode ~bits:16 fb in
        Alcotest.(check int)
          "a 16-bit sample is big-endian, as PNG and PPM store it"
          (Image.encode_channel16 Settings.Srgb 0.5)
          (Bytes.get_uint16_be r.samples (2 * (((0 * 9) + 4) * 3))));
    Alcotest.test_case "a crop takes exactly the region's pixels" `Quick (fun () ->
        let fb = Framebuffer.create 9 7 in
        for j = 0 to 6 do
          for i = 0 to 8 do
            Framebuffer.set fb i j
              (Color.v (Float.of_int i /. 8.) (Float.of_int j /. 6.) 0.)
          done
        done;
        let whole = Image.encode fb
        and part = Image.encode ~crop:{ x0 = 2; y0 = 3; x1 = 7; y1 = 5 } fb in
        Alcotest.(check (pair int int)) "5×2" (5, 2) (part.width, part.height);
        for j = 0 to 1 do
          for i = 0 to 4 do
            for c = 0 to 2 do
              Alcotest.(check int)
                "same sample"
                (Raster.get whole (i + 2) (j + 3) c)
                (Raster.get part i j c)
            done
          done
        done);
  ]

(* The byte doc/reference/shading.md gives for a linear value, written out here as the
   reference. *)
let srgb_byte v =
  let v = if Float.is_nan v then 0. else Float.min 1. (Float.max 0. v) in
  let e =
    if v <= 0.0031308 then 12.92 *. v else (1.055 *. Float.pow v (1. /. 2.4)) -. 0.055
  in
  int_of_float (Float.floor ((255. *. e) +. 0.5))

(* The linear value where the sRGB byte becomes k, near enough for a start. *)
let srgb_step k =
  let c = (Float.of_int k -. 0.5) /. 255. in
  if c <= 0.04045 then c /. 12.92 else Float.pow ((c +. 0.055) /. 1.055) 2.4

(* The filter type the PNG specification's heuristic picks for each row: the least sum of
   the filtered bytes read as signed, the first on a tie. *)
let cheapest_filters (r : Raster.t) =
  let bpp = r.channels * (r.depth / 8) in
  let stride = r.width * bpp in
  let get j k =
    if j < 0 || k < 0 then 0 else Bytes.get_uint8 r.samples ((j * stride) + k)
  in
  let paeth a b c =
    let p = a + b - c in
    let pa = abs (p - a) and pb = abs (p - b) and pc = abs (p - c) in
    if pa <= pb && pa <= pc then a else if pb <= pc then b else c
  in
  List.init r.height (fun j ->
      let sum ft =
        let s = ref 0 in
        for k = 0 to stride - 1 do
          let x = get j k and a = get j (k - bpp) and b = get (j - 1) k in
          let c = get (j - 1) (k - bpp) in
          let p =
            match ft with 0 -> 0 | 1 -> a | 2 -> b | 3 -> (a + b) / 2 | _ -> paeth a b c
          in
          let v = (x - p) land 255 in
          s := !s + min v (256 - v)
        done;
        !s
      in
      let best = ref 0 in
      for ft = 1 to 4 do
        if sum ft < sum !best then best := ft
      done;
      !best)

(* The inflated image data of a PNG file: each row's filter byte, then the row filtered
   (one IDAT stream, no interlace). *)
let filtered png (r : Raster.t) =
  let idat = Buffer.create 1024 in
  let rec chunks pos =
    if pos + 8 <= String.length png then (
      let len = Int32.to_int (String.get_int32_be png pos) in
      if String.sub png (pos + 4) 4 = "IDAT" then
        Buffer.add_string idat (String.sub png (pos + 8) len);
      chunks (pos + 12 + len))
  in
  chunks 8;
  let stride = r.width * r.channels * (r.depth / 8) in
  let raw = Buffer.create (r.height * (stride + 1)) in
  let data = Buffer.contents idat and pos = ref 0 in
  Zlib.uncompress
    (fun buf ->
      let n = min (Bytes.length buf) (String.length data - !pos) in
      Bytes.blit_string data !pos buf 0 n;
      pos := !pos + n;
      n)
    (fun buf n -> Buffer.add_subbytes raw buf 0 n);
  Buffer.contents raw

let filter_bytes png (r : Raster.t) =
  let stride = r.width * r.channels * (r.depth / 8) in
  let raw = filtered png r in
  List.init r.height (fun j -> Char.code raw.[j * (stride + 1)])

(* The filtered rows of [r] (each its filter byte first) as {!Png_reference} makes them. *)
let reference_filtered (r : Raster.t) =
  let bpp = r.channels * (r.depth / 8) in
  let stride = r.width * bpp in
  let out = Bytes.create (r.height * (stride + 1)) in
  let line = Bytes.create (stride + 1) in
  let prev = ref (Bytes.make stride '\000') in
  for j = 0 to r.height - 1 do
    let row = Bytes.sub r.samples (j * stride) stride in
    Png_reference.filter_row ~bpp row !prev line;
    Bytes.blit line 0 out (j * (stride + 1)) (stride + 1);
    prev := row
  done;
  Bytes.to_string out

(* Rasters whose rows make every filter win somewhere, with ties and wrap-around:
   noise, smooth gradients with a little noise, flat areas, 0 and 255 side by side, and
   rows that repeat the row above. *)
let varied_raster st ~width ~height ~channels ~depth =
  let n = width * height * channels * (depth / 8) in
  let stride = width * channels * (depth / 8) in
  let b = Bytes.create n in
  for j = 0 to height - 1 do
    let kind = Random.State.int st 6 in
    let base = Random.State.int st 256 in
    for k = 0 to stride - 1 do
      let v =
        match kind with
        | 0 -> Random.State.int st 256
        | 1 -> base + (k / 3) + j + Random.State.int st 3
        | 2 -> base
        | 3 -> if Random.State.bool st then 0 else 255
        | 4 when j > 0 -> Bytes.get_uint8 b (((j - 1) * stride) + k)
        | _ -> (k * k * 7) + (j * 13) + if Random.State.int st 8 = 0 then 128 else 0
      in
      Bytes.set_uint8 b ((j * stride) + k) (v land 255)
    done
  done;
  Raster.make ~width ~height ~channels ~depth b

let encoder_tests =
  [
    Alcotest.test_case
      "the 8-bit sRGB byte is the formula's at every step, beside it and across [0, 1]"
      `Quick (fun () ->
        let bad = ref [] in
        let try_ v =
          let got = Image.encode_channel Settings.Srgb v and want = srgb_byte v in
          if got <> want && List.length !bad < 5 then bad := (v, got, want) :: !bad
        in
        for k = 1 to 255 do
          (* 200 floats either side of each step, then wider offsets *)
          let v = ref (srgb_step k) in
          for _ = 1 to 200 do
            v := Float.pred !v
          done;
          for _ = 1 to 400 do
            try_ !v;
            v := Float.succ !v
          done;
          List.iter
            (fun d ->
              try_ (srgb_step k +. d);
              try_ (srgb_step k -. d))
            [ 1e-12; 1e-10; 1e-9; 1.5e-9; 1e-8; 1e-6; 1e-4 ]
        done;
        for i = 0 to 2_000_000 do
          try_ (Float.of_int i /. 2_000_000.)
        done;
        (* every bin's start and the floats around it *)
        for b = 0 to 4096 do
          let s = Float.of_int b /. 4096. in
          List.iter try_ [ Float.pred s; s; Float.succ s ]
        done;
        List.iter try_
          [
            0.;
            -0.;
            -1.;
            1.;
            2.;
            Float.nan;
            Float.infinity;
            Float.neg_infinity;
            Float.min_float;
            0.0031308;
            Float.pred 0.0031308;
            Float.succ 0.0031308;
            Float.pred 1.;
            1e-300;
          ];
        match !bad with
        | [] -> ()
        | l ->
            Alcotest.failf "%s"
              (String.concat "; "
                 (List.map
                    (fun (v, g, w) -> Printf.sprintf "%h (%.17g): %d, not %d" v v g w)
                    l)));
    Alcotest.test_case "an encoded framebuffer is encode_channel of each value" `Quick
      (fun () ->
        let fb = Framebuffer.create 37 11 in
        Float.Array.iteri
          (fun k _ ->
            Float.Array.set fb.data k
              (if k mod 13 = 0 then Float.nan
               else if k mod 11 = 0 then 1.5
               else Float.of_int (k * 7919 mod 1000) /. 999.))
          fb.data;
        List.iter
          (fun gamma ->
            let want =
              Bytes.init (Float.Array.length fb.data) (fun k ->
                  Char.chr (Image.encode_channel gamma (Float.Array.get fb.data k)))
            in
            Alcotest.(check bool)
              "to_bytes" true
              (Bytes.equal want (Image.to_bytes gamma fb));
            Alcotest.(check bool)
              "encode" true
              (Bytes.equal want (Image.encode ~gamma fb).samples))
          [ Settings.Srgb; Settings.Power 2.2 ];
        Alcotest.(check int)
          "a byte of 0.5 under gamma 2.2" 186
          (Image.encode_channel (Settings.Power 2.2) 0.5));
    Alcotest.test_case "each row of a written PNG has the cheapest filter, first on a tie"
      `Quick (fun () ->
        List.iter
          (fun (channels, depth, w, h) ->
            let r = sample_raster ~width:w ~height:h ~channels ~depth in
            (* and a gradient, where the filters that predict win *)
            let g =
              Raster.make ~width:w ~height:h ~channels ~depth:8
                (Bytes.init (w * h * channels) (fun k -> Char.chr (k / channels mod w)))
            in
            List.iter
              (fun (what, r) ->
                Alcotest.(check (list int))
                  (Printf.sprintf "%s, %d channels, %d bits" what channels depth)
                  (cheapest_filters r)
                  (filter_bytes (encode r) r))
              [ ("noise", r); ("gradient", g) ])
          [ (3, 8, 31, 9); (4, 8, 17, 5); (1, 8, 40, 6); (3, 16, 13, 7); (2, 16, 9, 4) ]);
    Alcotest.test_case
      "the written rows are the plain filter's, byte for byte, at every size and layout"
      `Quick (fun () ->
        let st = Random.State.make [| 2026 |] in
        let check (channels, depth, width, height) =
          let r = varied_raster st ~width ~height ~channels ~depth in
          let want = reference_filtered r and got = filtered (encode r) r in
          if not (String.equal want got) then
            Alcotest.failf "%d×%d, %d channels, %d bits: the filtered rows differ" width
              height channels depth
        in
        List.iter
          (fun channels ->
            List.iter
              (fun depth ->
                (* every width up to a few words past the first pixel, then wide rows *)
                for width = 1 to 24 do
                  check (channels, depth, width, 1 + Random.State.int st 6)
                done;
                List.iter
                  (fun width -> check (channels, depth, width, 4))
                  [ 97; 255; 480; 1921 ])
              [ 8; 16 ])
          [ 1; 2; 3; 4 ]);
  ]

let () =
  Alcotest.run "io"
    [
      ("reader", reader_tests);
      ("writer", writer_tests);
      ("corrupt", corrupt_tests);
      ("textures", texture_tests);
      ("16 bits, alpha, crop", sixteen_tests);
      ("encoder", encoder_tests);
    ]
