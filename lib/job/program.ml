module Dsl = Lancer_dsl.Dsl
module D = Description

(* What a loaded program keeps beside it: the images and meshes its scenes read, the
   motion of its bodies once asked for, and the description of the last scene made (for
   check's printers). *)
type extra = {
  assets : Compile.assets;
  mutable last : (Scene.t * D.t * bool) option;
      (** and whether the description has its objects (they are let go as they are
          compiled when a still is made from the load's description) *)
  mutable motion : (float * Physics.trajectory) option;
      (** the simulation of the bodies and the horizon it was computed for *)
  lock : Mutex.t;
  motion_lock : Mutex.t;
  mutable fixed : Compile.fixed option option;
      (** what the frames of an animation share, once made ([Some None]: nothing) *)
  fixed_lock : Mutex.t;
  made : int Atomic.t;  (** scenes begun *)
  mutable single : bool;  (** asked for one scene only ({!single_scene}) *)
  on_disk : (string, string) Hashtbl.t;
      (** the MD5 of input files this run has not decoded, as they were when asked *)
  disk_lock : Mutex.t;
}

module Programs = Ephemeron.K1.Make (struct
  type t = Dsl.t

  let equal = ( == )
  let hash p = Hashtbl.hash (Dsl.file p)
end)

let table = Programs.create 4
let table_lock = Mutex.create ()

let extra p =
  Mutex.protect table_lock (fun () ->
      match Programs.find_opt table p with
      | Some e -> e
      | None ->
          let e =
            {
              assets = Compile.assets ();
              last = None;
              motion = None;
              lock = Mutex.create ();
              motion_lock = Mutex.create ();
              fixed = None;
              fixed_lock = Mutex.create ();
              made = Atomic.make 0;
              single = false;
              on_disk = Hashtbl.create 4;
              disk_lock = Mutex.create ();
            }
          in
          Programs.replace table p e;
          e)

let assets p = (extra p).assets

(* A program loaded with the cache its files were read into. *)
let adopt assets r =
  Result.iter
    (fun p ->
      let e = extra p in
      Mutex.protect table_lock (fun () -> Programs.replace table p { e with assets }))
    r;
  r

let load_file ?(digests = true) ?after_read path =
  let a = Compile.assets ~digests ?after_read () in
  adopt a (Dsl.load_file ~files:(Compile.check_files a) path)

let load_string ?progress ?(digests = true) ?after_read ?filename text =
  let a = Compile.assets ~digests ?after_read () in
  adopt a (Dsl.load_string ?progress ~files:(Compile.check_files a) ?filename text)

let load_bundle ?progress ?(digests = true) b =
  let a = Compile.assets ~digests () in
  adopt a (Dsl.load_bundle ?progress ~files:(Compile.check_files a) b)

(* What a record says of an input: the digest of the bytes this run decoded, or, for a
   file it has not decoded (yet), of the file on disk, once. *)
let input_digest p rel =
  let path = Loc.relative_to (Dsl.file p) rel in
  let e = extra p in
  match Compile.digest e.assets path with
  | Some d -> d
  | None ->
      Mutex.protect e.disk_lock (fun () ->
          match Hashtbl.find_opt e.on_disk path with
          | Some d -> d
          | None ->
              let d =
                try Digest.to_hex (Digest.file path) with Sys_error _ -> "-"
              in
              Hashtbl.replace e.on_disk path d;
              d)

exception Refused of Diagnostic.t

let at p (loc : Loc.t) msg = Diagnostic.make ?source:(Dsl.source p loc.file) loc msg

(* Nothing raised below reaches the caller but an interrupt, as in the language. *)
let guard p f =
  try f () with
  | Sys.Break -> raise Sys.Break
  | Refused e -> Error [ e ]
  | Stack_overflow ->
      Error
        [
          Diagnostic.file_error (Dsl.file p)
            "the scene is nested too deeply (the evaluator's stack overflowed)";
        ]
  | Out_of_memory ->
      Error
        [
          Diagnostic.file_error (Dsl.file p)
            "the scene needs more memory than is available";
        ]
  | e ->
      Error
        [
          Diagnostic.file_error (Dsl.file p)
            ("internal error: " ^ Printexc.to_string e ^ " (please report it)");
        ]

(* ---------------------------------------------------------------------------------- *)
(* Physics: the bodies move through the static objects of the scene at time 0. *)

let colliders p =
  match Physics.colliders (Dsl.first p).objects with
  | Ok cs -> cs
  | Error o ->
      raise
        (Refused
           (at p o.loc
              (Printf.sprintf
                 "bodies cannot collide with this %s: physics follows a CSG object only \
                  when it is a union or merge of planes, parallelograms and boxes"
                 o.kind)))

(* The horizon for a frame at [time]: the whole animation, or [time] when later. *)
let horizon p time =
  let dur =
    match Dsl.animation p with Some (fps, n) -> Float.of_int n /. fps | None -> 0.
  in
  Float.max dur time

let trajectory p ~time =
  let until = horizon p time in
  let e = extra p in
  Mutex.protect e.motion_lock (fun () ->
      match e.motion with
      | Some (h, tr) when h >= until -> tr
      | _ ->
          let w = Option.value (Dsl.physics p) ~default:Physics.default_world in
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
                  (match (Dsl.first p).physics_loc with
                  | Some loc -> at p loc msg
                  | None -> Diagnostic.file_error (Dsl.file p) msg)));
          let tr = Physics.simulate w (colliders p) (Dsl.bodies p) ~until in
          e.motion <- Some (until, tr);
          tr)

let simulate p ~until =
  Result.map_error
    (Dsl.located p ~time:0. ~frame:0)
    (guard p (fun () -> Ok (trajectory p ~time:until)))

let physics_state p ~time =
  match Dsl.bodies p with
  | [] -> None
  | _ ->
      let tr = trajectory p ~time in
      Some (fun name s -> Physics.sample tr name s)

(* The description at time 0, frame 0 is the one the load made, each body placed where
   the simulation has it at time 0 (its initial centre): evaluated again only if the
   simulation says otherwise. *)
let first_at_rest p =
  let first = Dsl.first p in
  match first.bodies with
  | _ when Dsl.released p -> None
  | [] -> Some first
  | bodies -> (
      match physics_state p ~time:0. with
      | None -> Some first
      | Some state ->
          let bits x = Int64.bits_of_float x in
          let same (a : Vec3.t) (b : Vec3.t) =
            bits a.x = bits b.x && bits a.y = bits b.y && bits a.z = bits b.z
          in
          let states = List.map (fun (b : D.body) -> (b, state b.name 0.)) bodies in
          let at_rest ((b : D.body), st) =
            match st with
            | Some (q, v) -> same q b.center && same v b.velocity
            | None -> true
          in
          let place (o : D.obj) =
            match o.body with
            | None -> o
            | Some name -> (
                match List.find_opt (fun ((b : D.body), _) -> b.name = name) states with
                | Some (b, Some (q, _)) ->
                    {
                      o with
                      transform =
                        Transform.then_ o.transform
                          (Transform.translate (Vec3.sub q b.center));
                    }
                | _ -> o)
          in
          if List.for_all at_rest states then
            Some { first with objects = List.map place first.objects }
          else None)

let describe_ ?again ?body_state ?progress ?cancel ?parts p ~time ~frame =
  let reused =
    if Float.equal time 0. && frame = 0 && body_state = None then
      match guard p (fun () -> Ok (first_at_rest p)) with
      | Ok (Some d) -> Some (Ok d)
      | Ok None -> None
      | Error es -> Some (Error (Dsl.located p ~time ~frame es))
    else None
  in
  match reused with
  | Some r -> r
  | None -> (
      match
        guard p (fun () ->
            Ok (match body_state with Some f -> Some f | None -> physics_state p ~time))
      with
      | Error es -> Error (Dsl.located p ~time ~frame es)
      | Ok body_state ->
          Dsl.describe ?again ?body_state ?progress ?cancel ?parts
            ~files:(Compile.check_files (assets p))
            p ~time ~frame)

let describe ?body_state ?progress ?cancel p ~time ~frame =
  describe_ ?body_state ?progress ?cancel p ~time ~frame

(* ---------------------------------------------------------------------------------- *)
(* Scenes *)

(* The objects no frame changes, made once for the frames of an animation (a still is
   made once anyway). *)
let fixed p =
  let e = extra p in
  Mutex.protect e.fixed_lock (fun () ->
      match e.fixed with
      | Some f -> f
      | None ->
          let f =
            match (Dsl.animation p, Dsl.fixed_pieces p) with
            | None, _ -> None
            | Some _, pieces when List.for_all List.is_empty pieces -> None
            | Some _, pieces -> Some (Compile.fixed e.assets pieces)
          in
          e.fixed <- Some f;
          f)

let compile ?progress ?index ?objects ?parts ~share p (d : D.t) =
  (* [objects] is not used after the compile, which lets each go as it is compiled. *)
  let whole = Option.is_none objects && Option.is_none parts in
  match
    guard p (fun () ->
        Compile.compile ~source:(Dsl.source p) ?progress
          ?fixed:(if share && index <> Some false then fixed p else None)
          ?index ?objects ?parts (assets p) d)
  with
  | Ok sc ->
      let e = extra p in
      Mutex.protect e.lock (fun () -> e.last <- Some (sc, d, whole));
      Ok sc
  | Error es -> Error (Dsl.located p ~time:d.time ~frame:d.frame es)

let single_scene p = (extra p).single <- true

(* A still's one scene, where its caller asked for one only ({!single_scene}), is the
   load's description compiled once: the program lets its objects go ({!Dsl.release}),
   and the compile lets each go as it is made into primitives, so that a large scene is
   not held twice. A caller that asks for more scenes of a still (the live preview, the
   benchmarks) keeps the load's description for them. *)
let releasable ?body_state p ~share ~time ~frame =
  (extra p).single && (not share) && body_state = None && Float.equal time 0. && frame = 0
  && Dsl.animation p = None
  && Dsl.bodies p = []
  && not (Dsl.released p)

(* The scenes of an animated program share what does not change, from the first one on:
   the statements that do not depend on the instant are not evaluated again, and the
   objects they build are compiled and indexed once, as a part of their own (the first
   scene made the long way would build that index twice: once over every object, once
   over the fixed ones). A program without an animation has no such part: its first
   scene is made the long way, every statement evaluated. *)
let scene_and_description ?body_state ?progress ?cancel ?index p ~time ~frame =
  let later = Atomic.fetch_and_add (extra p).made 1 > 0 in
  let share = later || Option.is_some (Dsl.animation p) in
  if releasable ?body_state p ~share ~time ~frame then
    let d = Dsl.release p in
    let objects = d.objects and d = { d with objects = [] } in
    Result.map (fun sc -> (sc, d)) (compile ?progress ?index ~objects ~share p d)
  else
    (* Shared statements replayed: their objects come as the lists the fixed part was
       made from, not copied into one list per scene. *)
    let parts = ref None in
    let on_parts = if share then Some (fun ps -> parts := Some ps) else None in
    Result.bind
      (describe_ ~again:(not share) ?body_state ?progress ?cancel ?parts:on_parts p ~time
         ~frame) (fun d ->
        Result.map (fun sc -> (sc, d)) (compile ?progress ?index ?parts:!parts ~share p d))

let scene_with_files ?body_state ?progress ?cancel p ~time ~frame =
  Result.map
    (fun (sc, (d : D.t)) ->
      let files = List.sort_uniq compare (List.map (Dsl.scene_relative p) d.files) in
      (sc, files))
    (scene_and_description ?body_state ?progress ?cancel p ~time ~frame)

let scene_at ?body_state ?progress ?cancel ?index p ~time ~frame =
  Result.map fst
    (scene_and_description ?body_state ?progress ?cancel ?index p ~time ~frame)

(* ---------------------------------------------------------------------------------- *)
(* lancer check *)

(* The description [sc] was made from: the last one compiled, or made again (for
   [objects], when the one compiled let its objects go). *)
let description ?(objects = false) p (sc : Scene.t) =
  let e = extra p in
  match Mutex.protect e.lock (fun () -> e.last) with
  | Some (s, d, whole) when s == sc && (whole || not objects) -> Some d
  | _ -> (
      match describe p ~time:sc.time ~frame:sc.frame with
      | Ok d -> Some d
      | Error _ -> None)

(* What check prints beside the scene: the program's animation, bodies, physics and
   warnings (those at time 0). *)
let for_report p (d : D.t) =
  let f = Dsl.first p in
  {
    d with
    animation = f.animation;
    bodies = f.bodies;
    physics = f.physics;
    warnings = f.warnings;
  }

let rendered p sc = Compile.rendered (assets p) sc

let summary p (sc : Scene.t) =
  match description p sc with
  | Some d -> Scene_report.summary ~empty:(Dsl.empty p) (for_report p d) (rendered p sc)
  | None -> ""

let to_json ?body_state p (sc : Scene.t) =
  let d =
    match description ~objects:true p sc with
    | Some d -> d
    | None -> { (Dsl.first p) with objects = []; time = sc.time; frame = sc.frame }
  in
  let state =
    match body_state with
    | Some f -> Some f
    | None -> (
        try physics_state p ~time:sc.time with Sys.Break -> raise Sys.Break | _ -> None)
  in
  Scene_report.json ?state (for_report p d) (rendered p sc)
