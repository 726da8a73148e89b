open Lancer

type physics_method = Eval.physics_method = Exact | Verlet | Euler
type physics = Eval.physics = { gravity : Vec3.t; method_ : physics_method; step : float }

type body = Eval.body = {
  name : string;
  center : Vec3.t;
  radius : float;
  material : Material.t;
  velocity : Vec3.t;
  mass : float;
  restitution : float;
  loc : Loc.t;
}

type t = {
  file : string;
  stmts : Ast.stmt list;
  sources : (string, string) Hashtbl.t;
  includes : (string, Loc.t list) Hashtbl.t;
      (** for each included file, where it was included *)
  images : Eval.images;
  first : Eval.output;  (** the evaluation at time 0, frame 0 *)
  motion : (float * Physics.trajectory) option ref;
      (** the simulation of the bodies and the horizon it was computed for, once asked *)
  motion_lock : Mutex.t;
  digests : (string, string) Hashtbl.t;
      (** image and mesh file (as the scene names it) → MD5, once read *)
  digest_lock : Mutex.t;
}

let default_physics = Eval.default_physics

let inputs t =
  List.sort_uniq compare
    (Hashtbl.fold (fun file _ acc -> file :: acc) t.sources [] @ Eval.image_files t.images)

(* A path the evaluator resolved (relative to the including file), as seen from the main
   file's directory: how the scene itself names it, whatever path the scene was typed as. *)
let scene_relative t p =
  let d = Filename.dirname t.file in
  let prefix = Filename.concat d "" in
  if d <> "." && String.starts_with ~prefix p then
    String.sub p (String.length prefix) (String.length p - String.length prefix)
  else p

let text_digest t =
  let entry f text =
    (if f = t.file then "" else scene_relative t f)
    ^ " "
    ^ Digest.to_hex (Digest.string text)
  in
  let lines =
    List.sort String.compare
      (Hashtbl.fold (fun f text acc -> entry f text :: acc) t.sources [])
  in
  Digest.to_hex (Digest.string (String.concat "\n" lines))

let input_digest t rel =
  Mutex.protect t.digest_lock (fun () ->
      match Hashtbl.find_opt t.digests rel with
      | Some d -> d
      | None ->
          let d =
            try Digest.to_hex (Digest.file (Loc.relative_to t.file rel))
            with Sys_error _ -> "-"
          in
          Hashtbl.replace t.digests rel d;
          d)

let file t = t.file
let animation t = t.first.animation
let bodies t = t.first.bodies
let physics t = t.first.physics

exception Refused of Error.t

(* The one boundary: nothing raised below reaches the caller but an interrupt (Ctrl-C
   while a scene is evaluated), which is the command's to answer. *)
let guard file f =
  try f () with
  | Sys.Break -> raise Sys.Break
  | Refused e -> Error [ e ]
  | Stack_overflow ->
      Error
        [
          Error.file_error file
            "the scene is nested too deeply (the evaluator's stack overflowed)";
        ]
  | Out_of_memory ->
      Error [ Error.file_error file "the scene needs more memory than is available" ]
  | e ->
      Error
        [
          Error.file_error file
            ("internal error: " ^ Printexc.to_string e ^ " (please report it)");
        ]

let max_source_bytes = 64 * 1024 * 1024

(* Only a regular file of a sensible size is read: a device (/dev/zero) or a huge file
   would be read in full before being refused, and a FIFO would block. Checked from the
   file's status, before it is opened. *)
let source_problem path =
  match Unix.stat path with
  | exception Unix.Unix_error (e, _, _) -> Some (Unix.error_message e)
  | st -> (
      match st.st_kind with
      | Unix.S_REG when st.st_size > max_source_bytes ->
          Some
            (Printf.sprintf "it is %d MB; a scene file may be at most %d MB"
               (st.st_size / 1_000_000)
               (max_source_bytes / 1024 / 1024))
      | Unix.S_REG -> None
      | Unix.S_DIR -> Some "it is a directory"
      | Unix.S_FIFO -> Some "it is a pipe (FIFO), not a regular file"
      | Unix.S_CHR | Unix.S_BLK -> Some "it is a device, not a regular file"
      | Unix.S_SOCK -> Some "it is a socket, not a regular file"
      | Unix.S_LNK -> None)

let read_file path =
  match source_problem path with
  | Some m -> Error m
  | None -> (
      try Ok (In_channel.with_open_bin path In_channel.input_all)
      with Sys_error m -> Error m)

let canonical path = try Unix.realpath path with _ -> path

(* Replace every [include] by the parsed statements of the file it names, relative to the
   including file. [stack] holds the files being included, outermost last. *)
let resolve sources includes errors main stmts =
  let err loc msg =
    errors :=
      Error.make ?source:(Hashtbl.find_opt sources loc.Loc.file) loc msg :: !errors
  in
  let chain file = Option.value (Hashtbl.find_opt includes file) ~default:[] in
  let rec stmts_ stack file ss = List.map (stmt stack file) ss
  and items stack file its =
    List.map
      (function Ast.Field _ as f -> f | Ast.Stmt s -> Ast.Stmt (stmt stack file s))
      its
  and stmt stack file (s : Ast.stmt) =
    let d =
      match s.s with
      | Include (p, loc) -> (
          let path = Library.locate ~including:file p in
          let key = canonical path in
          match List.find_opt (fun (k, _) -> k = key) stack with
          | Some _ ->
              let chain = List.rev_map snd stack @ [ path ] in
              let rec cut = function
                | [] -> []
                | x :: rest as l -> if canonical x = key then l else cut rest
              in
              err loc
                (Printf.sprintf "include cycle: %s"
                   (String.concat " includes " (cut chain)));
              Ast.Included (path, [])
          | None when List.length stack > 64 ->
              err loc "includes are nested more than 64 deep";
              Ast.Included (path, [])
          | None -> (
              let unreadable m =
                let msg =
                  match Error.cannot_read ~what:"included file" ~written:p path with
                  | Some msg -> msg
                  | None -> Printf.sprintf "cannot read the included file \"%s\": %s" p m
                in
                err s.sloc msg;
                Ast.Included (path, [])
              in
              (* A file's status is checked before it is opened: a device or a FIFO would be
                 read for ever or block, a huge file read in full. *)
              match
                Option.bind
                  (if Sys.file_exists path then Some path else None)
                  source_problem
              with
              | Some m ->
                  err s.sloc
                    (Printf.sprintf "cannot read the included file \"%s\": %s" p m);
                  Ast.Included (path, [])
              | None -> (
                  match Library.read path with
                  | Error m -> unreadable m
                  | Ok text -> (
                      Hashtbl.replace sources path text;
                      (* The first include of a file gives the chain its errors show. *)
                      if key <> canonical main && not (Hashtbl.mem includes path) then
                        Hashtbl.replace includes path (s.sloc :: chain file);
                      match Syntax.parse ~file:path text with
                      | Error e ->
                          errors := e :: !errors;
                          Ast.Included (path, [])
                      | Ok ss -> Ast.Included (path, stmts_ ((key, path) :: stack) path ss)
                      ))))
      | Macro (f, ps, b) -> Macro (f, ps, stmts_ stack file b)
      | For (x, a, b, st, body) -> For (x, a, b, st, stmts_ stack file body)
      | If_stmt (c, t, e) -> If_stmt (c, stmts_ stack file t, stmts_ stack file e)
      | Block (k, its) -> Block (k, items stack file its)
      | Body (n, its) -> Body (n, items stack file its)
      | (Let _ | Fn _ | Included _ | Call_stmt _) as d -> d
    in
    { s with s = d }
  in
  stmts_ [ (canonical main, main) ] main stmts

(* Every error of a file that was included gets the chain of includes that led to it. *)
let chained includes r =
  Result.map_error
    (List.map
       (Error.with_includes (fun file ->
            Option.value (Hashtbl.find_opt includes file) ~default:[])))
    r

let chained_list includes es =
  match chained includes (Error es) with Error es -> es | Ok () -> []

let load_text ?progress file text =
  let sources = Hashtbl.create 4 and includes = Hashtbl.create 4 in
  Hashtbl.replace sources file text;
  chained includes
  @@
  match Syntax.parse ~file text with
  | Error e -> Error [ e ]
  | Ok stmts -> (
      let errors = ref [] in
      let stmts = resolve sources includes errors file stmts in
      if !errors <> [] then Error (List.rev !errors)
      else
        let images = Eval.new_images () in
        let on_objects n =
          Option.iter
            (fun f -> f (Printf.sprintf "checking the scene: %d objects so far" n))
            progress
        in
        (* The static check's mistakes, with those of the evaluation at time 0: one that
           both find (in code that runs) is reported once. The evaluation's come first, so
           that its files keep the order they had without the static check; sorted in
           source order within each file. *)
        let static = Static_check.run ~sources stmts in
        let merged es =
          let key (e : Error.t) = (e.file, e.line, e.col, e.message) in
          let seen = Hashtbl.create 16 in
          Eval.sort_errors
            (List.filter
               (fun e ->
                 let k = key e in
                 (not (Hashtbl.mem seen k))
                 &&
                 (Hashtbl.add seen k ();
                  true))
               (es @ static))
        in
        match
          Eval.run ~on_objects ~objects:false ~sources ~images ~time:0. ~frame:0 stmts
        with
        | Error es -> Error (merged es)
        | Ok _ when static <> [] -> Error (merged [])
        | Ok first ->
            Ok
              {
                file;
                stmts;
                sources;
                includes;
                images;
                first;
                motion = ref None;
                motion_lock = Mutex.create ();
                digests = Hashtbl.create 4;
                digest_lock = Mutex.create ();
              })

let load_string ?progress ?(filename = "<string>") text =
  guard filename (fun () -> load_text ?progress filename text)

let load_file path =
  guard path (fun () ->
      match read_file path with
      | Error m -> Error [ Error.file_error path ("cannot read the scene: " ^ m) ]
      | Ok text -> load_text path text)

(* ---------------------------------------------------------------------------------- *)
(* Physics: the bodies move through the static objects of the scene at time 0. *)

let is_axis_aligned tr =
  let count (v : Vec3.t) =
    Bool.to_int (v.x <> 0.) + Bool.to_int (v.y <> 0.) + Bool.to_int (v.z <> 0.)
  in
  List.for_all
    (fun v -> count (Transform.vector tr v) = 1)
    [ Vec3.v 1. 0. 0.; Vec3.v 0. 1. 0.; Vec3.v 0. 0. 1. ]

let collider_of (o : Primitive.t) : Physics.collider list =
  let tr = o.transform in
  match o.shape with
  | Shape.Plane { normal; offset } ->
      let n = Transform.normal tr normal
      and p = Transform.point tr (Vec3.smul offset normal) in
      [ Physics.Plane { normal = n; offset = Vec3.dot n p } ]
  | Shape.Parallelogram { origin; edge1; edge2; _ } ->
      [
        Physics.Parallelogram
          {
            origin = Transform.point tr origin;
            edge1 = Transform.vector tr edge1;
            edge2 = Transform.vector tr edge2;
          };
      ]
  | Shape.Box { min = a; max = b } when is_axis_aligned tr ->
      let p = Transform.point tr a and q = Transform.point tr b in
      [ Physics.Box { min = Vec3.min p q; max = Vec3.max p q } ]
  | Shape.Box { min = a; max = b } ->
      (* A rotated box: its six faces. *)
      let pt x y z = Transform.point tr (Vec3.v x y z) in
      let face o u v =
        Physics.Parallelogram { origin = o; edge1 = Vec3.sub u o; edge2 = Vec3.sub v o }
      in
      let c000 = pt a.x a.y a.z
      and c100 = pt b.x a.y a.z
      and c010 = pt a.x b.y a.z
      and c001 = pt a.x a.y b.z in
      let c111 = pt b.x b.y b.z
      and c011 = pt a.x b.y b.z
      and c101 = pt b.x a.y b.z
      and c110 = pt b.x b.y a.z in
      [
        face c000 c100 c010;
        face c000 c010 c001;
        face c000 c001 c100;
        face c111 c011 c101;
        face c111 c101 c110;
        face c111 c110 c011;
      ]
  | _ -> []

(* A CSG object collides exactly as its members only when its surface is every member's
   surface (a union, or a merge, whose faces a body outside meets first anyway) and each
   member is a collider (plane, parallelogram, box). Anything else would let bodies pass
   through it: refused, at the object. *)
let rec exact_csg (s : Shape.t) =
  match s with
  | Shape.Csg { op = Union | Merge; members; _ } ->
      Array.for_all (fun (m : Shape.csg_member) -> exact_csg m.shape) members
  | Shape.Csg _ -> false
  | Shape.Plane _ | Shape.Parallelogram _ | Shape.Box _ -> true
  | _ -> false

let colliders t =
  match Eval.run ~sources:t.sources ~images:t.images ~time:0. ~frame:0 t.stmts with
  | Error _ -> []
  | Ok out ->
      List.concat_map
        (fun (o : Eval.obj) ->
          if o.body <> None then []
          else
            List.concat_map
              (fun (p : Primitive.t) ->
                if not (Primitive.is_csg p) then collider_of p
                else if exact_csg p.shape then
                  List.concat_map collider_of (Array.to_list p.leaves)
                else
                  raise
                    (Refused
                       (Error.make
                          ?source:(Hashtbl.find_opt t.sources o.loc.Loc.file)
                          o.loc
                          (Printf.sprintf
                             "bodies cannot collide with this %s: physics follows a CSG \
                              object only when it is a union or merge of planes, \
                              parallelograms and boxes"
                             o.kind))))
              o.prims)
        out.objects

let world t : Physics.world =
  let p = Option.value t.first.physics ~default:Eval.default_physics in
  let method_ =
    match p.method_ with
    | Exact -> Physics.Exact
    | Verlet -> Physics.Verlet
    | Euler -> Physics.Euler
  in
  { gravity = p.gravity; method_; step = p.step }

(* The horizon for a frame at [time]: the whole animation, or [time] when later. *)
let horizon t time =
  let dur =
    match t.first.animation with Some (fps, n) -> Float.of_int n /. fps | None -> 0.
  in
  Float.max dur time

let trajectory t ~time =
  let until = horizon t time in
  Mutex.protect t.motion_lock (fun () ->
      match !(t.motion) with
      | Some (h, tr) when h >= until -> tr
      | _ ->
          let bodies =
            List.map
              (fun (b : body) ->
                Physics.body ~velocity:b.velocity ~mass:b.mass ~restitution:b.restitution
                  ~name:b.name ~center:b.center ~radius:b.radius ())
              t.first.bodies
          in
          let w = world t in
          (* A fixed-step method keeps every step: refuse what would not fit in memory. *)
          let max_steps = 10_000_000. in
          (if w.method_ <> Physics.Exact && until /. w.step > max_steps then
             let msg =
               Printf.sprintf
                 "the physics step %g s over %g s would take %.3g steps per body; the \
                  limit is %.0f (use a larger step or the exact method)"
                 w.step until (until /. w.step) max_steps
             in
             raise
               (Refused
                  (match t.first.physics_loc with
                  | Some loc ->
                      Error.make ?source:(Hashtbl.find_opt t.sources loc.Loc.file) loc msg
                  | None -> Error.file_error t.file msg)));
          let tr = Physics.simulate w (colliders t) bodies ~until in
          t.motion := Some (until, tr);
          tr)

let simulate t ~until =
  chained t.includes (guard t.file (fun () -> Ok (trajectory t ~time:until)))

let physics_state t ~time =
  match t.first.bodies with
  | [] -> None
  | _ ->
      let tr = trajectory t ~time in
      Some (fun name s -> Physics.sample tr name s)

let eval ?body_state ?on_objects ?cancel t ~time ~frame =
  if not (Float.is_finite time) then
    Error [ Error.file_error t.file "the time must be a finite number" ]
  else
    let body_state =
      match body_state with Some f -> Some f | None -> physics_state t ~time
    in
    Eval.run ?body_state ?on_objects ?cancel ~sources:t.sources ~images:t.images ~time
      ~frame t.stmts

(* An error that only some frames have names the frame: frame 0 was checked when the
   program was loaded, so an error at another instant is one of those. *)
let at_frame ~time ~frame r =
  if Float.equal time 0. && frame = 0 then r
  else
    Result.map_error
      (List.map (fun (e : Error.t) ->
           {
             e with
             message = Printf.sprintf "%s (at frame %d, time %g s)" e.message frame time;
           }))
      r

let scene_with_files ?body_state ?progress ?cancel t ~time ~frame =
  let say fmt = Printf.ksprintf (fun m -> Option.iter (fun f -> f m) progress) fmt in
  at_frame ~time ~frame @@ chained t.includes
  @@ guard t.file (fun () ->
         let on_objects n = say "evaluating the scene: %d objects so far" n in
         match eval ?body_state ~on_objects ?cancel t ~time ~frame with
         | Error es -> Error es
         | Ok out -> (
             let prims = List.concat_map (fun (o : Eval.obj) -> o.prims) out.objects in
             if List.compare_length_with prims 10_000 > 0 then
               say "building the acceleration structure over %d objects"
                 (List.length prims);
             match
               Scene.make ~settings:out.settings ~camera:out.camera ~time ~frame
                 ~lights:out.lights prims
             with
             | Ok s ->
                 let files =
                   List.sort_uniq compare (List.map (scene_relative t) out.files)
                 in
                 Ok (s, List.map (fun f -> (f, input_digest t f)) files)
             | Error m -> Error [ Error.file_error t.file ("invalid scene: " ^ m) ]))

let scene_at ?body_state ?progress ?cancel t ~time ~frame =
  Result.map fst (scene_with_files ?body_state ?progress ?cancel t ~time ~frame)

(* ---------------------------------------------------------------------------------- *)
(* lancer check *)

let count_by key xs =
  let tbl = Hashtbl.create 8 and order = ref [] in
  List.iter
    (fun x ->
      let k = key x in
      match Hashtbl.find_opt tbl k with
      | Some n -> Hashtbl.replace tbl k (n + 1)
      | None ->
          Hashtbl.add tbl k 1;
          order := k :: !order)
    xs;
  List.rev_map (fun k -> (k, Hashtbl.find tbl k)) !order

let light_kind = function
  | Light.Point { spot = Some _; _ } as l when Light.is_area l -> "soft spot"
  | Light.Point { spot = Some _; _ } -> "spot"
  | Light.Point _ as l when Light.is_area l -> "area"
  | Light.Point p when p.radius > 0. -> "point (radius without samples: hard shadows)"
  | Light.Point _ -> "point"
  | Light.Directional _ -> "directional"

(* A CSG tree in one line: difference(box, sphere, union(sphere, sphere)). *)
let rec csg_tree (s : Shape.t) =
  match s with
  | Shape.Csg { members; _ } ->
      Printf.sprintf "%s(%s)" (Shape.name s)
        (String.concat ", "
           (Array.to_list
              (Array.map (fun (m : Shape.csg_member) -> csg_tree m.shape) members)))
  | s -> Shape.name s

let distinct_materials (sc : Scene.t) =
  let tbl = Hashtbl.create 16 in
  Array.iter
    (fun (o : Primitive.t) ->
      List.iter
        (fun (m : Material.t) ->
          let h = Hashtbl.hash m in
          let same = Hashtbl.find_all tbl h in
          if not (List.exists (fun m' -> m' == m || try m' = m with _ -> false) same)
          then Hashtbl.add tbl h m)
        (Primitive.materials o))
    sc.objects;
  Hashtbl.length tbl

let warnings t (sc : Scene.t) =
  let file msg = Error.file_error ~kind:Error.Warning t.file msg in
  let scene =
    if List.is_empty t.stmts then
      [ file "the scene is empty (no statements): it renders the background only" ]
    else
      (if Array.length sc.objects = 0 then
         [ file "the scene has no objects: the image is the background only" ]
       else [])
      @
      if Array.length sc.lights = 0 && Array.length sc.objects > 0 then
        [
          file
            "the scene has no lights: objects show only their ambient colour (add light \
             { position: (x, y, z) })";
        ]
      else []
  in
  chained_list t.includes t.first.warnings @ scene

let summary ?body_state:_ t (sc : Scene.t) =
  let s = sc.settings in
  let objs = Array.to_list sc.objects in
  let kinds = count_by (fun (o : Primitive.t) -> Shape.name o.shape) objs in
  let lights = count_by light_kind (Array.to_list sc.lights) in
  let list l =
    String.concat ", " (List.map (fun (k, n) -> Printf.sprintf "%s %d" k n) l)
  in
  let b = Buffer.create 256 in
  let line fmt =
    Printf.ksprintf
      (fun x ->
        Buffer.add_string b x;
        Buffer.add_char b '\n')
      fmt
  in
  line "scene: %s" t.file;
  let adaptive =
    if s.adaptive > 0. then
      Printf.sprintf "adaptive %g: 2×2 samples, %d×%d where they differ by more"
        s.adaptive (max s.samples 4) (max s.samples 4)
    else "adaptive off"
  in
  line "image: %d×%d, %d×%d samples per pixel (jitter %s, %s), depth %d" s.width s.height
    s.samples s.samples
    (if s.jitter then "on" else "off")
    adaptive s.depth;
  (let c = sc.camera in
   line "camera: %s%s%s" (Camera.kind_name c.kind)
     (match c.kind with
     | Camera.Orthographic { width } -> Printf.sprintf ", %g wide" width
     | Perspective | Fisheye -> Printf.sprintf ", fov %g°" c.fov)
     (if Camera.depth_of_field c then
        Printf.sprintf ", depth of field (aperture %g, focused at %g, %d×%d lens samples)"
          c.aperture c.focal_distance c.lens_samples c.lens_samples
      else ""));
  (match animation t with
  | Some (fps, n) ->
      line "animation: %d frames at %g fps (%g s); this is frame %d, time %g s" n fps
        (Float.of_int n /. fps)
        sc.frame sc.time
  | None -> line "animation: none (a still)");
  line "objects: %d%s" (List.length objs)
    (if kinds = [] then "" else " (" ^ list kinds ^ ")");
  (let trees =
     List.filter_map
       (fun (o : Primitive.t) ->
         if Primitive.is_csg o then Some (csg_tree o.shape) else None)
       objs
   in
   let shown = 4 in
   match trees with
   | [] -> ()
   | ts ->
       line "csg: %d object%s: %s%s" (List.length ts)
         (if List.length ts = 1 then "" else "s")
         (String.concat "; " (List.filteri (fun i _ -> i < shown) ts))
         (if List.length ts > shown then
            Printf.sprintf "; … and %d more" (List.length ts - shown)
          else ""));
  line "lights: %d%s" (Array.length sc.lights)
    (if lights = [] then "" else " (" ^ list lights ^ ")");
  line "materials: %d distinct" (distinct_materials sc);
  (match bodies t with
  | [] -> ()
  | bs ->
      line "bodies: %d (%s)" (List.length bs)
        (String.concat ", " (List.map (fun b -> b.name) bs)));
  let feats = Features.to_list sc.features @ [ ("bodies", bodies t <> []) ] in
  let pick b =
    List.filter_map
      (fun (k, v) ->
        if v = b then Some (String.map (fun c -> if c = '_' then ' ' else c) k) else None)
      feats
  in
  let used = pick true and skipped = pick false in
  line "renderer uses: %s"
    (if used = [] then "nothing beyond direct light" else String.concat ", " used);
  line "renderer skips: %s"
    (if skipped = [] then "nothing" else String.concat ", " skipped);
  List.iter (fun w -> Buffer.add_string b (Error.to_string w)) (warnings t sc);
  Buffer.contents b

let vj (v : Vec3.t) = `List [ `Float v.x; `Float v.y; `Float v.z ]
let cj (c : Color.t) = `List [ `Float c.r; `Float c.g; `Float c.b ]

let light_json = function
  | Light.Point p ->
      `Assoc
        ([
           ("kind", `String (if Option.is_some p.spot then "spot" else "point"));
           ("position", vj p.position);
           ("color", cj p.color);
           ("intensity", `Float p.intensity);
           ("attenuation", vj p.attenuation);
           ("radius", `Float p.radius);
           ("samples", `Int p.samples);
         ]
        @
        match p.spot with
        | None -> []
        | Some sp ->
            [
              ("point_at", vj sp.point_at);
              ("inner", `Float sp.inner);
              ("outer", `Float sp.outer);
            ])
  | Light.Directional d ->
      `Assoc
        [
          ("kind", `String "directional");
          ("direction", vj d.direction);
          ("color", cj d.color);
          ("intensity", `Float d.intensity);
        ]

let to_json ?body_state t (sc : Scene.t) =
  let s = sc.settings and c = sc.camera in
  let state =
    match body_state with
    | Some f -> Some f
    | None -> (
        try physics_state t ~time:sc.time with Sys.Break -> raise Sys.Break | _ -> None)
  in
  let now (b : body) =
    match Option.bind state (fun f -> f b.name sc.time) with
    | Some (p, v) -> [ ("position", vj p); ("velocity_now", vj v) ]
    | None -> [ ("position", vj b.center); ("velocity_now", vj b.velocity) ]
  in
  let objects =
    match guard t.file (fun () -> eval ?body_state t ~time:sc.time ~frame:sc.frame) with
    | Ok out ->
        List.map
          (fun (o : Eval.obj) ->
            `Assoc
              ([ ("kind", `String o.kind) ]
              @ Lazy.force o.fields
              @ [
                  ("transforms", `List o.transforms);
                  ("material", Lazy.force o.material_json);
                ]
              @ match o.body with Some n -> [ ("body", `String n) ] | None -> []))
          out.objects
    | Error _ -> []
  in
  let method_name = function Exact -> "exact" | Verlet -> "verlet" | Euler -> "euler" in
  `Assoc
    [
      ("file", `String t.file);
      ("time", `Float sc.time);
      ("frame", `Int sc.frame);
      ( "settings",
        `Assoc
          [
            ("width", `Int s.width);
            ("height", `Int s.height);
            ("depth", `Int s.depth);
            ("samples", `Int s.samples);
            ("jitter", `Bool s.jitter);
            ("adaptive", `Float s.adaptive);
            ("shadows", `Bool s.shadows);
            ( "background",
              match s.sky with
              | None -> cj s.background
              | Some sk ->
                  `Assoc
                    [
                      ("kind", `String "gradient");
                      ("horizon", cj sk.horizon);
                      ("zenith", cj sk.zenith);
                    ] );
            ( "fog",
              match s.fog with
              | None -> `Null
              | Some f ->
                  `Assoc [ ("color", cj f.color); ("distance", `Float f.distance) ] );
            ("ambient", cj s.ambient);
            ( "gamma",
              match s.gamma with
              | Settings.Srgb -> `String "srgb"
              | Settings.Power g -> `Float g );
          ] );
      ( "camera",
        `Assoc
          ([
             ("kind", `String (Camera.kind_name c.kind));
             ("position", vj c.position);
             ("look_at", vj c.look_at);
             ("up", vj c.up);
           ]
          @ (match c.kind with
            | Camera.Orthographic { width } -> [ ("width", `Float width) ]
            | Perspective | Fisheye -> [ ("fov", `Float c.fov) ])
          @ [
              ("aperture", `Float c.aperture);
              ("focal_distance", `Float c.focal_distance);
              ("lens_samples", `Int c.lens_samples);
            ]) );
      ( "animation",
        match animation t with
        | Some (fps, n) -> `Assoc [ ("fps", `Float fps); ("frames", `Int n) ]
        | None -> `Null );
      ("lights", `List (List.map light_json (Array.to_list sc.lights)));
      ("objects", `List objects);
      ( "bodies",
        `List
          (List.map
             (fun b ->
               `Assoc
                 ([
                    ("name", `String b.name);
                    ("center", vj b.center);
                    ("radius", `Float b.radius);
                    ("velocity", vj b.velocity);
                    ("mass", `Float b.mass);
                    ("restitution", `Float b.restitution);
                  ]
                 @ now b))
             (bodies t)) );
      ( "physics",
        match physics t with
        | Some p ->
            `Assoc
              [
                ("gravity", vj p.gravity);
                ("method", `String (method_name p.method_));
                ("step", `Float p.step);
              ]
        | None -> `Null );
      ( "features",
        `Assoc (List.map (fun (k, v) -> (k, `Bool v)) (Features.to_list sc.features)) );
    ]
