module D = Description

(* A file's problem is kept as its message for any spelling of its name: the same file
   named two ways ("gone.obj" from an include, "sub/gone.obj" from the main file) is
   read once, and each place is told of it as it wrote it. *)
type 'a read = ('a, string -> string) result

type assets = {
  pictures : (string, Framebuffer.t read) Hashtbl.t;
  meshes : (string * bool, Trimesh.t read) Hashtbl.t;
  heights : (string, (int * int * Float.Array.t) read) Hashtbl.t;
      (** height-field images: width, height and each pixel's luminance in [0, 1] *)
  height_fields : (string * bool, unit) Hashtbl.t;
      (** the height fields made of them: (path, smooth) *)
  digests : (string, string) Hashtbl.t option;
      (** with [~digests:true]: each file's MD5 (hex), of the very bytes decoded *)
  after_read : string -> unit;
  lock : Mutex.t;
}

let assets ?(digests = false) ?(after_read = ignore) () =
  {
    pictures = Hashtbl.create 4;
    meshes = Hashtbl.create 4;
    heights = Hashtbl.create 4;
    height_fields = Hashtbl.create 4;
    digests = (if digests then Some (Hashtbl.create 4) else None);
    after_read;
    lock = Mutex.create ();
  }

let files (c : assets) =
  Mutex.protect c.lock (fun () ->
      List.sort_uniq compare
        (Hashtbl.fold (fun p _ acc -> p :: acc) c.pictures []
        @ Hashtbl.fold (fun (p, _) _ acc -> p :: acc) c.meshes []
        @ Hashtbl.fold (fun p _ acc -> p :: acc) c.heights []))

let digest (c : assets) path =
  Option.bind c.digests (fun t ->
      Mutex.protect c.lock (fun () -> Hashtbl.find_opt t path))

(* Read once per cache, whatever frame or thread asks first. *)
let cached c tbl key read =
  match Mutex.protect c.lock (fun () -> Hashtbl.find_opt tbl key) with
  | Some r -> r
  | None ->
      let r = read () in
      Mutex.protect c.lock (fun () -> Hashtbl.replace tbl key r);
      r

let guarded what f =
  try f () with
  | Sys.Break -> raise Sys.Break
  | e ->
      let m = Printexc.to_string e in
      Error (fun written -> Printf.sprintf "cannot %s \"%s\": %s" what written m)

let unreadable ~what path =
  Option.map
    (fun r -> Error (fun written -> Diagnostic.cannot_read_because ~what ~written path r))
    (Diagnostic.unreadable path)

let failed what m =
  Error (fun written -> Printf.sprintf "cannot %s \"%s\": %s" what written m)

let spelled written r = Result.map_error (fun f -> f written) r

(* A file's bytes, as they are decoded: read once, and digested from those very bytes
   where the cache keeps digests, so that what a record says of a file is what the
   picture was made of, even if the file is replaced meanwhile. A file read twice (a mesh
   smooth and faceted, a picture also a height field) must give the same bytes both times:
   otherwise it changed while the scene was being made, and which version a frame shows
   would be a matter of timing. *)
let took c path bytes =
  c.after_read path;
  match c.digests with
  | None -> Ok bytes
  | Some t -> (
      let d = Digest.to_hex (Digest.string bytes) in
      match
        Mutex.protect c.lock (fun () ->
            match Hashtbl.find_opt t path with
            | Some d' when not (String.equal d d') -> Some d'
            | Some _ -> None
            | None ->
                Hashtbl.replace t path d;
                None)
      with
      | None -> Ok bytes
      | Some _ -> Error "the file changed while the scene was being made; run again")

let picture c (im : D.image) =
  spelled im.written
  @@ cached c c.pictures im.path (fun () ->
         match unreadable ~what:"image" im.path with
         | Some e -> e
         | None ->
             guarded "read the image" (fun () ->
                 match Image.read_bytes im.path with
                 | Error m -> failed "read the image" m
                 | Ok bytes -> (
                     match took c im.path bytes with
                     | Error m -> failed "read the image" m
                     | Ok bytes -> (
                         match Image.linear_of_string ~path:im.path bytes with
                         | Ok img -> Ok img
                         | Error m -> failed "read the image" m))))

(* A mesh file's text: a regular file only (a FIFO would block, a device never end). *)
let mesh_text path =
  match Unix.stat path with
  | exception Unix.Unix_error (e, _, _) ->
      Error (Printf.sprintf "%s:0: cannot read the file (%s)" path (Unix.error_message e))
  | { st_kind = Unix.S_REG; _ } -> (
      match In_channel.with_open_bin path In_channel.input_all with
      | text -> Ok text
      | exception Sys_error m ->
          Error (Printf.sprintf "%s:0: cannot read the file (%s)" path m))
  | _ ->
      Error
        (Printf.sprintf "%s:0: not a regular file (a device or a pipe), not a mesh" path)

(* The size of a mesh file's text from which it is collected before the hierarchy is
   built: a full collection marks what is live, little beside reading so large a file. *)
let large_mesh_text = 16 * 1024 * 1024

let mesh c ~file ~path ~smooth =
  spelled file
  @@ cached c c.meshes (path, smooth) (fun () ->
         match unreadable ~what:"mesh" path with
         | Some e -> e
         | None ->
             guarded "load the mesh" (fun () ->
                 match mesh_text path with
                 | Error m -> failed "load the mesh" m
                 | Ok text -> (
                     match took c path text with
                     | Error m -> failed "load the mesh" m
                     | Ok text -> (
                         let read =
                           if String.lowercase_ascii (Filename.extension path) = ".ply"
                           then Ply.read_mesh
                           else Obj_file.read_mesh
                         in
                         let large = String.length text >= large_mesh_text in
                         match read ~smooth ~file:path text with
                         | Ok m ->
                             (* The text is no longer reachable: a large one is let go
                                (with what the reader outgrew) before the hierarchy's
                                build, which would otherwise peak beside it. *)
                             if large then Gc.full_major ();
                             Ok (Mesh_normals.build ~smooth m)
                         | Error m -> failed "load the mesh" m))))

let heights c ~file ~path =
  spelled file
  @@ cached c c.heights path (fun () ->
         match unreadable ~what:"image" path with
         | Some e -> e
         | None -> (
             match
               Result.bind (Image.read_bytes path) (fun bytes ->
                   Result.bind (took c path bytes) (Image.raster_of_string ~path))
             with
             | Error m -> failed "read the image" m
             | Ok r ->
                 (* Luminance (Rec. 709 weights) of the stored samples, linear from 0 to the
                 largest value (255, or 65535 for 16 bits) to 1; a grey pixel is its own
                 value; alpha is ignored. *)
                 let w = r.width and h = r.height in
                 let top = Float.of_int (Raster.max_value r) in
                 let v k =
                   let i = k mod w and j = k / w in
                   let c n = Float.of_int (Raster.get r i j n) in
                   if r.channels <= 2 then c 0 /. top
                   else if c 0 = c 1 && c 1 = c 2 then c 0 /. top
                   else ((0.2126 *. c 0) +. (0.7152 *. c 1) +. (0.0722 *. c 2)) /. top
                 in
                 Ok (w, h, Float.Array.init (w * h) v)))

(* A problem found while compiling: reported at the place the description recorded. *)
exception Problem of Loc.t * string

let problem loc fmt = Printf.ksprintf (fun m -> raise (Problem (loc, m))) fmt
let ok_or loc = function Ok x -> x | Error m -> raise (Problem (loc, m))

(* The description's texture with its image decoded and its colour maps as arrays (the
   description has checked them). *)
let texture c : D.texture -> Texture.t = function
  | Solid c -> Solid c
  | Checker { c1; c2; size } -> Checker { c1; c2; size }
  | Stripes { c1; c2; size } -> Stripes { c1; c2; size }
  | Noise { c1; c2; scale } -> Noise { c1; c2; scale }
  | Marble { c1; c2; scale } -> Marble { c1; c2; scale }
  | Wood { c1; c2; scale } -> Wood { c1; c2; scale }
  | Gradient { axis; map } -> Gradient { axis; map = Texture.color_map map }
  | Mapped { pattern; map } -> Mapped { pattern; map = Texture.color_map map }
  | Image { image; scale } -> Image { image = ok_or image.at (picture c image); scale }

let bump c : D.bump -> Bump.t = function
  | Noise_bump { scale; amount } -> Noise_bump { scale; amount }
  | Image_bump { image; amount } ->
      Image_bump { image = ok_or image.at (picture c image); amount }

let material c (m : D.material) : Material.t =
  { m with texture = Option.map (texture c) m.texture; bump = Option.map (bump c) m.bump }

let height_field c ~file ~path ~(origin : Vec3.t) ~(size : Vec3.t) ~smooth ~at =
  match heights c ~file ~path with
  | Error m -> problem at "%s" m
  | Ok (w, h, _) when w < 2 || h < 2 ->
      problem at "a height field needs an image of at least 2×2 pixels; \"%s\" is %d×%d"
        file w h
  | Ok (w, h, v) ->
      Mutex.protect c.lock (fun () -> Hashtbl.replace c.height_fields (path, smooth) ());
      (* Vertex (i, j) at O + (sx·i/(W−1), sy·v(i, j), sz·j/(H−1)); j is the image row. *)
      let vert i j =
        Vec3.v
          (origin.x +. (size.x *. Float.of_int i /. Float.of_int (w - 1)))
          (origin.y +. (size.y *. Float.Array.get v ((j * w) + i)))
          (origin.z +. (size.z *. Float.of_int j /. Float.of_int (h - 1)))
      in
      if smooth then (
        (* The same vertices and triangles, as one mesh whose normals are computed. *)
        let pos = Float.Array.create (3 * w * h) in
        for j = 0 to h - 1 do
          for i = 0 to w - 1 do
            let p = vert i j and k = 3 * ((j * w) + i) in
            Float.Array.set pos k p.x;
            Float.Array.set pos (k + 1) p.y;
            Float.Array.set pos (k + 2) p.z
          done
        done;
        let tv = Trimesh.ints (6 * (w - 1) * (h - 1)) and n = ref 0 in
        let corner v =
          Bigarray.Array1.set tv !n (Int32.of_int v);
          incr n
        in
        for j = 0 to h - 2 do
          for i = 0 to w - 2 do
            let a = (j * w) + i in
            let bb = a + w and c = a + 1 and d = a + w + 1 in
            List.iter corner [ a; bb; c; c; bb; d ]
          done
        done;
        let none = Float.Array.create 0 in
        [
          Shape.mesh
            (Mesh_normals.build ~smooth
               {
                 pos;
                 nrm = none;
                 tex = none;
                 tv;
                 tn = Trimesh.no_ints;
                 tt = Trimesh.no_ints;
               });
        ])
      else
        let tris = ref [] in
        for j = h - 2 downto 0 do
          for i = w - 2 downto 0 do
            let a = vert i j
            and bb = vert i (j + 1)
            and c = vert (i + 1) j
            and d = vert (i + 1) (j + 1) in
            tris := Shape.triangle ~a ~b:bb ~c :: Shape.triangle ~a:c ~b:bb ~c:d :: !tris
          done
        done;
        !tris

(* The shapes of an object (one, or a mesh's or height field's triangles) and, for a CSG
   object, the material of each of its leaves ([None]: the object's own). *)
let rec shapes c (o : D.obj) : Shape.t list * D.material option array =
  match o.shape with
  | Sphere { center; radius } -> ([ Shape.sphere ~center ~radius ], [||])
  | Plane { normal; offset } -> ([ Shape.plane ~normal ~offset ], [||])
  | Parallelogram { origin; edge1; edge2 } ->
      ([ Shape.parallelogram ~origin ~edge1 ~edge2 ], [||])
  | Triangle { a; b; c = cc } -> ([ Shape.triangle ~a ~b ~c:cc ], [||])
  | Paraboloid { vertex; axis; radius; height } ->
      ([ Shape.paraboloid ~vertex ~axis ~radius ~height ], [||])
  | Box { min; max } -> ([ Shape.box ~min ~max ], [||])
  | Cylinder { base; top; radius; caps } ->
      ([ Shape.cylinder ~base ~top ~radius ~caps ], [||])
  | Disk { center; normal; radius } -> ([ Shape.disk ~center ~normal ~radius ], [||])
  | Cone { base; base_radius; top; top_radius; caps } ->
      ([ Shape.cone ~base ~top ~base_radius ~top_radius ~caps ], [||])
  | Torus { center; major; minor; axis } ->
      ([ Shape.torus ~center ~axis ~major ~minor ], [||])
  | Mesh { file; path; smooth; at } -> (
      match mesh c ~file ~path ~smooth with
      | Error m -> problem at "%s" m
      | Ok m when Trimesh.count m = 0 ->
          problem at "the mesh \"%s\" has no triangles" file
      | Ok m -> ([ Shape.mesh m ], [||]))
  | Height_field { file; path; origin; size; smooth; at } ->
      (height_field c ~file ~path ~origin ~size ~smooth ~at, [||])
  | Csg { op; block; members; solid } ->
      let member (m : D.obj) =
        let sh, leaves = shapes c m in
        match (m.shape, sh) with
        | Mesh _, [ Shape.Mesh { mesh; _ } ] ->
            (if solid then
               match Obj_file.open_edges_mesh mesh with
               | 0 -> ()
               | n ->
                   problem m.loc
                     "this mesh is open: %d edge%s not shared by exactly two faces, so \
                      it has no inside to combine in `%s`"
                     n
                     (if n = 1 then " is" else "s are")
                     block);
            ((Shape.solid_mesh mesh, m.transform), [| D.object_material m |])
        | _, [ s ] ->
            ( (s, m.transform),
              if Array.length leaves = 0 then [| D.object_material m |]
              else
                Array.map
                  (function None -> D.object_material m | Some _ as x -> x)
                  leaves )
        | _ -> problem m.loc "a %s cannot be a member of a CSG object" m.kind
      in
      let op : Shape.csg_op =
        match op with
        | Union -> Union
        | Merge -> Merge
        | Intersection -> Intersection
        | Difference -> Difference
      in
      let ms = List.map member members in
      ([ Shape.csg op (List.map fst ms) ], Array.concat (List.map snd ms))

(* Errors in source order: files in the order they first appear, then line and column. *)
let sort_problems ps =
  let files =
    List.fold_left
      (fun acc ((l : Loc.t), _) -> if List.mem l.file acc then acc else acc @ [ l.file ])
      [] ps
  in
  let rec index x i = function
    | [] -> i
    | y :: r -> if y = x then i else index x (i + 1) r
  in
  let key ((l : Loc.t), _) = (index l.file 0 files, l.line, l.col) in
  List.stable_sort (fun a b -> compare (key a) (key b)) ps

(* Materials compared as the generic table compares keys, hashed over every field:
   [Hashtbl.hash] reads the first ten values of a record only, and materials that differ
   in their filter alone would all fall in one bucket. *)
module Materials = Hashtbl.Make (struct
  type t = D.material

  let equal (m : t) m' = compare m m' = 0
  let hash (m : t) = Hashtbl.hash_param 32 256 m
end)

(* One material record per distinct material of the description (hash-consed: objects
   whose materials are equal, or differ in their colour alone, which objects hold beside
   them, share one), the default material the renderer's own. *)
let materials c =
  let last = ref None and table = Materials.create 16 in
  function
  | None -> Material.default
  | Some m -> (
      match !last with
      | Some (dm, rm) when dm == m -> rm
      | _ ->
          let rm =
            match Materials.find_opt table m with
            | Some rm -> rm
            | None ->
                let rm = material c m in
                if Materials.length table < D.shared_materials then
                  Materials.add table m rm;
                rm
          in
          last := Some (m, rm);
          rm)

(* The primitives of one object: its colour beside its material, but for a CSG object,
   whose leaves take the material with its colour. *)
let primitives c material_of (o : D.obj) =
  let sh, leaves = shapes c o in
  if Array.length leaves = 0 then
    List.map
      (Primitive.make ~transform:o.transform ~color:o.color (material_of o.material))
      sh
  else
    let m = material_of (D.object_material o) in
    let leaf_materials =
      Array.map (Option.map (fun lm -> material_of (Some lm))) leaves
    in
    List.map (Primitive.make ~transform:o.transform ~leaf_materials m) sh

type static = {
  entry_of : int array;  (** by statement position: its entry, or −1 *)
  positions : int array;  (** each entry's statement position, increasing *)
  firsts : int array;  (** the index in [objs] of each entry's first object *)
  counts : int array;  (** and its count of objects *)
  objs : D.obj array;
  start : int array;  (** where each object's primitives start in [flat] *)
  faces : int array;
      (** the faces of the objects before each (one more entry: all of them), a mesh
          counting as its faces *)
  flat : Primitive.t array;
  ok : bool;  (** whether every object compiled *)
  part_lock : Mutex.t;
  mutable part : Scene.fixed option;  (** for the last origin asked *)
}

let static c (st : D.static) =
  let entries = Array.of_list st in
  let positions = Array.map fst entries in
  let counts = Array.map (fun (_, objs) -> List.length objs) entries in
  let firsts = Array.make (Array.length entries) 0 in
  for k = 1 to Array.length entries - 1 do
    firsts.(k) <- firsts.(k - 1) + counts.(k - 1)
  done;
  let entry_of = Array.make (1 + Array.fold_left max (-1) positions) (-1) in
  Array.iteri
    (fun e i ->
      if i < 0 || entry_of.(i) >= 0 || (e > 0 && positions.(e - 1) >= i) then
        invalid_arg "Compile.static: the positions are not increasing";
      entry_of.(i) <- e)
    positions;
  let objs = Array.of_list (List.concat_map snd st) in
  let material_of = materials c in
  let made ~ok ~start ~faces ~flat =
    {
      entry_of;
      positions;
      firsts;
      counts;
      objs;
      start;
      faces;
      flat;
      ok;
      part_lock = Mutex.create ();
      part = None;
    }
  in
  match Array.map (primitives c material_of) objs with
  | prims ->
      let start = Array.make (Array.length objs) 0 in
      let n = ref 0 in
      Array.iteri
        (fun i ps ->
          start.(i) <- !n;
          n := !n + List.length ps)
        prims;
      let flat = Array.of_list (List.concat (Array.to_list prims)) in
      let faces = Array.make (Array.length objs + 1) 0 in
      Array.iteri
        (fun i ps ->
          faces.(i + 1) <- List.fold_left (fun w p -> w + Primitive.faces p) faces.(i) ps)
        prims;
      made ~ok:true ~start ~faces ~flat
  | exception Problem _ -> made ~ok:false ~start:[||] ~faces:[||] ~flat:[||]

(* The structure over the static part, moved for [origin]: the one made for the last
   origin asked, or a new one. *)
let static_part st (origin : Vec3.t) =
  Mutex.protect st.part_lock (fun () ->
      match st.part with
      | Some f
        when let bits = Int64.bits_of_float and (o : Vec3.t) = Scene.fixed_origin f in
             bits o.x = bits origin.x
             && bits o.y = bits origin.y
             && bits o.z = bits origin.z ->
          f
      | _ ->
          st.part <- None;
          let f = Scene.fixed ~key:st.positions ~origin st.flat in
          st.part <- Some f;
          f)

(* The entry of the static statement at position [i]. *)
let entry st i =
  if i >= 0 && i < Array.length st.entry_of && st.entry_of.(i) >= 0 then st.entry_of.(i)
  else invalid_arg "Compile.compile: a static part that is not the static part's"

(* The GC's space overhead while objects handed over are compiled: over a million
   spheres, the default (120) let the heap grow by 100 MB beside the dying objects before
   it reused their space; 40 by about 55 MB, with no measurable cost in time; 20 by about
   30 MB, for a tenth more processor time. *)
let handed_over_overhead = 40

(* The same from [compact_objects] objects on where a structure is built (the compile
   then compacts: below, and in lancer check, it stays [handed_over_overhead]), the heap
   at its peak holding the description, its primitives and what the collector has not
   reclaimed yet: over a million spheres each with a colour of its own, 30 peaks at
   293 MiB where 40 peaks at 307 MiB, in the same time (1.44 s against 1.40 s, medians of
   five runs), while the 100 000 spheres of field_100000 at 40 run 12 % fewer
   instructions than at 30 (1.68 G against 1.91 G at 480×270). *)
let large_overhead = 30

(* From this many objects handed over, the heap is compacted once they are all compiled,
   before the acceleration structure is built: the space the dead description leaves in
   the heap is not given back to the system otherwise, and the structure's arrays would
   be allocated beside it. Over a million spheres that is 284 MB at the peak instead of
   367 MB. Compacting takes about 0.3 s there. Below, the space given back is not worth
   the time. Without a structure to build (lancer check), nothing is allocated after the
   objects. A still's stream, which holds no description, is collected in full only where
   that many of its primitives moved ([of_stream]). *)
let compact_objects = 250_000

(* Objects compiled one by one into one array of primitives: as [compile] walks a
   description's objects, or as a still's program makes them ({!stream}). *)
type stream = {
  s_assets : assets;
  s_material : D.material option -> Material.t;
  s_flat : Gathered.t;
  mutable s_problems : (Loc.t * string) list;  (** newest first *)
  s_seen : (Loc.t * string, unit) Hashtbl.t;
  mutable s_count : int;  (** primitives, a mesh's triangles each *)
  mutable s_open : bool;
}

let new_stream ?move c =
  {
    s_assets = c;
    s_material = materials c;
    s_flat = Gathered.create ?move ();
    s_problems = [];
    s_seen = Hashtbl.create 4;
    s_count = 0;
    s_open = true;
  }

let stream c = new_stream c

let report s loc msg =
  if not (Hashtbl.mem s.s_seen (loc, msg)) then (
    Hashtbl.add s.s_seen (loc, msg) ();
    s.s_problems <- (loc, msg) :: s.s_problems)

let counted s (o : D.obj) n =
  s.s_count <- s.s_count + n;
  if s.s_count > D.max_objects && s.s_count - n <= D.max_objects then
    report s o.loc
      (Printf.sprintf "this scene builds more than %d objects; that is the limit"
         D.max_objects)

let faces ps = List.fold_left (fun w p -> w + Primitive.faces p) 0 ps

(* The primitives of [o] (then counted), or its problem reported. *)
let compiled s (o : D.obj) =
  match primitives s.s_assets s.s_material o with
  | ps ->
      counted s o (faces ps);
      Some ps
  | exception Problem (loc, msg) ->
      report s loc msg;
      None

let add s (o : D.obj) =
  if not s.s_open then invalid_arg "Compile.add: the stream is finished";
  match o.shape with
  | Sphere { center; radius } when o.transform == Transform.identity -> (
      (* What [primitives] makes of it, handed to the stream as its parts: no primitive
         or list is made for a sphere the stream holds as floats. *)
      match s.s_material o.material with
      | m ->
          counted s o 1;
          Gathered.add_sphere s.s_flat ~center ~radius ~color:o.color m
      | exception Problem (loc, msg) -> report s loc msg)
  | _ -> (
      match compiled s o with
      | Some ps -> List.iter (Gathered.add s.s_flat) ps
      | None -> ())

(* The problems found, each at its place, in source order. *)
let problems ~source s =
  List.map
    (fun ((loc : Loc.t), msg) -> Diagnostic.make ?source:(source loc.file) loc msg)
    (sort_problems (List.rev s.s_problems))

let building ~progress ~index s =
  if index && s.s_count > 10_000 then
    progress
      (Printf.sprintf "building the acceleration structure over %d objects" s.s_count)

let invalid (d : D.t) = function
  | Ok sc -> Ok sc
  | Error m -> Error [ Diagnostic.file_error d.file ("invalid scene: " ^ m) ]

(* The scene of the stream's primitives, in render coordinates. *)
let of_stream ~index s (d : D.t) =
  let flat = Gathered.take s.s_flat in
  (* Into render coordinates where the stream did not move them as they were made (the
     camera was not known yet), in place: a primitive that does not move (one without a
     transform, near the world's origin) is itself. *)
  let moved = ref 0 in
  (if not (Gathered.moves s.s_flat) then
     let move = Scene.mover d.camera in
     for i = 0 to Array.length flat - 1 do
       let p = Array.unsafe_get flat i in
       (* Written only where it moved: a write is a barrier for the collector to follow,
          a million of them for a million spheres. *)
       let q = move p in
       if q != p then (
         incr moved;
         Array.unsafe_set flat i q)
     done);
  (* The primitives that moved leave their unmoved ones dead: from [compact_objects] of
     them, those are freed before the structure's arrays are allocated, or what lancer
     check goes on to allocate. A full major cycle frees them; compacting the heap as
     well would move nothing worth it, the primitives filling the pools they were
     promoted into. Nothing else of the load is worth a collection there: the held
     spheres' floats are outside the heap, freed as they are read. *)
  if !moved >= compact_objects then Gc.full_major ();
  invalid d
    (Scene.of_moved ~index ~checked:true ~settings:d.settings ~camera:d.camera
       ~time:d.time ~frame:d.frame ~lights:d.lights flat)

let finish ?(source = fun _ -> None) ?(progress = ignore) ?(index = true) s (d : D.t) =
  if not s.s_open then invalid_arg "Compile.finish: the stream is finished";
  s.s_open <- false;
  if s.s_problems <> [] then (
    Gathered.discard s.s_flat;
    Error (problems ~source s))
  else (
    building ~progress ~index s;
    of_stream ~index s d)

let compile ?(source = fun _ -> None) ?(progress = ignore) ?(index = true) ?static
    ?objects ?parts c (d : D.t) =
  let handed_over = Option.is_some objects in
  let objects = Option.value objects ~default:d.objects in
  (* The static part a scene made of parts is layered over: one that compiled and holds
     objects. *)
  let fx =
    match (parts, static) with
    | Some _, Some st when index && st.ok && Array.length st.objs > 0 -> Some st
    | _ -> None
  in
  let pieces = ref [] in
  (* The run of the static part met last, not yet in [pieces]: consecutive objects of the
     static part make one piece, with nothing allocated for each. *)
  let run_first = ref 0 and run_n = ref 0 in
  let end_run () =
    if !run_n > 0 then (
      pieces := Scene.Fixed (!run_first, !run_n) :: !pieces;
      run_n := 0)
  in
  (* Each primitive moved into render coordinates as it is made: the unmoved one dies
     young, instead of a second copy of them all made beside the first. Without a
     static part, the objects go straight into the stream's one array: no list cell or
     piece per object beside them while the structure is built. *)
  let s = new_stream ~move:(Scene.mover d.camera) c in
  (* Objects handed over die as they are compiled: the major GC keeps pace with them, so
     that the space they leave holds their primitives rather than a heap grown beside.
     (No closure here holds the list: each object goes once it is compiled.) *)
  let compacting =
    index && handed_over && List.compare_length_with objects compact_objects >= 0
  in
  let overhead = (Gc.get ()).space_overhead in
  let pace o = if handed_over then Gc.set { (Gc.get ()) with space_overhead = o } in
  pace (min overhead (if compacting then large_overhead else handed_over_overhead));
  (* Primitives [first] to [first + n − 1] of the static part, after what came
     before. *)
  let add_run first n =
    if !run_n > 0 && !run_first + !run_n = first then run_n := !run_n + n
    else (
      end_run ();
      run_first := first;
      run_n := n)
  in
  (* Where the static part's primitives of object [j] start (all of them at the end). *)
  let prim_end (fx : static) j =
    if j < Array.length fx.start then fx.start.(j) else Array.length fx.flat
  in
  (* Objects [i] to [j − 1] of the static part, placed as they were made. *)
  let add_static (fx : static) i j =
    add_run fx.start.(i) (prim_end fx j - fx.start.(i))
  in
  let one (o : D.obj) =
    match fx with
    | None -> add s o
    | Some _ -> (
        match compiled s o with
        | Some ps ->
            end_run ();
            pieces := Scene.Moving ps :: !pieces
        | None -> ())
  in
  (* The static statements placed whole, in order, and the last one's entry. *)
  let placed = ref 0 and last = ref (-1) in
  let static_piece i =
    let st =
      match static with
      | Some st -> st
      | None -> invalid_arg "Compile.compile: a static part without the static part"
    in
    let e = entry st i in
    let i0 = st.firsts.(e) and j = st.firsts.(e) + st.counts.(e) in
    match fx with
    | Some fx when s.s_count + fx.faces.(j) - fx.faces.(i0) <= D.max_objects ->
        (* All its objects at once, nothing done per object. *)
        add_static fx i0 j;
        s.s_count <- s.s_count + fx.faces.(j) - fx.faces.(i0);
        if e > !last && st.counts.(e) > 0 then incr placed;
        last := e
    | Some fx ->
        for k = i0 to j - 1 do
          add_static fx k (k + 1);
          counted s fx.objs.(k) (fx.faces.(k + 1) - fx.faces.(k))
        done
    | None ->
        for k = i0 to j - 1 do
          one st.objs.(k)
        done
  in
  Fun.protect
    ~finally:(fun () -> pace overhead)
    (fun () ->
      match parts with
      | None -> List.iter one objects
      | Some ps ->
          List.iter
            (function D.Static i -> static_piece i | D.Built objs -> List.iter one objs)
            ps);
  end_run ();
  if s.s_problems <> [] then Error (problems ~source s)
  else (
    if compacting then Gc.compact ();
    building ~progress ~index s;
    let whole (fx : static) =
      !placed = Array.fold_left (fun n k -> if k > 0 then n + 1 else n) 0 fx.counts
    in
    match fx with
    | Some fx when whole fx ->
        (* Every static statement is here, whole: its structure is reused. *)
        invalid d
          (Scene.make_layered ~checked:true ~settings:d.settings ~camera:d.camera
             ~time:d.time ~frame:d.frame ~lights:d.lights
             ~fixed:(static_part fx (Scene.origin_of d.camera))
             (List.rev !pieces))
    | None -> of_stream ~index s d
    | Some fx ->
        invalid d
          (Scene.make ~checked:true ~settings:d.settings ~camera:d.camera ~time:d.time
             ~frame:d.frame ~lights:d.lights
             (List.concat_map
                (function
                  | Scene.Moving ps -> ps
                  | Scene.Fixed (first, n) -> List.init n (fun m -> fx.flat.(first + m)))
                (List.rev !pieces))))

(* ---------------------------------------------------------------------------------- *)
(* The files alone *)

let check_files c uses =
  let problems = ref [] and seen = Hashtbl.create 4 in
  let report loc msg =
    if not (Hashtbl.mem seen (loc, msg)) then (
      Hashtbl.add seen (loc, msg) ();
      problems := (loc, msg) :: !problems)
  in
  List.iter
    (fun (u : D.file_use) ->
      match u with
      | Picture im -> ( match picture c im with Ok _ -> () | Error m -> report im.at m)
      | Model { file; path; smooth; at; solid_in } -> (
          match mesh c ~file ~path ~smooth with
          | Error m -> report at m
          | Ok m when Trimesh.count m = 0 ->
              report at (Printf.sprintf "the mesh \"%s\" has no triangles" file)
          | Ok m -> (
              match solid_in with
              | None -> ()
              | Some (block, member) -> (
                  match Obj_file.open_edges_mesh m with
                  | 0 -> ()
                  | n ->
                      report member
                        (Printf.sprintf
                           "this mesh is open: %d edge%s not shared by exactly two \
                            faces, so it has no inside to combine in `%s`"
                           n
                           (if n = 1 then " is" else "s are")
                           block))))
      | Heights { file; path; at } -> (
          match heights c ~file ~path with
          | Error m -> report at m
          | Ok (w, h, _) when w < 2 || h < 2 ->
              report at
                (Printf.sprintf
                   "a height field needs an image of at least 2×2 pixels; \"%s\" is %d×%d"
                   file w h)
          | Ok _ -> ()))
    uses;
  List.rev !problems

(* ---------------------------------------------------------------------------------- *)
(* What was made *)

(* How many objects of each kind, a mesh counting each of its faces. *)
let kinds (objs : Primitive.t array) =
  let tbl = Hashtbl.create 8 and order = ref [] in
  let add k n =
    match Hashtbl.find_opt tbl k with
    | Some m -> Hashtbl.replace tbl k (m + n)
    | None ->
        Hashtbl.add tbl k n;
        order := k :: !order
  in
  Array.iter
    (fun (o : Primitive.t) ->
      match o.shape with
      | Shape.Mesh { mesh = m; _ } ->
          let plain = ref 0 in
          for k = 0 to Trimesh.count m - 1 do
            if not (Trimesh.has_normals m k || Trimesh.has_uvs m k) then incr plain
          done;
          (* The kinds in the order the faces meet them, as one object per face would. *)
          let first_plain =
            Trimesh.count m > 0 && not (Trimesh.has_normals m 0 || Trimesh.has_uvs m 0)
          in
          let some = Trimesh.count m - !plain in
          if first_plain then (
            add "triangle" !plain;
            if some > 0 then add "mesh" some)
          else (
            if some > 0 then add "mesh" some;
            if !plain > 0 then add "triangle" !plain)
      | _ -> add (Shape.name o.shape) 1)
    objs;
  List.rev_map (fun k -> (k, Hashtbl.find tbl k)) !order

(* A CSG tree in one line: difference(box, sphere, union(sphere, sphere)). *)
let rec csg_tree (s : Shape.t) =
  match s with
  | Shape.Csg { members; _ } ->
      Printf.sprintf "%s(%s)" (Shape.name s)
        (String.concat ", "
           (Array.to_list
              (Array.map (fun (m : Shape.csg_member) -> csg_tree m.shape) members)))
  | s -> Shape.name s

(* How many distinct materials the objects shade with (a CSG object's leaves' each): the
   records {!Primitive.materials} gives, equal when every field is, colour included. An
   object holds its material's record and its colour apart, and a loop that colours a
   million objects makes a million materials that differ in their colour alone: they are
   counted from those (record, colour) pairs, with no record copied. Two pairs are the
   same material when their colours are equal and their records equal but for their
   colours ([same_record]: one record, or every other field equal, a texture or bump map
   the same one or equal). The pairs go into a table of their first uses, by surface,
   with open addressing on the colour's hash and the record's (kept for the last record
   hashed: the objects of a loop share theirs): three to six words a distinct material,
   integers only (nothing for the collector to follow), and no allocation per object. *)
let same_record (m : Material.t) (m' : Material.t) =
  let same a b = a == b || try a = b with _ -> false in
  m == m'
  || same m.texture m'.texture && same m.bump m'.bump
     && Bool.equal m.fresnel m'.fresnel
     && m.ambient = m'.ambient && m.diffuse = m'.diffuse && m.specular = m'.specular
     && m.shininess = m'.shininess && m.reflection = m'.reflection
     && m.transparency = m'.transparency
     && m.ior = m'.ior && m.metallic = m'.metallic && m.filter = m'.filter

(* A hash of what [same_record] compares, equal for equal records (−0 and 0 alike, as
   [=] takes them). *)
let record_hash = D.material_hash (fun x -> Hashtbl.hash x)

(* The table grows straight to room for every surface, rather than by doubling, once
   this many surfaces have been met and most of them were new materials (a colour per
   object): a million materials make one large allocation, not twenty. *)
let distinct_sample = 4096

let distinct_materials (sc : Scene.t) =
  (* A surface (object i, leaf l, −1 for the object itself) as one integer. *)
  let leaves, surfaces =
    Array.fold_left
      (fun (m, n) (o : Primitive.t) ->
        let l = Array.length o.extra.leaves in
        (max m l, n + max 1 l))
      (0, 0) sc.objects
  in
  let span = leaves + 1 in
  let surface w =
    let o = sc.objects.(w / span) and l = (w mod span) - 1 in
    if l < 0 then o else o.extra.leaves.(l)
  in
  let last = ref Material.default and last_hash = ref (record_hash Material.default) in
  let hash (m : Material.t) (c : Color.t) =
    if not (!last == m) then (
      last := m;
      last_hash := record_hash m);
    Hashtbl.hash c + (!last_hash * 0x9e3779b1)
  in
  (* The materials found, [count] of them, by their first surface, and the slots of the
     table (at most half full, a power of two of them), both grown as they fill. *)
  let who = ref (Array.make 16 0) and slots = ref (Array.make 32 (-1)) in
  let count = ref 0 and met = ref 0 in
  let mask () = Array.length !slots - 1 in
  let rec free s = if !slots.(s) < 0 then s else free ((s + 1) land mask ()) in
  let grow () =
    let n = Array.length !who in
    let n' = ref (2 * n) in
    if !met >= distinct_sample && 2 * !count >= !met then
      while !n' < surfaces do
        n' := 2 * !n'
      done;
    let n' = !n' in
    let w = Array.make n' 0 in
    Array.blit !who 0 w 0 n;
    who := w;
    slots := Array.make (2 * n') (-1);
    for e = 0 to !count - 1 do
      let p = surface w.(e) in
      !slots.(free (hash p.material p.color land mask ())) <- e
    done
  in
  let meet x =
    let (p : Primitive.t) = surface x in
    let m = p.material and c = p.color in
    incr met;
    let h = hash m c in
    let s = ref (h land mask ()) and go = ref true in
    while !go do
      let e = !slots.(!s) in
      if e < 0 then (
        if !count = Array.length !who then (
          grow ();
          s := free (h land mask ()));
        !slots.(!s) <- !count;
        !who.(!count) <- x;
        incr count;
        go := false)
      else
        let p' = surface !who.(e) in
        let c' = p'.color in
        if c'.r = c.r && c'.g = c.g && c'.b = c.b && same_record p'.material m then
          go := false
        else s := (!s + 1) land mask ()
    done
  in
  Array.iteri
    (fun i (o : Primitive.t) ->
      if Array.length o.extra.leaves = 0 then meet (i * span)
      else
        for l = 0 to Array.length o.extra.leaves - 1 do
          meet ((i * span) + l + 1)
        done)
    sc.objects;
  !count

let rendered c (sc : Scene.t) : D.rendered =
  let objs = sc.objects in
  Mutex.protect c.lock (fun () ->
      {
        D.r_settings = sc.settings;
        r_lights = Array.to_list sc.lights;
        r_features = sc.features;
        r_kinds = kinds objs;
        r_csg =
          Array.fold_right
            (fun (o : Primitive.t) acc ->
              if Primitive.is_csg o then csg_tree o.shape :: acc else acc)
            objs [];
        r_materials = distinct_materials sc;
        r_meshes =
          Hashtbl.fold
            (fun k r acc ->
              match r with
              | Ok m ->
                  let with_normals = ref 0 in
                  for k = 0 to Trimesh.count m - 1 do
                    if Trimesh.has_normals m k then incr with_normals
                  done;
                  let computed = Trimesh.computed m in
                  ( k,
                    {
                      D.triangles = Trimesh.count m;
                      read = !with_normals - computed;
                      computed;
                    } )
                  :: acc
              | Error _ -> acc)
            c.meshes [];
        r_rasters =
          Hashtbl.fold
            (fun ((path, _) as k) () acc ->
              match Hashtbl.find_opt c.heights path with
              | Some (Ok (w, h, _)) -> (k, (w, h)) :: acc
              | Some (Error _) | None -> acc)
            c.height_fields [];
      })

let primitive_count c (o : D.obj) =
  match o.shape with
  | Height_field { file; path; _ } -> (
      match heights c ~file ~path with
      | Ok (w, h, _) when w >= 2 && h >= 2 -> 2 * (w - 1) * (h - 1)
      | Ok _ | Error _ -> 0)
  | _ -> 1
