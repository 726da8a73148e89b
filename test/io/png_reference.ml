let[@inline] paeth a b c =
  let p = a + b - c in
  let pa = abs (p - a) and pb = abs (p - b) and pc = abs (p - c) in
  if pa <= pb && pa <= pc then a else if pb <= pc then b else c

(* The cost of a filtered byte: the absolute value of the byte read as signed, from a
   table (a branch on random bytes is mispredicted half the time). *)
let costs = String.init 256 (fun v -> Char.chr (if v < 128 then v else 256 - v))
let[@inline] cost v = Char.code (String.unsafe_get costs v)

(* [row] filtered with the filter that minimises the sum of absolute (signed) values, the
   first of the cheapest on a tie, into [out] (filter byte first). [prev] is the row above
   (zeros for the first). The five sums are taken in one pass over the row, then the row is
   filtered once with the winner. *)
let filter_row ~bpp row prev out =
  let n = Bytes.length row in
  let c0 = ref 0 and c1 = ref 0 and c2 = ref 0 and c3 = ref 0 and c4 = ref 0 in
  for k = 0 to n - 1 do
    let x = Char.code (Bytes.unsafe_get row k)
    and b = Char.code (Bytes.unsafe_get prev k) in
    let a = if k >= bpp then Char.code (Bytes.unsafe_get row (k - bpp)) else 0 in
    let c = if k >= bpp then Char.code (Bytes.unsafe_get prev (k - bpp)) else 0 in
    c0 := !c0 + cost x;
    c1 := !c1 + cost ((x - a) land 255);
    c2 := !c2 + cost ((x - b) land 255);
    c3 := !c3 + cost ((x - ((a + b) lsr 1)) land 255);
    c4 := !c4 + cost ((x - paeth a b c) land 255)
  done;
  let best = ref 0 and best_cost = ref !c0 in
  let consider ft c =
    if c < !best_cost then (
      best := ft;
      best_cost := c)
  in
  consider 1 !c1;
  consider 2 !c2;
  consider 3 !c3;
  consider 4 !c4;
  let ft = !best in
  Bytes.set_uint8 out 0 ft;
  (* One loop per filter type: the type is the same along the row. *)
  let get b k = Char.code (Bytes.unsafe_get b k) in
  let put k v = Bytes.unsafe_set out (k + 1) (Char.unsafe_chr (v land 255)) in
  match ft with
  | 0 -> Bytes.blit row 0 out 1 n
  | 1 ->
      for k = 0 to n - 1 do
        put k (get row k - if k >= bpp then get row (k - bpp) else 0)
      done
  | 2 ->
      for k = 0 to n - 1 do
        put k (get row k - get prev k)
      done
  | 3 ->
      for k = 0 to n - 1 do
        let a = if k >= bpp then get row (k - bpp) else 0 in
        put k (get row k - ((a + get prev k) lsr 1))
      done
  | _ ->
      for k = 0 to n - 1 do
        let a = if k >= bpp then get row (k - bpp) else 0 in
        let c = if k >= bpp then get prev (k - bpp) else 0 in
        put k (get row k - paeth a (get prev k) c)
      done
