(* See ply.mli. *)

open Tri_builder

exception Bad of string

let bad fmt = Printf.ksprintf (fun m -> raise (Bad m)) fmt

type format = Ascii | Binary_le | Binary_be
type scalar = Int8 | Uint8 | Int16 | Uint16 | Int32 | Uint32 | Float32 | Float64

type property =
  | Scalar of { name : string; ty : scalar }
  | List of { name : string; count : scalar; item : scalar }

type element = { name : string; count : int; props : property array; line : int }

let scalar_of = function
  | "char" | "int8" -> Some Int8
  | "uchar" | "uint8" -> Some Uint8
  | "short" | "int16" -> Some Int16
  | "ushort" | "uint16" -> Some Uint16
  | "int" | "int32" -> Some Int32
  | "uint" | "uint32" -> Some Uint32
  | "float" | "float32" -> Some Float32
  | "double" | "float64" -> Some Float64
  | _ -> None

let size = function
  | Int8 | Uint8 -> 1
  | Int16 | Uint16 -> 2
  | Int32 | Uint32 | Float32 -> 4
  | Float64 -> 8

let prop_name = function Scalar { name; _ } | List { name; _ } -> name

(* A binary value at [p] of [t], as a float or an integer. *)
let[@inline] get_float ~le ty t p =
  match ty with
  | Float32 ->
      Int32.float_of_bits
        (if le then String.get_int32_le t p else String.get_int32_be t p)
  | Float64 ->
      Int64.float_of_bits
        (if le then String.get_int64_le t p else String.get_int64_be t p)
  | Int8 -> Float.of_int (String.get_int8 t p)
  | Uint8 -> Float.of_int (String.get_uint8 t p)
  | Int16 ->
      Float.of_int (if le then String.get_int16_le t p else String.get_int16_be t p)
  | Uint16 ->
      Float.of_int (if le then String.get_uint16_le t p else String.get_uint16_be t p)
  | Int32 ->
      Int32.to_float (if le then String.get_int32_le t p else String.get_int32_be t p)
  | Uint32 ->
      let v = if le then String.get_int32_le t p else String.get_int32_be t p in
      Int64.to_float (Int64.logand (Int64.of_int32 v) 0xFFFF_FFFFL)

(* An integer value; −1 for a float type (never a valid count or index). *)
let[@inline] get_int ~le ty t p =
  match ty with
  | Int8 -> String.get_int8 t p
  | Uint8 -> String.get_uint8 t p
  | Int16 -> if le then String.get_int16_le t p else String.get_int16_be t p
  | Uint16 -> if le then String.get_uint16_le t p else String.get_uint16_be t p
  | Int32 ->
      Int32.to_int (if le then String.get_int32_le t p else String.get_int32_be t p)
  | Uint32 ->
      Int32.to_int (if le then String.get_int32_le t p else String.get_int32_be t p)
      land 0xFFFF_FFFF
  | Float32 | Float64 -> -1

(* ---- The header ---------------------------------------------------------------------- *)

(* The header's lines up to "end_header", the format, the elements in order, and the
   offset of the first byte of data. Every problem names the header's line. *)
let header text =
  let len = String.length text in
  let rec lines i n acc =
    if i >= len then bad "line %d: the header has no end_header line" n
    else
      let e = match String.index_from_opt text i '\n' with Some e -> e | None -> len in
      let line = String.sub text i (e - i) in
      let line =
        if String.length line > 0 && line.[String.length line - 1] = '\r' then
          String.sub line 0 (String.length line - 1)
        else line
      in
      let words = List.filter (( <> ) "") (String.split_on_char ' ' line) in
      let words = List.concat_map (String.split_on_char '\t') words in
      let words = List.filter (( <> ) "") words in
      if words = [ "end_header" ] then (List.rev ((n, words) :: acc), min len (e + 1))
      else lines (e + 1) (n + 1) ((n, words) :: acc)
  in
  if
    not
      (String.length text >= 4
      && String.sub text 0 3 = "ply"
      && (text.[3] = '\n' || text.[3] = '\r'))
  then bad "line 1: not a PLY file (it must start with a line \"ply\")";
  let ls, data = lines 0 1 [] in
  let format = ref None and elements = ref [] in
  let add_prop n p =
    match !elements with
    | [] -> bad "line %d: a property before any element" n
    | e :: rest -> elements := { e with props = Array.append e.props [| p |] } :: rest
  in
  List.iter
    (fun (n, words) ->
      match words with
      | [ "ply" ] when n = 1 -> ()
      | [ "format"; f; "1.0" ] -> (
          if !format <> None then bad "line %d: a second format line" n;
          match f with
          | "ascii" -> format := Some Ascii
          | "binary_little_endian" -> format := Some Binary_le
          | "binary_big_endian" -> format := Some Binary_be
          | _ ->
              bad
                "line %d: unknown format %S (expected ascii, binary_little_endian or \
                 binary_big_endian)"
                n f)
      | "format" :: _ ->
          bad
            "line %d: expected \"format ascii|binary_little_endian|binary_big_endian \
             1.0\""
            n
      | ("comment" | "obj_info") :: _ -> ()
      | [ "element"; name; count ] -> (
          match int_of_string_opt count with
          | Some c when c >= 0 ->
              elements := { name; count = c; props = [||]; line = n } :: !elements
          | _ ->
              bad "line %d: element %s: expected a count of 0 or more, got %S" n name
                count)
      | [ "property"; "list"; c; i; name ] -> (
          match (scalar_of c, scalar_of i) with
          | Some (Float32 | Float64), _ ->
              bad "line %d: property %s: a list's count must be an integer type" n name
          | Some count, Some item -> add_prop n (List { name; count; item })
          | _ ->
              bad
                "line %d: property %s: unknown type (expected char, uchar, short, \
                 ushort, int, uint, float, double or their int8…float64 names)"
                n name)
      | [ "property"; ty; name ] -> (
          match scalar_of ty with
          | Some ty -> add_prop n (Scalar { name; ty })
          | None -> bad "line %d: property %s: unknown type %S" n name ty)
      | [ "end_header" ] -> ()
      | [] -> ()
      | w :: _ ->
          bad "line %d: unknown header line %S" n
            (if String.length w > 16 then String.sub w 0 16 ^ "…" else w))
    ls;
  match !format with
  | None -> bad "line 2: the header has no format line"
  | Some f -> (f, List.rev !elements, data, List.length ls)

(* ---- Reading values -------------------------------------------------------------------- *)

(* A cursor over the data: binary values at a byte offset, or ASCII words with the line
   they are on. *)
type cursor = { text : string; mutable pos : int; mutable line : int; fmt : format }

let where c =
  match c.fmt with
  | Ascii -> Printf.sprintf "line %d" c.line
  | Binary_le | Binary_be -> Printf.sprintf "byte %d" c.pos

(* The next ASCII word, [s, e). *)
let word c =
  let t = c.text and len = String.length c.text in
  let i = ref c.pos in
  while
    !i < len
    &&
    match String.unsafe_get t !i with
    | ' ' | '\t' | '\r' -> true
    | '\n' ->
        c.line <- c.line + 1;
        true
    | _ -> false
  do
    incr i
  done;
  if !i >= len then bad "%s: the file ends before its last element" (where c);
  let s = !i in
  while
    !i < len
    && match String.unsafe_get t !i with ' ' | '\t' | '\r' | '\n' -> false | _ -> true
  do
    incr i
  done;
  c.pos <- !i;
  (s, !i)

let need c n =
  if c.pos + n > String.length c.text then
    bad "%s: the file ends before its last element" (where c)

(* A value as a float (integers exactly). *)
let read_float c ty =
  match c.fmt with
  | Ascii ->
      let s, e = word c in
      let f = Obj_file.float_at c.text s e in
      if Float.is_nan f then
        bad "%s: expected a number, got %S" (where c)
          (String.sub c.text s (min 16 (e - s)));
      f
  | Binary_le | Binary_be ->
      need c (size ty);
      let p = c.pos in
      c.pos <- p + size ty;
      get_float ~le:(c.fmt = Binary_le) ty c.text p

(* A value that must be an integer (a list's count, an index). *)
let read_int c ty =
  match c.fmt with
  | Ascii -> (
      let s, e = word c in
      match Obj_file.int_at c.text s e with
      | Some n -> n
      | None ->
          bad "%s: expected an integer, got %S" (where c)
            (String.sub c.text s (min 16 (e - s))))
  | Binary_le | Binary_be ->
      need c (size ty);
      let p = c.pos in
      c.pos <- p + size ty;
      get_int ~le:(c.fmt = Binary_le) ty c.text p

let skip c = function
  | Scalar { ty; _ } -> (
      match c.fmt with
      | Ascii -> ignore (word c)
      | _ ->
          need c (size ty);
          c.pos <- c.pos + size ty)
  | List { count; item; name } -> (
      let n = read_int c count in
      if n < 0 then bad "%s: list %s has a negative length %d" (where c) name n;
      match c.fmt with
      | Ascii ->
          for _ = 1 to n do
            ignore (word c)
          done
      | _ ->
          need c (n * size item);
          c.pos <- c.pos + (n * size item))

(* ---- The mesh ---------------------------------------------------------------------------- *)

let index_of props names =
  let found = ref None in
  Array.iteri
    (fun i p -> if !found = None && List.mem (prop_name p) names then found := Some i)
    props;
  !found

let read_mesh ?(smooth = true) ~file text =
  try
    let fmt, elements, data, header_lines = header text in
    let c = { text; pos = data; line = header_lines + 1; fmt } in
    let vertices = List.find_opt (fun (e : element) -> e.name = "vertex") elements in
    let nv = match vertices with Some e -> e.count | None -> 0 in
    let vs = floats 3 and vns = floats 3 and vts = floats 2 in
    let tv = corners () and tn = corners () and tt = corners () in
    let with_normals = ref false and with_uvs = ref false in
    (* The corners of the face being read. *)
    let cur = ref (Array.make 16 0) in
    let set_cur j v =
      if j >= Array.length !cur then (
        let d = Array.make (2 * j) 0 in
        Array.blit !cur 0 d 0 j;
        cur := d);
      Array.unsafe_set !cur j v
    in
    (* Faces read before the vertices they use (an element order PLY allows), as their
       corner count and corners, made into triangles once every vertex is known. *)
    let deferred = ref (Trimesh.ints 0) and nd = ref 0 in
    let defer v =
      if !nd + 1 > Bigarray.Array1.dim !deferred then (
        let d = Trimesh.ints (max 64 (2 * !nd)) in
        Bigarray.Array1.blit !deferred (Bigarray.Array1.sub d 0 !nd);
        deferred := d);
      Bigarray.Array1.unsafe_set !deferred !nd (Int32.of_int v);
      incr nd
    in
    let vertices_read = ref false and nf = ref 0 in
    let has_normals = ref false and has_uvs = ref false in
    (* Face [corner 0 … corner (n − 1)] as triangles, fanned from its first corner as
       OBJ's polygons are; those of zero area dropped. *)
    let fan corner n =
      incr nf;
      let a = corner 0 in
      for i = 1 to n - 2 do
        let b = corner i and d = corner (i + 1) in
        let ar = area vs.fl a b d in
        if ar > 0. && Float.is_finite ar then (
          push_corners tv a b d;
          if smooth && !has_normals then (
            with_normals := true;
            push_present tn a b d)
          else push_absent tn;
          if !has_uvs then (
            with_uvs := true;
            push_present tt a b d)
          else push_absent tt)
      done
    in
    List.iter
      (fun (e : element) ->
        match e.name with
        | "vertex" ->
            let p k names =
              match index_of e.props names with
              | Some i -> (
                  match e.props.(i) with
                  | Scalar _ -> Some i
                  | List _ ->
                      bad "line %d: vertex property %s must not be a list" e.line k)
              | None -> None
            in
            let x = p "x" [ "x" ] and y = p "y" [ "y" ] and z = p "z" [ "z" ] in
            let nx = p "nx" [ "nx" ] and ny = p "ny" [ "ny" ] and nz = p "nz" [ "nz" ] in
            let u = p "u" [ "u"; "s"; "texture_u"; "texture_s" ]
            and v = p "v" [ "v"; "t"; "texture_v"; "texture_t" ] in
            let req name = function
              | Some i -> i
              | None -> bad "line %d: the vertex element has no property %s" e.line name
            in
            let x = req "x" x and y = req "y" y and z = req "z" z in
            let normals =
              match (nx, ny, nz) with
              | Some a, Some b, Some c -> Some (a, b, c)
              | _ -> None
            in
            let uvs = match (u, v) with Some a, Some b -> Some (a, b) | _ -> None in
            has_normals := normals <> None;
            has_uvs := uvs <> None;
            let n = Array.length e.props in
            let in_range px py pz =
              Float.abs px <= 1e150 && Float.abs py <= 1e150 && Float.abs pz <= 1e150
            in
            let scalar i =
              match e.props.(i) with Scalar { ty; _ } -> ty | List _ -> Uint8
            in
            (if
               fmt <> Ascii
               && Array.for_all (function Scalar _ -> true | List _ -> false) e.props
             then (
               (* Fixed-size records: each value read in place at its offset. *)
               let le = fmt = Binary_le
               and t = text in
               let offs = Array.make n 0 and stride = ref 0 in
               for i = 0 to n - 1 do
                 offs.(i) <- !stride;
                 stride := !stride + size (scalar i)
               done;
               let stride = !stride and base = c.pos in
               if e.count > (String.length t - base) / max 1 stride then (
                 c.pos <- String.length t;
                 bad "%s: the file ends before its last element" (where c));
               let at k i = get_float ~le (scalar i) t (base + (k * stride) + offs.(i)) in
               for k = 0 to e.count - 1 do
                 let px = at k x and py = at k y and pz = at k z in
                 if not (in_range px py pz) then (
                   c.pos <- base + (k * stride);
                   bad "%s: a vertex coordinate is outside ±1e150" (where c));
                 push3 vs px py pz;
                 (match normals with
                 | Some (a, b, d) -> push3 vns (at k a) (at k b) (at k d)
                 | None -> ());
                 match uvs with Some (a, b) -> push2 vts (at k a) (at k b) | None -> ()
               done;
               c.pos <- base + (e.count * stride))
             else
               let value = Float.Array.make n 0. in
               for _ = 1 to e.count do
                 for i = 0 to n - 1 do
                   match e.props.(i) with
                   | Scalar { ty; _ } -> Float.Array.unsafe_set value i (read_float c ty)
                   | List _ as l -> skip c l
                 done;
                 let g i = Float.Array.unsafe_get value i in
                 let px = g x and py = g y and pz = g z in
                 if not (in_range px py pz) then
                   bad "%s: a vertex coordinate is outside ±1e150" (where c);
                 push3 vs px py pz;
                 Option.iter (fun (a, b, d) -> push3 vns (g a) (g b) (g d)) normals;
                 Option.iter (fun (a, b) -> push2 vts (g a) (g b)) uvs
               done);
            vertices_read := true
        | "face" ->
            let li, count, item =
              match index_of e.props [ "vertex_indices"; "vertex_index" ] with
              | Some i -> (
                  match e.props.(i) with
                  | List { count; item; _ } -> (i, count, item)
                  | Scalar _ ->
                      bad "line %d: the face property %s must be a list" e.line
                        (prop_name e.props.(i)))
              | None when e.count = 0 -> (-1, Uint8, Uint8)
              | None -> bad "line %d: the face element has no vertex_indices list" e.line
            in
            (match item with
            | Float32 | Float64 ->
                bad "line %d: the face list %s must hold integers" e.line
                  (prop_name e.props.(li))
            | _ -> ());
            let np = Array.length e.props in
            for _ = 1 to e.count do
              for i = 0 to np - 1 do
                if i <> li then skip c e.props.(i)
                else
                  let n = read_int c count in
                  if n < 3 then
                    bad "%s: a face needs at least 3 corners, got %d" (where c) n;
                  for j = 0 to n - 1 do
                    let k = read_int c item in
                    if k < 0 || k >= nv then
                      bad "%s: vertex index %d is out of range (%d vertices)" (where c) k
                        nv;
                    set_cur j k
                  done;
                  if !vertices_read then fan (Array.unsafe_get !cur) n
                  else (
                    defer n;
                    for j = 0 to n - 1 do
                      defer (Array.unsafe_get !cur j)
                    done)
              done
            done
        | _ ->
            for _ = 1 to e.count do
              Array.iter (skip c) e.props
            done)
      elements;
    if fmt = Ascii then (
      (* Only blank space may follow the last element. *)
      let len = String.length text in
      let i = ref c.pos in
      while
        !i < len && match text.[!i] with ' ' | '\t' | '\r' | '\n' -> true | _ -> false
      do
        if text.[!i] = '\n' then c.line <- c.line + 1;
        incr i
      done;
      if !i < len then bad "line %d: more values than the header's elements hold" c.line);
    let at k = Int32.to_int (Bigarray.Array1.unsafe_get !deferred k) in
    let k = ref 0 in
    while !k < !nd do
      let n = at !k and s = !k + 1 in
      fan (fun j -> at (s + j)) n;
      k := s + n
    done;
    if tv.n = 0 && !nf > 0 then bad "all %d faces of the file have zero area" !nf
    else if tv.n = 0 then bad "the file has no faces"
    else
      Ok
        (mesh vs vns vts tv
           (if !with_normals then Some tn else None)
           (if !with_uvs then Some tt else None))
  with Bad m ->
    (* "line N: …" is located as the OBJ reader's errors are, file:N: …. *)
    let located =
      match Scanf.sscanf_opt m "line %d: %n" (fun n k -> (n, k)) with
      | Some (n, k) ->
          Printf.sprintf "%s:%d: %s" file n (String.sub m k (String.length m - k))
      | None -> Printf.sprintf "%s: %s" file m
    in
    Error located

let parse_mesh ?(smooth = true) ~file text =
  Result.map (Mesh_normals.build ~smooth) (read_mesh ~smooth ~file text)
