(* A decimal w·10^q (w < 2^63) to the nearest double, exactly.

   Small cases are exact in double arithmetic (Clinger): w ≤ 2^53 and |q| ≤ 22, one
   rounding. Otherwise (after Eisel and Lemire): with 10^q = T·2^e, T in [2^127, 2^128) and
   t = ⌊T⌋ (a power of ten's 128-bit mantissa, from a table made at build time), the product X' of m
   (w shifted to 64 bits) and t, of 192 bits H·2^128 + L·2^64 + R, is the exact product's
   lower bound, by less than m < 2^64: the error may carry one into L, and into H only
   where L is all ones. Otherwise H is exact, and gives the double's 53 bits and the 54th,
   which says how to round but where the bits below it may all be zero (a tie, rounded to
   even): X' says they are not unless its own are all zero. There, and for a result that
   is not a normal double, [None]. *)

(* ---- The powers of ten, 10^q = (hi·2^64 + lo)·2^e, made at build time ---- *)

let lowest = -350

(* ---- The conversion ---- *)

let pow10 = Array.init 23 (fun i -> float_of_string ("1e" ^ string_of_int i))
let ult a b = Int64.unsigned_compare a b < 0

(* The high and low 64 bits of the unsigned product of [a] and [b]. *)
let[@inline] mul_hi a b =
  let m = 0xFFFFFFFFL in
  let a0 = Int64.logand a m and a1 = Int64.shift_right_logical a 32 in
  let b0 = Int64.logand b m and b1 = Int64.shift_right_logical b 32 in
  let p00 = Int64.mul a0 b0 and p01 = Int64.mul a0 b1 in
  let p10 = Int64.mul a1 b0 and p11 = Int64.mul a1 b1 in
  let mid =
    Int64.add
      (Int64.add (Int64.shift_right_logical p00 32) (Int64.logand p01 m))
      (Int64.logand p10 m)
  in
  Int64.add p11
    (Int64.add
       (Int64.add (Int64.shift_right_logical p01 32) (Int64.shift_right_logical p10 32))
       (Int64.shift_right_logical mid 32))

let[@inline] mul_lo a b = Int64.mul a b

(* The zeros above the highest bit of [w > 0], as a 64-bit number: 63 less the place of
   that bit, found by halves. *)
let leading_zeros w =
  let p = 0 and x = w in
  let p, x = if x lsr 32 <> 0 then (p + 32, x lsr 32) else (p, x) in
  let p, x = if x lsr 16 <> 0 then (p + 16, x lsr 16) else (p, x) in
  let p, x = if x lsr 8 <> 0 then (p + 8, x lsr 8) else (p, x) in
  let p, x = if x lsr 4 <> 0 then (p + 4, x lsr 4) else (p, x) in
  let p, x = if x lsr 2 <> 0 then (p + 2, x lsr 2) else (p, x) in
  let p = if x lsr 1 <> 0 then p + 1 else p in
  63 - p

(* NaN where it cannot tell (no numeral is NaN). *)
let lemire w q =
  if q < lowest || q > 350 then Float.nan
  else
    let i = q - lowest in
    let th = Decimal_powers.hi.(i)
    and tl = Decimal_powers.lo.(i)
    and e = Decimal_powers.e.(i) in
    let lz = leading_zeros w in
    let m = Int64.shift_left (Int64.of_int w) lz in
    (* m·(th·2^64 + tl) = H·2^128 + L·2^64 + R *)
    let hh = mul_hi m th and hl = mul_lo m th in
    let lh = mul_hi m tl and ll = mul_lo m tl in
    let l = Int64.add hl lh in
    let h = if ult l hl then Int64.add hh 1L else hh in
    let r = ll in
    (* The error (< m) may carry one into L: not into H unless L is all ones. *)
    if l = -1L then Float.nan
    else
      let top = Int64.compare h 0L < 0 in
      let shift = if top then 10 else 9 in
      let m54 = Int64.shift_right_logical h shift in
      let below = Int64.logand h (Int64.sub (Int64.shift_left 1L shift) 1L) in
      let tie_bit = Int64.logand m54 1L = 1L in
      (* Past the 54th bit, zero bits could be a tie: only if all the known ones are. *)
      if tie_bit && below = 0L && l = 0L && r = 0L then Float.nan
      else
        let m53 = Int64.shift_right_logical m54 1 in
        let m53 = if tie_bit then Int64.add m53 1L else m53 in
        let exp = (if top then 191 else 190) + e - lz in
        let m53, exp =
          if Int64.shift_right_logical m53 53 > 0L then
            (Int64.shift_right_logical m53 1, exp + 1)
          else (m53, exp)
        in
        if exp < -1022 || exp > 1023 then Float.nan
        else
          Int64.float_of_bits
            (Int64.logor
               (Int64.shift_left (Int64.of_int (exp + 1023)) 52)
               (Int64.logand m53 0xFFFFFFFFFFFFFL))

(* The same, NaN where it cannot tell. *)
let parts w q =
  if w = 0 then 0.
  else if w <= 1 lsl 53 && q >= -22 && q <= 22 then
    if q >= 0 then Float.of_int w *. pow10.(q) else Float.of_int w /. pow10.(-q)
  else lemire w q

let of_parts w q =
  let x = parts w q in
  if Float.is_nan x then None else Some x

(* The numeral at [text.[s]] (the lexer's: digits, perhaps a point and more, perhaps an
   exponent), read up to [len] at most; where it ends goes in [at]. Up to 18 significant
   digits are kept in w (zeros after them scale it; any other digit, and the exactly
   rounded answer needs them all: [float_of_string]). *)
type cursor = { mutable at : int }

let slow text s e = float_of_string (String.sub text s (e - s))

let result text s e w q c =
  c.at <- e;
  let x = parts w q in
  if Float.is_nan x then slow text s e else x

let digit text i len =
  i < len
  &&
  let c = String.unsafe_get text i in
  c >= '0' && c <= '9'

(* At an [e] or [E]: the exponent, when digits follow (after a sign, perhaps). *)
let rec exponent text s len i w q c =
  let j =
    if
      i + 1 < len
      && (String.unsafe_get text (i + 1) = '-' || String.unsafe_get text (i + 1) = '+')
    then i + 2
    else i + 1
  in
  if not (digit text j len) then result text s i w q c
  else
    let neg = String.unsafe_get text (i + 1) = '-' in
    let rec go j x =
      if digit text j len then
        go (j + 1) (min 100_000 ((x * 10) + Char.code (String.unsafe_get text j) - 48))
      else result text s j w (if neg then q - x else q + x) c
    in
    go j 0

and whole text s len i w n q c =
  if i >= len then result text s i w q c
  else
    match String.unsafe_get text i with
    | '0' .. '9' as ch ->
        let d = Char.code ch - 48 in
        if n < 18 then
          if w = 0 && d = 0 then whole text s len (i + 1) 0 0 q c
          else whole text s len (i + 1) ((w * 10) + d) (n + 1) q c
        else if d = 0 then whole text s len (i + 1) w n (q + 1) c
        else inexact text s len (i + 1) c
    | '.' -> fraction text s len (i + 1) w n q c
    | 'e' | 'E' -> exponent text s len i w q c
    | _ -> result text s i w q c

and fraction text s len i w n q c =
  if i >= len then result text s i w q c
  else
    match String.unsafe_get text i with
    | '0' .. '9' as ch ->
        let d = Char.code ch - 48 in
        if n < 18 then
          if w = 0 && d = 0 then fraction text s len (i + 1) 0 0 (q - 1) c
          else fraction text s len (i + 1) ((w * 10) + d) (n + 1) (q - 1) c
        else if d = 0 then fraction text s len (i + 1) w n q c
        else inexact text s len (i + 1) c
    | 'e' | 'E' -> exponent text s len i w q c
    | _ -> result text s i w q c

(* Digits beyond what w holds: the numeral's end, for [float_of_string]. *)
and inexact text s len i c =
  let rec past_digits i = if digit text i len then past_digits (i + 1) else i in
  let i = past_digits i in
  let i = if i < len && String.unsafe_get text i = '.' then past_digits (i + 1) else i in
  let e =
    if i < len && (String.unsafe_get text i = 'e' || String.unsafe_get text i = 'E') then
      let j =
        if
          i + 1 < len
          && (String.unsafe_get text (i + 1) = '-' || String.unsafe_get text (i + 1) = '+')
        then i + 2
        else i + 1
      in
      if digit text j len then past_digits j else i
    else i
  in
  c.at <- e;
  slow text s e

(* The common numeral (digits, perhaps a point and more, at most 18 significant digits, no
   exponent) in one pass, any other as above: the integer part, then the fraction, whose
   digits start at [f]. *)
let rec common text s len i w n c =
  if i < len then
    let ch = String.unsafe_get text i in
    if ch >= '0' && ch <= '9' && n < 18 then
      let w = (w * 10) + (Char.code ch - 48) in
      common text s len (i + 1) w (if w > 0 then n + 1 else n) c
    else if ch = '.' then common_fraction text s len (i + 1) w n (i + 1) c
    else common_end text s len i w 0 c
  else result text s i w 0 c

and common_fraction text s len i w n f c =
  if i < len then
    let ch = String.unsafe_get text i in
    if ch >= '0' && ch <= '9' && n < 18 then
      let w = (w * 10) + (Char.code ch - 48) in
      common_fraction text s len (i + 1) w (if w > 0 then n + 1 else n) f c
    else common_end text s len i w (f - i) c
  else result text s i w (f - i) c

(* At [i < len], past the digits read: more digits, or an exponent, are read as above. *)
and common_end text s len i w q c =
  match String.unsafe_get text i with
  | '0' .. '9' | 'e' | 'E' -> whole text s len s 0 0 0 c
  | _ -> result text s i w q c

let scan_to text s len c =
  if s < 0 || s >= len then invalid_arg "Decimal.scan" else common text s len s 0 0 c

let scan text s c = scan_to text s (String.length text) c

let read text s e =
  let c = { at = s } in
  if s < 0 || e > String.length text || s >= e then invalid_arg "Decimal.read";
  let x = scan_to text s e c in
  if c.at <> e then invalid_arg "Decimal.read: not a numeral" else x
