exception Bad of int * string

let bad line fmt = Printf.ksprintf (fun m -> raise (Bad (line, m))) fmt

(* Growable arrays of the elements read so far. *)
type 'a store = { mutable data : 'a array; mutable len : int }

let store () = { data = [||]; len = 0 }

let push s x =
  if s.len = Array.length s.data then (
    let d = Array.make (max 16 (2 * s.len)) x in
    Array.blit s.data 0 d 0 s.len;
    s.data <- d);
  s.data.(s.len) <- x;
  s.len <- s.len + 1

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

let number line what s =
  match float_of_string_opt s with
  | Some f when Float.is_finite f -> f
  | _ -> bad line "%s: expected a number, got %S" what s

(* The coordinate range of the whole renderer (doc/numerics.md): beyond it squared lengths
   overflow, and a triangle's area or normal would be infinite or NaN. *)
let coordinate line s =
  let f = number line "vertex" s in
  if Float.abs f > 1e150 then bad line "vertex coordinate %s is outside ±1e150" s else f

(* A 1-based or negative index into [n] elements, as a 0-based index. *)
let index line what n s =
  match int_of_string_opt s with
  | None -> bad line "expected a %s index, got %S" what s
  | Some 0 -> bad line "%s index 0 is invalid (indices start at 1)" what
  | Some i ->
      let k = if i > 0 then i - 1 else n + i in
      if k < 0 || k >= n then
        bad line "%s index %d is out of range (%d defined so far)" what i n
      else k

let parse ?(smooth = true) ~file text =
  let vs = store () and vts = store () and vns = store () in
  let tris = ref [] and faces = ref 0 in
  let corner line s =
    match String.split_on_char '/' s with
    | [ v ] -> (index line "vertex" vs.len v, -1, -1)
    | [ v; t ] -> (index line "vertex" vs.len v, index line "texture" vts.len t, -1)
    | [ v; ""; n ] -> (index line "vertex" vs.len v, -1, index line "normal" vns.len n)
    | [ v; t; n ] ->
        ( index line "vertex" vs.len v,
          index line "texture" vts.len t,
          index line "normal" vns.len n )
    | _ -> bad line "malformed face corner %S" s
  in
  let face line (a, ta, na) (b, tb, nb) (c, tc, nc) =
    let pa = vs.data.(a) and pb = vs.data.(b) and pc = vs.data.(c) in
    let area = Vec3.length (Vec3.cross (Vec3.sub pb pa) (Vec3.sub pc pa)) in
    if area > 0. && Float.is_finite area then (
      let normals =
        if smooth && na >= 0 && nb >= 0 && nc >= 0 then
          Some (vns.data.(na), vns.data.(nb), vns.data.(nc))
        else None
      in
      let uvs =
        if ta >= 0 && tb >= 0 && tc >= 0 then
          Some (vts.data.(ta), vts.data.(tb), vts.data.(tc))
        else None
      in
      ignore line;
      tris := Shape.mesh_triangle ?normals ?uvs ~a:pa ~b:pb ~c:pc () :: !tris)
  in
  let statement line words =
    match words with
    | [] -> ()
    | "v" :: x :: y :: z :: rest ->
        if List.length rest > 1 then
          bad line "a vertex has 3 coordinates (and an optional weight)";
        push vs (Vec3.v (coordinate line x) (coordinate line y) (coordinate line z))
    | "v" :: _ -> bad line "a vertex needs 3 coordinates"
    | "vt" :: u :: rest ->
        let v =
          match rest with [] -> 0. | v :: _ -> number line "texture coordinate" v
        in
        if List.length rest > 2 then
          bad line "a texture coordinate has at most 3 components";
        push vts (number line "texture coordinate" u, v)
    | "vt" :: _ -> bad line "a texture coordinate needs at least 1 component"
    | [ "vn"; x; y; z ] ->
        push vns
          (Vec3.v (number line "normal" x) (number line "normal" y)
             (number line "normal" z))
    | "vn" :: _ -> bad line "a normal needs 3 components"
    | "f" :: corners ->
        let cs = Array.of_list (List.map (corner line) corners) in
        if Array.length cs < 3 then
          bad line "a face needs at least 3 corners, got %d" (Array.length cs);
        incr faces;
        for i = 1 to Array.length cs - 2 do
          face line cs.(0) cs.(i) cs.(i + 1)
        done
    | kw :: _ when List.mem kw ignored -> ()
    | kw :: _ ->
        let kw = if String.length kw > 16 then String.sub kw 0 16 ^ "…" else kw in
        bad line "unknown statement %S (expected v, vt, vn or f)" kw
  in
  try
    if String.contains text '\000' then bad 1 "not a text file";
    let lines = String.split_on_char '\n' text in
    List.iteri
      (fun i l ->
        let l =
          match String.index_opt l '#' with Some k -> String.sub l 0 k | None -> l
        in
        let words =
          String.split_on_char ' '
            (String.map (fun c -> if c = '\t' || c = '\r' then ' ' else c) l)
          |> List.filter (fun w -> w <> "")
        in
        statement (i + 1) words)
      lines;
    if !tris = [] && !faces > 0 then
      Error
        (Printf.sprintf "%s:%d: all %d faces of the file have zero area" file
           (List.length lines) !faces)
    else if !tris = [] then
      Error (Printf.sprintf "%s:%d: the file has no faces" file (List.length lines))
    else Ok (List.rev !tris)
  with Bad (line, m) -> Error (Printf.sprintf "%s:%d: %s" file line m)

let load ?smooth path =
  match In_channel.with_open_bin path In_channel.input_all with
  | text -> parse ?smooth ~file:path text
  | exception Sys_error m ->
      Error (Printf.sprintf "%s:0: cannot read the file (%s)" path m)

let open_edges tris =
  let uses = Hashtbl.create 1024 in
  let key (a : Vec3.t) (b : Vec3.t) =
    let k (v : Vec3.t) = (v.x, v.y, v.z) in
    if compare (k a) (k b) <= 0 then (k a, k b) else (k b, k a)
  in
  List.iter
    (function
      | Shape.Triangle { a; b; c; _ } ->
          List.iter
            (fun (p, q) ->
              let e = key p q in
              Hashtbl.replace uses e
                (1 + Option.value (Hashtbl.find_opt uses e) ~default:0))
            [ (a, b); (b, c); (c, a) ]
      | _ -> ())
    tris;
  Hashtbl.fold (fun _ n acc -> if n = 2 then acc else acc + 1) uses 0
