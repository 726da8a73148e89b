exception Bad of int * string

let bad line fmt = Printf.ksprintf (fun m -> raise (Bad (line, m))) fmt

open Tri_builder

let ignored =
  [
    "o";
    "g";
    "s";
    "usemtl";
    "mtllib";
    "l";
    "p";
    "vp";
    "cstype";
    "deg";
    "curv";
    "curv2";
    "surf";
    "parm";
    "end";
    "bevel";
    "c_interp";
    "d_interp";
    "lod";
    "shadow_obj";
    "trace_obj";
    "maplib";
    "usemap";
    "bmat";
    "step";
    "trim";
    "hole";
    "scrv";
    "sp";
    "con";
    "mg";
    "ctech";
    "stech";
  ]

(* --- Numbers, read in place ----------------------------------------------------------

   The bytes of [text] between [s] and [e] are read as [float_of_string] and
   [int_of_string] would read them. The common forms are decoded here without a copy:
   an optional minus sign and at most 15 digits, with or without a decimal point, are
   M / 10^k with M < 2^53 and k ≤ 15, both exact doubles, and one IEEE division rounds
   their quotient correctly, which is what the C library's strtod gives too. Anything
   else (exponents, more digits, signs, hexadecimal, underscores, nan, inf) goes to the
   standard functions on a copy. *)

let pow10 =
  Float.Array.of_list
    [
      1e0; 1e1; 1e2; 1e3; 1e4; 1e5; 1e6; 1e7; 1e8; 1e9; 1e10; 1e11; 1e12; 1e13; 1e14; 1e15;
    ]

let[@inline] digit c = Char.code c - 48

(* The float at [s, e), or NaN when those bytes are not one. *)
let float_at text s e =
  let i = ref s and neg = text.[s] = '-' in
  if neg then incr i;
  let m = ref 0 and nd = ref 0 and frac = ref (-1) and ok = ref (!i < e) in
  while !ok && !i < e do
    let c = String.unsafe_get text !i in
    if c >= '0' && c <= '9' then (
      m := (10 * !m) + digit c;
      incr nd;
      if !frac >= 0 then incr frac)
    else if c = '.' && !frac < 0 && !nd > 0 then frac := 0
    else ok := false;
    incr i
  done;
  if !ok && !nd > 0 && !nd <= 15 then
    let f = Float.of_int !m in
    let f = if !frac > 0 then f /. Float.Array.unsafe_get pow10 !frac else f in
    if neg then -.f else f
  else
    match float_of_string_opt (String.sub text s (e - s)) with
    | Some f -> f
    | None -> Float.nan

(* The int at [s, e), as [int_of_string_opt] reads it. *)
let int_at text s e =
  let i = ref s and neg = s < e && text.[s] = '-' in
  if neg then incr i;
  let m = ref 0 and ok = ref (!i < e && e - !i <= 18) in
  while !ok && !i < e do
    let c = String.unsafe_get text !i in
    if c >= '0' && c <= '9' then m := (10 * !m) + digit c else ok := false;
    incr i
  done;
  if !ok then Some (if neg then - !m else !m)
  else int_of_string_opt (String.sub text s (e - s))

(* --- Lines read in one pass -----------------------------------------------------------

   Most lines of a large file are "v x y z", "vn x y z", "vt u v" and "f a b c" (or
   a/b/c, a//c, a/b corners) in the plain forms above. Such a line is read as it is
   scanned, without first being cut into words: a number is the bytes [float_at] would
   read the same way (at most 15 digits, an optional point and minus sign), a corner's
   indices positive and among those read so far. Any other byte, form or count leaves
   the line to the general reading, from its start, which also gives every error its
   message. *)

let[@inline] blank c = c = ' ' || c = '\t' || c = '\r'
let[@inline] ends_word c = blank c || c = '\n'

(* Past the blanks from [i]. *)
let[@inline] skip_blanks text len i =
  let j = ref i in
  while !j < len && blank (String.unsafe_get text !j) do
    incr j
  done;
  !j

(* The plain decimal at [i], ended by a blank, a newline or the end: its value in
   [out.(k)] and the position after it, or −1. Its integer digits and its fraction's are
   read by two loops that test one byte each, the digits' value kept in one integer. *)
let[@inline] is_digit c = c >= '0' && c <= '9'

let scan_decimal text len i out k =
  let neg = i < len && String.unsafe_get text i = '-' in
  let s = if neg then i + 1 else i in
  let j = ref s and m = ref 0 in
  while !j < len && is_digit (String.unsafe_get text !j) do
    m := (10 * !m) + digit (String.unsafe_get text !j);
    incr j
  done;
  let whole = !j - s in
  let fraction =
    if whole > 0 && !j < len && String.unsafe_get text !j = '.' then (
      incr j;
      let f0 = !j in
      while !j < len && is_digit (String.unsafe_get text !j) do
        m := (10 * !m) + digit (String.unsafe_get text !j);
        incr j
      done;
      !j - f0)
    else 0
  in
  if
    whole = 0
    || whole + fraction > 15
    || (!j < len && not (ends_word (String.unsafe_get text !j)))
  then -1
  else
    let f = Float.of_int !m in
    let f = if fraction > 0 then f /. Float.Array.unsafe_get pow10 fraction else f in
    Float.Array.unsafe_set out k (if neg then -.f else f);
    !j

(* The position after the blanks from [e] when there is at least one (so not after a
   slash), else −1; −1 from −1. *)
let[@inline] gap text len e =
  if e < 0 then -1
  else
    let s = skip_blanks text len e in
    if s = e then -1 else s

(* The positive index at [i] into [n] elements, ended by a slash, a blank, a newline or
   the end: as a 0-based index in [out.(0)] and the position after it, or −1. *)
let scan_index text len n i out =
  let j = ref i and m = ref 0 in
  while !j < len && is_digit (String.unsafe_get text !j) do
    m := (10 * !m) + digit (String.unsafe_get text !j);
    incr j
  done;
  let e = !j and m = !m in
  if
    e = i
    || e - i > 18
    || m < 1 || m > n
    || e < len
       &&
       let c = String.unsafe_get text e in
       not (c = '/' || ends_word c)
  then -1
  else (
    Array.unsafe_set out 0 (m - 1);
    e)

(* The coordinate range of the whole renderer (doc/reference/numerics.md): beyond it squared lengths
   overflow, and a triangle's area or normal would be infinite or NaN. *)
let max_coordinate = 1e150

let read_mesh ?(smooth = true) ~file text =
  let vs = floats 3 and vts = floats 2 and vns = floats 3 in
  let tv = corners () and tn = corners () and tt = corners () in
  let with_normals = ref false and with_uvs = ref false in
  let faces = ref 0 in
  let len = String.length text in
  (* The words of the current line, as (start, end) byte offsets. *)
  let ws = ref (Array.make 64 0) and nw = ref 0 in
  let ws0 k = Array.unsafe_get !ws (2 * k)
  and ws1 k = Array.unsafe_get !ws ((2 * k) + 1) in
  let word k = String.sub text (ws0 k) (ws1 k - ws0 k) in
  let add_word s e =
    if 2 * (!nw + 1) > Array.length !ws then (
      let d = Array.make (4 * (!nw + 1)) 0 in
      Array.blit !ws 0 d 0 (2 * !nw);
      ws := d);
    !ws.(2 * !nw) <- s;
    !ws.((2 * !nw) + 1) <- e;
    incr nw
  in
  let is_word k w =
    let s = ws0 k and n = String.length w in
    ws1 k - s = n
    && String.unsafe_get text s = String.unsafe_get w 0
    && (n = 1 || (n = 2 && String.unsafe_get text (s + 1) = String.unsafe_get w 1))
  in
  let number line what k =
    let f = float_at text (ws0 k) (ws1 k) in
    if Float.is_finite f then f
    else bad line "%s: expected a number, got %S" what (word k)
  in
  let coordinate line k =
    let f = number line "vertex" k in
    if Float.abs f > max_coordinate then
      bad line "vertex coordinate %s is outside ±1e150" (word k)
    else f
  in
  (* A 1-based or negative index into [n] elements, at [s, e), as a 0-based index. *)
  let index line what n s e =
    match int_at text s e with
    | None -> bad line "expected a %s index, got %S" what (String.sub text s (e - s))
    | Some 0 -> bad line "%s index 0 is invalid (indices start at 1)" what
    | Some i ->
        let k = if i > 0 then i - 1 else n + i in
        if k < 0 || k >= n then
          bad line "%s index %d is out of range (%d defined so far)" what i n
        else k
  in
  (* The corners of the current face: vertex, texture and normal indices (−1: none). *)
  let cv = ref (Array.make 16 0)
  and ct = ref (Array.make 16 0)
  and cn = ref (Array.make 16 0) in
  (* Corner [j] of the current face. *)
  let set_corner j v t n =
    if j >= Array.length !cv then (
      let grow a =
        let d = Array.make (2 * j) 0 in
        Array.blit !a 0 d 0 j;
        a := d
      in
      grow cv;
      grow ct;
      grow cn);
    !cv.(j) <- v;
    !ct.(j) <- t;
    !cn.(j) <- n
  in
  let corner line j k =
    let s = ws0 k and e = ws1 k in
    let slash from =
      let r = ref (-1) and i = ref from in
      while !r < 0 && !i < e do
        if String.unsafe_get text !i = '/' then r := !i;
        incr i
      done;
      !r
    in
    let p1 = slash s in
    let p2 = if p1 < 0 then -1 else slash (p1 + 1) in
    (* Within a corner, the normal is checked before the texture coordinate, and both
       before the vertex. *)
    let v, t, n =
      if p1 < 0 then (index line "vertex" vs.len s e, -1, -1)
      else if p2 < 0 then
        let t = index line "texture" vts.len (p1 + 1) e in
        (index line "vertex" vs.len s p1, t, -1)
      else if slash (p2 + 1) >= 0 then bad line "malformed face corner %S" (word k)
      else
        let n = index line "normal" vns.len (p2 + 1) e in
        let t = if p2 = p1 + 1 then -1 else index line "texture" vts.len (p1 + 1) p2 in
        (index line "vertex" vs.len s p1, t, n)
    in
    set_corner j v t n
  in
  (* The triangle of vertices [a], [b], [c] added to the mesh's, whether it was: one of
     zero area (or of an area beyond the floats) is left out. *)
  let added a b c =
    let area = area vs.fl a b c in
    area > 0. && Float.is_finite area
    &&
    (push_corners tv a b c;
     true)
  in
  let face i j k =
    let cv = !cv and ct = !ct and cn = !cn in
    if added cv.(i) cv.(j) cv.(k) then (
      if smooth && cn.(i) >= 0 && cn.(j) >= 0 && cn.(k) >= 0 then (
        with_normals := true;
        push_present tn cn.(i) cn.(j) cn.(k))
      else push_absent tn;
      if ct.(i) >= 0 && ct.(j) >= 0 && ct.(k) >= 0 then (
        with_uvs := true;
        push_present tt ct.(i) ct.(j) ct.(k))
      else push_absent tt)
  in
  let num = Float.Array.make 3 0. and ix = Array.make 1 0 in
  (* [count] numbers after the keyword, which ends at [i]: pushed (a vertex, normal or
     texture coordinate) by [push]. *)
  let fast_numbers i count push =
    let j = ref i and k = ref 0 in
    while !k < count && !j >= 0 do
      let j0 = skip_blanks text len !j in
      if j0 = !j then j := -1
      else (
        j := scan_decimal text len j0 num !k;
        incr k)
    done;
    if !j < 0 then -1
    else
      let e = skip_blanks text len !j in
      if e < len && String.unsafe_get text e <> '\n' then -1
      else (
        push ();
        e + 1)
  in
  let get k = Float.Array.unsafe_get num k in
  let push_v () = push3 vs (get 0) (get 1) (get 2)
  and push_vn () = push3 vns (get 0) (get 1) (get 2)
  and push_vt () = push2 vts (get 0) (get 1) in
  (* One corner at [i]: its indices into the corner arrays at [c], the position after it
     or −1. *)
  let fast_corner c i =
    let e = scan_index text len vs.len i ix in
    if e < 0 then -1
    else
      let v = Array.unsafe_get ix 0 in
      let e, t, n =
        if e < len && String.unsafe_get text e = '/' then
          if e + 1 < len && String.unsafe_get text (e + 1) = '/' then
            let e2 = scan_index text len vns.len (e + 2) ix in
            (e2, -1, Array.unsafe_get ix 0)
          else
            let e1 = scan_index text len vts.len (e + 1) ix in
            let t = Array.unsafe_get ix 0 in
            if e1 >= 0 && e1 < len && String.unsafe_get text e1 = '/' then
              let e2 = scan_index text len vns.len (e1 + 1) ix in
              (e2, t, Array.unsafe_get ix 0)
            else (e1, t, -1)
        else (e, -1, -1)
      in
      if e < 0 || (e < len && String.unsafe_get text e = '/') then -1
      else (
        set_corner c v t n;
        e)
  in
  (* The corners of a face line from [j], where [k] corners are read already: the
     position after its newline, or −1. *)
  let fast_corners j k =
    let j = ref j and k = ref k and go = ref true in
    while !go do
      let j0 = skip_blanks text len !j in
      if j0 >= len || String.unsafe_get text j0 = '\n' then (
        j := j0;
        go := false)
      else if j0 = !j then (
        j := -1;
        go := false)
      else
        let e = fast_corner !k j0 in
        if e < 0 then (
          j := -1;
          go := false)
        else (
          j := e;
          incr k)
    done;
    if !j < 0 || !k < 3 then -1
    else (
      incr faces;
      for c = 1 to !k - 2 do
        face 0 c (c + 1)
      done;
      !j + 1)
  in
  (* A triangle of vertices [a], [b], [c] alone, without normals or (u, v). *)
  let triangle a b c =
    if added a b c then (
      push_absent tn;
      push_absent tt)
  in
  (* The face line at [i]. "f a b c", plain vertex indices, is the most common: its
     corners are read into integers and the triangle added at once; a line that goes on
     past three plain corners goes on with them, and any other form is read from its
     first corner again. *)
  let fast_face i =
    let s0 = gap text len (i + 1) in
    let e0 = if s0 < 0 then -1 else scan_index text len vs.len s0 ix in
    let a = Array.unsafe_get ix 0 in
    let s1 = gap text len e0 in
    let e1 = if s1 < 0 then -1 else scan_index text len vs.len s1 ix in
    let b = Array.unsafe_get ix 0 in
    let s2 = gap text len e1 in
    let e2 = if s2 < 0 then -1 else scan_index text len vs.len s2 ix in
    let c = Array.unsafe_get ix 0 in
    if e2 < 0 then fast_corners (i + 1) 0
    else
      let e = skip_blanks text len e2 in
      if e >= len || String.unsafe_get text e = '\n' then (
        incr faces;
        triangle a b c;
        e + 1)
      else if e = e2 then fast_corners (i + 1) 0
      else (
        set_corner 0 a (-1) (-1);
        set_corner 1 b (-1) (-1);
        set_corner 2 c (-1) (-1);
        fast_corners e2 3)
  in
  (* The line starting at [i] read in one pass (see Lines read in one pass): the
     position after its newline (after the end for the last line), or −1 to read it word
     by word. *)
  let fast_line i =
    if i + 1 >= len then -1
    else
      match String.unsafe_get text i with
      | 'v' -> (
          match String.unsafe_get text (i + 1) with
          | 'n' -> fast_numbers (i + 2) 3 push_vn
          | 't' -> fast_numbers (i + 2) 2 push_vt
          | _ -> fast_numbers (i + 1) 3 push_v)
      | 'f' -> fast_face i
      | _ -> -1
  in
  (* One line's words: a statement. Within a statement, components are checked from the
     last to the first. *)
  let statement line =
    let nw = !nw in
    if nw = 0 then ()
    else if is_word 0 "v" then (
      if nw < 4 then bad line "a vertex needs 3 coordinates";
      if nw > 5 then bad line "a vertex has 3 coordinates (and an optional weight)";
      let z = coordinate line 3 in
      let y = coordinate line 2 in
      let x = coordinate line 1 in
      push3 vs x y z)
    else if is_word 0 "f" then (
      for j = 0 to nw - 2 do
        corner line j (j + 1)
      done;
      if nw - 1 < 3 then bad line "a face needs at least 3 corners, got %d" (nw - 1);
      incr faces;
      for i = 1 to nw - 3 do
        face 0 i (i + 1)
      done)
    else if is_word 0 "vn" then (
      if nw <> 4 then bad line "a normal needs 3 components";
      let z = number line "normal" 3 in
      let y = number line "normal" 2 in
      let x = number line "normal" 1 in
      push3 vns x y z)
    else if is_word 0 "vt" then (
      if nw < 2 then bad line "a texture coordinate needs at least 1 component";
      let v = if nw >= 3 then number line "texture coordinate" 2 else 0. in
      if nw > 4 then bad line "a texture coordinate has at most 3 components";
      let u = number line "texture coordinate" 1 in
      push2 vts u v)
    else
      let kw = word 0 in
      if not (List.mem kw ignored) then
        let kw = if String.length kw > 16 then String.sub kw 0 16 ^ "…" else kw in
        bad line "unknown statement %S (expected v, vt, vn or f)" kw
  in
  try
    (* Lines end at '\n' (the text after the last one is a line too); '#' starts a
       comment; words are separated by spaces, tabs and carriage returns. A NUL byte
       anywhere makes the whole file not text, whatever else is wrong with it: the scan
       stops at one, and the first error found before one is checked against the rest. *)
    let line = ref 1 and i = ref 0 and start = ref (-1) and comment = ref false in
    let bol = ref true in
    nw := 0;
    while !i <= len do
      let e = if !bol then fast_line !i else -1 in
      if e >= 0 then (
        (* A whole line read in one pass, its newline too unless it was the last. *)
        if e <= len then incr line;
        i := e)
      else
        let c = if !i = len then '\n' else String.unsafe_get text !i in
        bol := c = '\n';
        if c = '\000' then bad 1 "not a text file"
        else if c = '\n' then (
          if !start >= 0 then add_word !start !i;
          statement !line;
          nw := 0;
          start := -1;
          comment := false;
          if !i < len then incr line)
        else if !comment then ()
        else if c = ' ' || c = '\t' || c = '\r' || c = '#' then (
          if !start >= 0 then (
            add_word !start !i;
            start := -1);
          if c = '#' then comment := true)
        else if !start < 0 then start := !i;
        incr i
    done;
    let lines = !line in
    if tv.n = 0 && !faces > 0 then
      Error
        (Printf.sprintf "%s:%d: all %d faces of the file have zero area" file lines !faces)
    else if tv.n = 0 then Error (Printf.sprintf "%s:%d: the file has no faces" file lines)
    else
      Ok
        (mesh vs vns vts tv
           (if !with_normals then Some tn else None)
           (if !with_uvs then Some tt else None))
  with Bad (line, m) ->
    let line, m =
      if String.contains text '\000' then (1, "not a text file")
      else if vs.len = 0 && vns.len = 0 && vts.len = 0 && !faces = 0 then
        (* Nothing read yet is OBJ: the file is something else, whose words are not
           quoted (a scene may name any file as a mesh). *)
        ( line,
          "not an OBJ file: no vertex, normal, texture coordinate or face before this \
           line" )
      else (line, m)
    in
    Error (Printf.sprintf "%s:%d: %s" file line m)

let parse_mesh ?(smooth = true) ~file text =
  Result.map (Mesh_normals.build ~smooth) (read_mesh ~smooth ~file text)

let load_mesh ?smooth path =
  match In_channel.with_open_bin path In_channel.input_all with
  | text -> parse_mesh ?smooth ~file:path text
  | exception Sys_error m ->
      Error (Printf.sprintf "%s:0: cannot read the file (%s)" path m)

let parse ?smooth ~file text = Result.map Shape.faces (parse_mesh ?smooth ~file text)
let load ?smooth path = Result.map Shape.faces (load_mesh ?smooth path)

(* A slot of an open-addressing table of [mask + 1] slots (a power of two) for a hash. *)
let[@inline] scramble h mask =
  let h = h lxor (h lsr 31) in
  let h = h * 0x2545F4914F6CDD1D in
  (h lsr 21) land mask

(* The number of slots for [n] entries: a power of two at least twice [n]. *)
let table_size n =
  let s = ref 16 in
  while !s < 2 * n do
    s := 2 * !s
  done;
  !s

(* Two coordinates at one position: equal, or both NaN. *)
let[@inline] coord_eq a b = a = b || (Float.is_nan a && Float.is_nan b)

let[@inline] same_corner xyz i j =
  let g k = Float.Array.unsafe_get xyz k in
  coord_eq (g (3 * i)) (g (3 * j))
  && coord_eq (g ((3 * i) + 1)) (g ((3 * j) + 1))
  && coord_eq (g ((3 * i) + 2)) (g ((3 * j) + 2))

(* A hash of coordinate [x]'s bits, the same for 0 and -0 and for every NaN; the sign (the
   bit that does not fit an [int]) folded into the lowest. *)
let[@inline] coord_bits x =
  if x = 0. then 0
  else if Float.is_nan x then 1
  else
    let b = Int64.bits_of_float x in
    Int64.to_int b lxor Int64.to_int (Int64.shift_right_logical b 63)

(* The edges of triangles whose corners are [xyz] (9 floats a triangle: corners a, b, c)
   that are not shared by exactly two of them. Corners are one position where their
   coordinates are equal as floats, or both NaN (0 and -0 are one, as [compare] has it):
   each corner is numbered by the first corner at its position, through a table hashed
   on the coordinates' bits; each edge is the pair of its ends' numbers, lower first, and
   a second table counts each edge's uses. *)
let open_edges_of xyz =
  let nc = Float.Array.length xyz / 3 in
  let size = table_size nc in
  let mask = size - 1 in
  let first = Array.make size (-1) and id = Array.make nc 0 in
  for i = 0 to nc - 1 do
    let h = scramble (coord_bits (Float.Array.get xyz (3 * i))) (-1) in
    let h = scramble (h + coord_bits (Float.Array.get xyz ((3 * i) + 1))) (-1) in
    let h = h + coord_bits (Float.Array.get xyz ((3 * i) + 2)) in
    let s = ref (scramble h mask) in
    while first.(!s) >= 0 && not (same_corner xyz first.(!s) i) do
      s := (!s + 1) land mask
    done;
    if first.(!s) < 0 then first.(!s) <- i;
    id.(i) <- first.(!s)
  done;
  let edge = Array.make size (-1) and uses = Array.make size 0 in
  for c = 0 to nc - 1 do
    let a = id.(c) and b = id.(if c mod 3 = 2 then c - 2 else c + 1) in
    let e = if a <= b then (a * nc) + b else (b * nc) + a in
    let s = ref (scramble e mask) in
    while edge.(!s) >= 0 && edge.(!s) <> e do
      s := (!s + 1) land mask
    done;
    edge.(!s) <- e;
    uses.(!s) <- uses.(!s) + 1
  done;
  let opened = ref 0 in
  for s = 0 to size - 1 do
    if edge.(s) >= 0 && uses.(s) <> 2 then incr opened
  done;
  !opened

let open_edges tris =
  let tris =
    List.filter_map
      (function Shape.Triangle { a; b; c; _ } -> Some (a, b, c) | _ -> None)
      tris
  in
  let xyz = Float.Array.create (9 * List.length tris) in
  List.iteri
    (fun t ((a : Vec3.t), (b : Vec3.t), (c : Vec3.t)) ->
      List.iteri
        (fun k (v : Vec3.t) ->
          let o = (9 * t) + (3 * k) in
          Float.Array.set xyz o v.x;
          Float.Array.set xyz (o + 1) v.y;
          Float.Array.set xyz (o + 2) v.z)
        [ a; b; c ])
    tris;
  open_edges_of xyz

let open_edges_mesh m =
  let n = Trimesh.count m in
  let xyz = Float.Array.create (9 * n) in
  for t = 0 to n - 1 do
    for k = 0 to 2 do
      let v = Trimesh.vertex m t k and o = (9 * t) + (3 * k) in
      Float.Array.set xyz o v.x;
      Float.Array.set xyz (o + 1) v.y;
      Float.Array.set xyz (o + 2) v.z
    done
  done;
  open_edges_of xyz
