exception Bad of string

(* [body ()], then [release ()] also when [body] raises. Unlike Fun.protect, an exception
   from [release] (an interrupt arriving just then) never hides [body]'s own. *)
let finally release body =
  match body () with
  | r ->
      release ();
      r
  | exception e ->
      (try release () with _ -> ());
      raise e

let bad fmt = Printf.ksprintf (fun s -> raise (Bad s)) fmt
let signature = "\137PNG\r\n\026\n"

(* ---- writing ---- *)

let be32 n =
  let b = Bytes.create 4 in
  Bytes.set_int32_be b 0 (Int32.of_int n);
  Bytes.unsafe_to_string b

let crc_of kind data len =
  let c = Zlib.update_crc_string 0l kind 0 4 in
  Zlib.update_crc_string c data 0 len

let chunk write kind data len =
  write (be32 len);
  write kind;
  write (if len = String.length data then data else String.sub data 0 len);
  let crc = Bytes.create 4 in
  Bytes.set_int32_be crc 0 (crc_of kind data len);
  write (Bytes.unsafe_to_string crc)

(* [abs d] without a branch: d's sign spread over the word flips and corrects it. *)
let[@inline] iabs d =
  let m = d asr 62 in
  (d lxor m) - m

(* The Paeth predictor of a byte from its left [a], upper [b] and upper-left [c]
   neighbours: the one nearest a + b - c, a first on a tie, then b. The distances are
   |b - c|, |a - c| and |a + b - 2c|; the choice is made with masks from the signs of
   their differences, not with branches, which the neighbours of a noisy row would
   mispredict half the time. *)
let[@inline] paeth a b c =
  let pa = iabs (b - c) and pb = iabs (a - c) and pc = iabs (a + b - c - c) in
  (* b where pb <= pc, else c *)
  let bc = c lxor (b lxor c land lnot ((pc - pb) asr 62)) in
  (* a where pa <= pb and pa <= pc *)
  bc lxor (a lxor bc land lnot (((pb - pa) lor (pc - pa)) asr 62))

(* The cost of a filtered byte: the absolute value of the byte read as signed, from a
   table (a branch on random bytes is mispredicted half the time). *)
let costs = String.init 256 (fun v -> Char.chr (if v < 128 then v else 256 - v))
let[@inline] cost v = Char.code (String.unsafe_get costs v)
let[@inline] get b k = Char.code (Bytes.unsafe_get b k)
let[@inline] put out k v = Bytes.unsafe_set out (k + 1) (Char.unsafe_chr (v land 255))

external get64 : bytes -> int -> int64 = "%caml_bytes_get64u"
external set64 : bytes -> int -> int64 -> unit = "%caml_bytes_set64u"

(* Eight bytes of a row at once, in an unboxed int64 (SIMD within a register): the
   filters, their costs and the Paeth predictor computed byte by byte, without a carry
   from one byte into the next. The byte order of the loads does not matter: every
   operation is the same on each byte, and a word is stored back the way it was read. *)
module Wide = struct
  let ( + ) = Int64.add
  let ( - ) = Int64.sub
  let ( * ) = Int64.mul
  let ( land ) = Int64.logand
  let ( lor ) = Int64.logor
  let ( lxor ) = Int64.logxor
  let ( lsr ) = Int64.shift_right_logical
  let ( lsl ) = Int64.shift_left
  let high = 0x8080808080808080L
  let low7 = 0x7F7F7F7F7F7F7F7FL
  let ones = 0x0101010101010101L
  let even = 0x00FF00FF00FF00FFL
  let ones16 = 0x0001000100010001L

  (* x - y in each byte, modulo 256: the high bits are taken apart so that no byte
     borrows from the next, then put back. *)
  let[@inline] sub x y =
    ((x lor high) - (y land low7)) lxor (x lxor Int64.lognot y land high)

  (* (a + b) / 2 in each byte, rounded down, without the ninth bit. *)
  let[@inline] avg a b = (a land b) + ((a lxor b land 0xFEFEFEFEFEFEFEFEL) lsr 1)

  (* The sum of the eight bytes' costs: each negative byte v becomes -v = (v xor 255) + 1
     (at most 128, no carry), pairs are added into 16-bit lanes, then the four lanes into
     the top one by a multiplication. *)
  let[@inline] cost v =
    let neg = (v lsr 7) land ones in
    let s = (v lxor ((neg lsl 8) - neg)) + neg in
    let s = (s land even) + ((s lsr 8) land even) in
    Int64.to_int ((s * ones16) lsr 48)

  (* 1 in each 16-bit lane where p <= q (both below 1024): bit 10 of 1024 + q - p. *)
  let[@inline] le p q = (((q lor 0x0400040004000400L) - p) lsr 10) land ones16

  (* The Paeth predictor of four bytes held in 16-bit lanes. A difference d is taken
     biased by 2^s (its sign is then bit s), |d| is its low s bits, complemented and
     plus one where d < 0. *)
  let[@inline] paeth4 a b c =
    let d = (b lor 0x0100010001000100L) - c in
    let n = (d lsr 8) land ones16 lxor ones16 in
    let pa = (d lxor ((n lsl 8) - n) land even) + n in
    let d = (a lor 0x0100010001000100L) - c in
    let n = (d lsr 8) land ones16 lxor ones16 in
    let pb = (d lxor ((n lsl 8) - n) land even) + n in
    let d = a + b + 0x0200020002000200L - (c + c) in
    let n = (d lsr 9) land ones16 lxor ones16 in
    let pc = (d lxor ((n lsl 9) - n) land 0x01FF01FF01FF01FFL) + n in
    let pick_a = le pa pb land le pa pc and pick_b = le pb pc in
    let bc = c lxor (b lxor c land ((pick_b lsl 8) - pick_b)) in
    bc lxor (a lxor bc land ((pick_a lsl 8) - pick_a))

  let[@inline] paeth a b c =
    paeth4 (a land even) (b land even) (c land even)
    lor (paeth4 ((a lsr 8) land even) ((b lsr 8) land even) ((c lsr 8) land even) lsl 8)
end

(* [row] filtered with the filter that minimises the sum of absolute (signed) values, the
   first of the cheapest on a tie, into [out] (filter byte first). [prev] is the row above
   (zeros for the first). The five sums are taken in one pass over the row, then the row is
   filtered once with the winner. The first [bpp] bytes have no left neighbour (a = c = 0,
   where Sub is None and Paeth is Up); the rest go eight at a time, and the bytes after
   the last whole eight one at a time. *)
let filter_row ~bpp row prev out =
  let n = Bytes.length row in
  let head = if bpp < n then bpp else n in
  let c0 = ref 0 and c2 = ref 0 and c3 = ref 0 in
  for k = 0 to head - 1 do
    let x = get row k and b = get prev k in
    c0 := !c0 + cost x;
    c2 := !c2 + cost ((x - b) land 255);
    c3 := !c3 + cost ((x - (b lsr 1)) land 255)
  done;
  let c1 = ref !c0 and c4 = ref !c2 in
  let k = ref bpp in
  while !k + 8 <= n do
    let i = !k in
    let x = get64 row i and b = get64 prev i in
    let a = get64 row (i - bpp) and c = get64 prev (i - bpp) in
    c0 := !c0 + Wide.cost x;
    c1 := !c1 + Wide.cost (Wide.sub x a);
    c2 := !c2 + Wide.cost (Wide.sub x b);
    c3 := !c3 + Wide.cost (Wide.sub x (Wide.avg a b));
    c4 := !c4 + Wide.cost (Wide.sub x (Wide.paeth a b c));
    k := i + 8
  done;
  for k = !k to n - 1 do
    let x = get row k and b = get prev k in
    let a = get row (k - bpp) and c = get prev (k - bpp) in
    c0 := !c0 + cost x;
    c1 := !c1 + cost ((x - a) land 255);
    c2 := !c2 + cost ((x - b) land 255);
    c3 := !c3 + cost ((x - ((a + b) lsr 1)) land 255);
    c4 := !c4 + cost ((x - paeth a b c) land 255)
  done;
  let ft = ref 0 and best = ref !c0 in
  let consider t c =
    if c < !best then (
      ft := t;
      best := c)
  in
  consider 1 !c1;
  consider 2 !c2;
  consider 3 !c3;
  consider 4 !c4;
  let ft = !ft in
  Bytes.set_uint8 out 0 ft;
  (* One loop per filter type: the type is the same along the row. *)
  match ft with
  | 0 -> Bytes.blit row 0 out 1 n
  | 2 ->
      let k = ref 0 in
      while !k + 8 <= n do
        let i = !k in
        set64 out (i + 1) (Wide.sub (get64 row i) (get64 prev i));
        k := i + 8
      done;
      for k = !k to n - 1 do
        put out k (get row k - get prev k)
      done
  | 1 ->
      Bytes.blit row 0 out 1 head;
      let k = ref bpp in
      while !k + 8 <= n do
        let i = !k in
        set64 out (i + 1) (Wide.sub (get64 row i) (get64 row (i - bpp)));
        k := i + 8
      done;
      for k = !k to n - 1 do
        put out k (get row k - get row (k - bpp))
      done
  | 3 ->
      for k = 0 to head - 1 do
        put out k (get row k - (get prev k lsr 1))
      done;
      let k = ref bpp in
      while !k + 8 <= n do
        let i = !k in
        set64 out (i + 1)
          (Wide.sub (get64 row i) (Wide.avg (get64 row (i - bpp)) (get64 prev i)));
        k := i + 8
      done;
      for k = !k to n - 1 do
        put out k (get row k - ((get row (k - bpp) + get prev k) lsr 1))
      done
  | _ ->
      for k = 0 to head - 1 do
        put out k (get row k - get prev k)
      done;
      let k = ref bpp in
      while !k + 8 <= n do
        let i = !k in
        set64 out (i + 1)
          (Wide.sub (get64 row i)
             (Wide.paeth (get64 row (i - bpp)) (get64 prev i) (get64 prev (i - bpp))));
        k := i + 8
      done;
      for k = !k to n - 1 do
        put out k (get row k - paeth (get row (k - bpp)) (get prev k) (get prev (k - bpp)))
      done

let colour_type channels = match channels with 1 -> 0 | 2 -> 4 | 3 -> 2 | _ -> 6

(* An international text chunk, uncompressed, with no language tag: the keyword (Latin-1,
   1 to 79 bytes, no NUL) and UTF-8 text. *)
let itxt keyword text =
  let n = String.length keyword in
  if n < 1 || n > 79 || String.contains keyword '\000' then
    invalid_arg "Png.encode: a text keyword of 1 to 79 bytes without NUL";
  keyword ^ "\000\000\000\000\000" ^ text

let encode ?(level = 6) ?(text = []) (r : Raster.t) write =
  let bpp = r.channels * (r.depth / 8) in
  let stride = r.width * bpp in
  write signature;
  let ihdr = Bytes.create 13 in
  Bytes.set_int32_be ihdr 0 (Int32.of_int r.width);
  Bytes.set_int32_be ihdr 4 (Int32.of_int r.height);
  Bytes.set_uint8 ihdr 8 r.depth;
  Bytes.set_uint8 ihdr 9 (colour_type r.channels);
  Bytes.set_uint8 ihdr 10 0;
  Bytes.set_uint8 ihdr 11 0;
  Bytes.set_uint8 ihdr 12 0;
  chunk write "IHDR" (Bytes.to_string ihdr) 13;
  List.iter
    (fun (k, v) ->
      let d = itxt k v in
      chunk write "iTXt" d (String.length d))
    text;
  (* Rows are filtered one at a time and streamed through deflate; each time its output
     buffer is full it becomes one IDAT chunk. *)
  let z = Zlib.deflate_init level true in
  finally (fun () -> Zlib.deflate_end z) @@ fun () ->
  let out = Bytes.create 65536 in
  let emit n = if n > 0 then chunk write "IDAT" (Bytes.sub_string out 0 n) n in
  let filled = ref 0 in
  let rec feed src pos len flush =
    let finished, used_in, used_out =
      Zlib.deflate z src pos len out !filled (Bytes.length out - !filled) flush
    in
    filled := !filled + used_out;
    if !filled = Bytes.length out then (
      emit !filled;
      filled := 0);
    let pos = pos + used_in and len = len - used_in in
    match flush with
    | Zlib.Z_FINISH -> if not finished then feed src pos len flush
    | _ -> if len > 0 then feed src pos len flush
  in
  let row = ref (Bytes.create stride)
  and prev = ref (Bytes.make stride '\000')
  and line = Bytes.create (stride + 1) in
  for j = 0 to r.height - 1 do
    Bytes.blit r.samples (j * stride) !row 0 stride;
    filter_row ~bpp !row !prev line;
    feed line 0 (stride + 1) Zlib.Z_NO_FLUSH;
    let t = !prev in
    prev := !row;
    row := t
  done;
  feed line 0 0 Zlib.Z_FINISH;
  emit !filled;
  chunk write "IEND" "" 0

(* ---- reading ---- *)

type header = { w : int; h : int; depth : int; ctype : int; interlaced : bool }

let channels_of_type = function 0 -> 1 | 2 -> 3 | 3 -> 1 | 4 -> 2 | 6 -> 4 | _ -> 0

let type_name = function
  | 0 -> "gray"
  | 2 -> "RGB"
  | 3 -> "palette"
  | 4 -> "gray+alpha"
  | 6 -> "RGBA"
  | t -> Printf.sprintf "colour type %d" t

let parse_header max_pixels d =
  if String.length d <> 13 then
    bad "its IHDR chunk has %d bytes, not 13" (String.length d);
  let w = Int32.to_int (String.get_int32_be d 0)
  and h = Int32.to_int (String.get_int32_be d 4) in
  let depth = Char.code d.[8] and ctype = Char.code d.[9] in
  if w < 1 || h < 1 then bad "a PNG image of %d×%d pixels is empty" w h;
  if w > max_pixels / h then
    bad "image %d×%d is larger than the limit of %d pixels" w h max_pixels;
  let depths =
    match ctype with
    | 0 -> [ 1; 2; 4; 8; 16 ]
    | 3 -> [ 1; 2; 4; 8 ]
    | 2 | 4 | 6 -> [ 8; 16 ]
    | _ -> []
  in
  if depths = [] then
    bad "unsupported PNG colour type %d (the standard ones are 0, 2, 3, 4 and 6)" ctype;
  if not (List.mem depth depths) then
    bad "a %s PNG cannot have %d bits per sample" (type_name ctype) depth;
  if Char.code d.[10] <> 0 then
    bad "unsupported PNG compression method %d" (Char.code d.[10]);
  if Char.code d.[11] <> 0 then bad "unsupported PNG filter method %d" (Char.code d.[11]);
  let interlaced =
    match Char.code d.[12] with
    | 0 -> false
    | 1 -> true
    | m -> bad "unsupported PNG interlace method %d" m
  in
  { w; h; depth; ctype; interlaced }

(* The chunks of a file: header, palette, transparency and the concatenated image data. *)
let read_chunks max_pixels s =
  let n = String.length s in
  if n < 8 || String.sub s 0 8 <> signature then bad "not a PNG file";
  let header = ref None
  and plte = ref None
  and trns = ref None
  and idat = Buffer.create ((n / 2) + 16) in
  let rec go pos first =
    if pos + 8 > n then bad "truncated PNG file (it ends before its IEND chunk)";
    let len = Int32.to_int (String.get_int32_be s pos) land 0xFFFFFFFF in
    let kind = String.sub s (pos + 4) 4 in
    if pos + 12 + len > n || len < 0 then
      bad "truncated PNG file (chunk %s at byte %d runs past the end)"
        (String.escaped kind) pos;
    if first && kind <> "IHDR" then bad "not a PNG file (its first chunk is not IHDR)";
    let stored = String.get_int32_be s (pos + 8 + len) in
    let data = String.sub s (pos + 8) len in
    if not (Int32.equal stored (crc_of kind data len)) then
      bad "corrupt PNG file (bad checksum in chunk %s at byte %d)" (String.escaped kind)
        pos;
    let next = pos + 12 + len in
    match kind with
    | "IHDR" ->
        if first then header := Some (parse_header max_pixels data)
        else bad "corrupt PNG file (a second IHDR chunk)";
        go next false
    | "PLTE" ->
        plte := Some data;
        go next false
    | "tRNS" ->
        trns := Some data;
        go next false
    | "IDAT" ->
        Buffer.add_string idat data;
        go next false
    | "IEND" -> ()
    | _ ->
        (* Ancillary chunks (lower-case first letter) may be skipped; critical ones not. *)
        if Char.code kind.[0] land 32 = 0 then
          bad "unsupported critical PNG chunk %s" (String.escaped kind);
        go next false
  in
  go 8 true;
  match !header with
  | None -> bad "not a PNG file (no IHDR chunk)"
  | Some hd ->
      if Buffer.length idat = 0 then bad "corrupt PNG file (no image data)";
      (hd, !plte, !trns, Buffer.contents idat)

(* The passes of the image: (x0, y0, dx, dy); Adam7 has seven, a plain image one. *)
let passes hd =
  if hd.interlaced then
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

let pass_size hd (x0, y0, dx, dy) = ((hd.w - x0 + dx - 1) / dx, (hd.h - y0 + dy - 1) / dy)
let row_bytes hd pw = ((pw * channels_of_type hd.ctype * hd.depth) + 7) / 8

let inflate data expected =
  let out = Bytes.create expected in
  let z = Zlib.inflate_init true in
  finally (fun () -> Zlib.inflate_end z) @@ fun () ->
  let spare = Bytes.create 1 in
  let rec go pos opos =
    let len = String.length data - pos in
    let finished, used_in, used_out =
      if opos < expected then
        Zlib.inflate_string z data pos len out opos (expected - opos) Zlib.Z_SYNC_FLUSH
      else Zlib.inflate_string z data pos len spare 0 1 Zlib.Z_SYNC_FLUSH
    in
    if opos >= expected && used_out > 0 then
      bad "corrupt PNG file (more image data than its size needs)";
    let pos = pos + used_in and opos = opos + used_out in
    if finished then (
      if opos < expected then
        bad "truncated PNG image data (%d of %d bytes)" opos expected)
    else if used_in = 0 && used_out = 0 then (
      if opos < expected then
        bad "truncated PNG image data (%d of %d bytes)" opos expected)
    else go pos opos
  in
  (try go 0 0 with Zlib.Error (_, m) -> bad "corrupt PNG image data (zlib: %s)" m);
  out

let unfilter ~bpp buf off stride rows =
  let prev_row = ref (-1) in
  for y = 0 to rows - 1 do
    let base = off + (y * (stride + 1)) in
    let ft = Bytes.get_uint8 buf base in
    if ft > 4 then bad "corrupt PNG image data (filter type %d)" ft;
    let row = base + 1 in
    let up = !prev_row in
    for k = 0 to stride - 1 do
      let a = if k >= bpp then Bytes.get_uint8 buf (row + k - bpp) else 0 in
      let b = if up >= 0 then Bytes.get_uint8 buf (up + k) else 0 in
      let c = if k >= bpp && up >= 0 then Bytes.get_uint8 buf (up + k - bpp) else 0 in
      let x = Bytes.get_uint8 buf (row + k) in
      let v =
        match ft with
        | 0 -> x
        | 1 -> x + a
        | 2 -> x + b
        | 3 -> x + ((a + b) lsr 1)
        | _ -> x + paeth a b c
      in
      Bytes.set_uint8 buf (row + k) (v land 255)
    done;
    prev_row := row
  done

let decode_exn max_pixels s =
  let hd, plte, trns, idat = read_chunks max_pixels s in
  let ch = channels_of_type hd.ctype in
  let palette =
    match (hd.ctype, plte) with
    | 3, None -> bad "corrupt PNG file (a palette image without a PLTE chunk)"
    | 3, Some p when String.length p mod 3 <> 0 || String.length p = 0 ->
        bad "corrupt PNG file (PLTE chunk of %d bytes)" (String.length p)
    | 3, Some p -> p
    | _ -> ""
  in
  let out_ch = if hd.ctype = 3 then if trns <> None then 4 else 3 else ch in
  let out_depth = if hd.depth = 16 then 16 else 8 in
  let ob = out_depth / 8 in
  let samples = Bytes.create (hd.w * hd.h * out_ch * ob) in
  let bpp = max 1 (ch * hd.depth / 8) in
  let ps =
    List.filter
      (fun p ->
        let pw, ph = pass_size hd p in
        pw > 0 && ph > 0)
      (passes hd)
  in
  let expected =
    List.fold_left
      (fun acc p ->
        let pw, ph = pass_size hd p in
        acc + (ph * (row_bytes hd pw + 1)))
      0 ps
  in
  let raw = inflate idat expected in
  let maxv = (1 lsl hd.depth) - 1 in
  let off = ref 0 in
  List.iter
    (fun ((x0, y0, dx, dy) as p) ->
      let pw, ph = pass_size hd p in
      let stride = row_bytes hd pw in
      unfilter ~bpp raw !off stride ph;
      for y = 0 to ph - 1 do
        let row = !off + (y * (stride + 1)) + 1 in
        let j = y0 + (y * dy) in
        for x = 0 to pw - 1 do
          let i = x0 + (x * dx) in
          let dst = ((j * hd.w) + i) * out_ch in
          if hd.depth = 16 then
            for c = 0 to ch - 1 do
              Bytes.set_uint16_be samples
                (2 * (dst + c))
                (Bytes.get_uint16_be raw (row + (2 * ((x * ch) + c))))
            done
          else if hd.depth = 8 && hd.ctype <> 3 then
            for c = 0 to ch - 1 do
              Bytes.set_uint8 samples (dst + c) (Bytes.get_uint8 raw (row + (x * ch) + c))
            done
          else
            (* One sample of 1, 2, 4 or 8 bits: gray or a palette index. *)
            let v =
              if hd.depth = 8 then Bytes.get_uint8 raw (row + x)
              else
                let bit = x * hd.depth in
                (Bytes.get_uint8 raw (row + (bit / 8)) lsr (8 - hd.depth - (bit mod 8)))
                land maxv
            in
            if hd.ctype = 3 then (
              if (3 * v) + 2 >= String.length palette then
                bad "corrupt PNG image data (palette index %d of %d entries)" v
                  (String.length palette / 3);
              for c = 0 to 2 do
                Bytes.set_uint8 samples (dst + c) (Char.code palette.[(3 * v) + c])
              done;
              match trns with
              | Some t ->
                  Bytes.set_uint8 samples (dst + 3)
                    (if v < String.length t then Char.code t.[v] else 255)
              | None -> ())
            else Bytes.set_uint8 samples dst (v * 255 / maxv)
        done
      done;
      off := !off + (ph * (stride + 1)))
    ps;
  Raster.make ~width:hd.w ~height:hd.h ~channels:out_ch ~depth:out_depth samples

(* The text of a tEXt chunk (keyword NUL text, Latin-1) or an uncompressed iTXt one
   (keyword NUL flag method language NUL translated NUL text); None for a compressed one or
   any other chunk. *)
let text_of kind data =
  match String.index_opt data '\000' with
  | None -> None
  | Some k -> (
      let keyword = String.sub data 0 k in
      let rest = String.sub data (k + 1) (String.length data - k - 1) in
      match kind with
      | "tEXt" -> Some (keyword, rest)
      | "iTXt" when String.length rest >= 2 && rest.[0] = '\000' -> (
          let after = String.sub rest 2 (String.length rest - 2) in
          match String.index_opt after '\000' with
          | None -> None
          | Some l -> (
              match String.index_from_opt after (l + 1) '\000' with
              | None -> None
              | Some t ->
                  Some (keyword, String.sub after (t + 1) (String.length after - t - 1))))
      | _ -> None)

let texts s =
  let n = String.length s in
  if n < 8 || String.sub s 0 8 <> signature then Error "not a PNG file"
  else
    let rec go pos acc =
      if pos + 12 > n then Ok (List.rev acc)
      else
        let len = Int32.to_int (String.get_int32_be s pos) land 0xFFFFFFFF in
        let kind = String.sub s (pos + 4) 4 in
        if len < 0 || pos + 12 + len > n then Ok (List.rev acc)
        else if kind = "IEND" then Ok (List.rev acc)
        else
          let data = String.sub s (pos + 8) len in
          let acc =
            if Int32.equal (String.get_int32_be s (pos + 8 + len)) (crc_of kind data len)
            then match text_of kind data with Some t -> t :: acc | None -> acc
            else acc
          in
          go (pos + 12 + len) acc
    in
    go 8 []

let decode ?(max_pixels = Raster.max_pixels) s =
  match decode_exn max_pixels s with
  | r -> Ok r
  | exception Bad m -> Error m
  | exception Out_of_memory -> Error "the image needs more memory than is available"
