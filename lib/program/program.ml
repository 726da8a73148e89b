module Dsl = Lancer_dsl.Dsl
module D = Description

(* A loaded program and what it keeps beside it: the images and meshes its scenes read,
   the motion of its bodies once asked for, and the description of the last scene made
   (for check's printers). *)
type t = {
  dsl : Dsl.t;
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

let of_dsl assets dsl =
  {
    dsl;
    assets;
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

let language p = p.dsl
let assets p = p.assets
let file p = Dsl.file p.dsl
let animation p = Dsl.animation p.dsl
let bodies p = Dsl.bodies p.dsl
let empty p = Dsl.empty p.dsl
let inputs p = Dsl.inputs p.dsl
let named_files p = Dsl.named_files p.dsl
let text_digest p = Dsl.text_digest p.dsl
let source_problem = Dsl.source_problem

type bundle = Dsl.bundle

let bundle p = Dsl.bundle p.dsl

let load_file ?(digests = true) ?after_read path =
  let a = Compile.assets ~digests ?after_read () in
  Result.map (of_dsl a) (Dsl.load_file ~files:(Compile.check_files a) path)

let load_string ?progress ?(digests = true) ?after_read ?filename text =
  let a = Compile.assets ~digests ?after_read () in
  Result.map (of_dsl a)
    (Dsl.load_string ?progress ~files:(Compile.check_files a) ?filename text)

let load_bundle ?progress ?(digests = true) b =
  let a = Compile.assets ~digests () in
  Result.map (of_dsl a) (Dsl.load_bundle ?progress ~files:(Compile.check_files a) b)

(* What a record says of an input: the digest of the bytes this run decoded, or, for a
   file it has not decoded (yet), of the file on disk, once. *)
let input_digest p rel =
  let path = Loc.relative_to (file p) rel in
  match Compile.digest p.assets path with
  | Some d -> d
  | None ->
      Mutex.protect p.disk_lock (fun () ->
          match Hashtbl.find_opt p.on_disk path with
          | Some d -> d
          | None ->
              let d = try Digest.to_hex (Digest.file path) with Sys_error _ -> "-" in
              Hashtbl.replace p.on_disk path d;
              d)

exception Refused of Diagnostic.t

let at p (loc : Loc.t) msg = Diagnostic.make ?source:(Dsl.source p.dsl loc.file) loc msg

(* Nothing raised below reaches the caller but an interrupt, as in the language. *)
let guard p f =
  try f () with
  | Sys.Break -> raise Sys.Break
  | Refused e -> Error [ e ]
  | Stack_overflow ->
      Error
        [
          Diagnostic.file_error (Dsl.file p.dsl)
            "the scene is nested too deeply (the evaluator's stack overflowed)";
        ]
  | Out_of_memory ->
      Error
        [
          Diagnostic.file_error (Dsl.file p.dsl)
            "the scene needs more memory than is available";
        ]
  | e ->
      Error
        [
          Diagnostic.file_error (Dsl.file p.dsl)
            ("internal error: " ^ Printexc.to_string e ^ " (please report it)");
        ]

(* ---------------------------------------------------------------------------------- *)
(* Physics: the bodies move through the static objects of the scene at time 0. *)

let colliders p =
  match Physics.colliders (Dsl.first p.dsl).objects with
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
    match Dsl.animation p.dsl with Some (fps, n) -> Float.of_int n /. fps | None -> 0.
  in
  Float.max dur time

let trajectory p ~time =
  let until = horizon p time in
  let e = p in
  Mutex.protect e.motion_lock (fun () ->
      match e.motion with
      | Some (h, tr) when h >= until -> tr
      | _ ->
          let w = Option.value (Dsl.physics p.dsl) ~default:Physics.default_world in
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
                  (match (Dsl.first p.dsl).physics_loc with
                  | Some loc -> at p loc msg
                  | None -> Diagnostic.file_error (Dsl.file p.dsl) msg)));
          let tr = Physics.simulate w (colliders p) (Dsl.bodies p.dsl) ~until in
          e.motion <- Some (until, tr);
          tr)

let simulate p ~until =
  Result.map_error
    (Dsl.located p.dsl ~time:0. ~frame:0)
    (guard p (fun () -> Ok (trajectory p ~time:until)))

let physics_state p ~time =
  match Dsl.bodies p.dsl with
  | [] -> None
  | _ ->
      let tr = trajectory p ~time in
      Some (fun name s -> Physics.sample tr name s)

(* The description at time 0, frame 0 is the one the load made, each body placed where
   the simulation has it at time 0 (its initial centre): evaluated again only if the
   simulation says otherwise. *)
let first_at_rest p =
  let first = Dsl.first p.dsl in
  match first.bodies with
  | _ when Dsl.released p.dsl -> None
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
      | Error es -> Some (Error (Dsl.located p.dsl ~time ~frame es))
    else None
  in
  match reused with
  | Some r -> r
  | None -> (
      match
        guard p (fun () ->
            Ok (match body_state with Some f -> Some f | None -> physics_state p ~time))
      with
      | Error es -> Error (Dsl.located p.dsl ~time ~frame es)
      | Ok body_state ->
          Dsl.describe ?again ?body_state ?progress ?cancel ?parts
            ~files:(Compile.check_files p.assets)
            p.dsl ~time ~frame)

let describe ?body_state ?progress ?cancel p ~time ~frame =
  describe_ ?body_state ?progress ?cancel p ~time ~frame

(* ---------------------------------------------------------------------------------- *)
(* Scenes *)

(* Whether the program's camera has an open shutter (at time 0): a still is then made at
   several instants ({!scenes}). *)
let blurred p = Camera.motion_blur (Dsl.first p.dsl).camera

(* The objects no frame changes, made once for the frames of an animation or the
   instants of a blurred still (another still is made once anyway). *)
let fixed p =
  let e = p in
  Mutex.protect e.fixed_lock (fun () ->
      match e.fixed with
      | Some f -> f
      | None ->
          let f =
            match (Dsl.animation p.dsl, Dsl.fixed_pieces p.dsl) with
            | None, _ when not (blurred p) -> None
            | _, pieces when List.for_all List.is_empty pieces -> None
            | _, pieces -> Some (Compile.fixed e.assets pieces)
          in
          e.fixed <- Some f;
          f)

let compile ?progress ?index ?objects ?parts ~share p (d : D.t) =
  (* [objects] is not used after the compile, which lets each go as it is compiled. *)
  let whole = Option.is_none objects && Option.is_none parts in
  match
    guard p (fun () ->
        Compile.compile ~source:(Dsl.source p.dsl) ?progress
          ?fixed:(if share && index <> Some false then fixed p else None)
          ?index ?objects ?parts p.assets d)
  with
  | Ok sc ->
      let e = p in
      Mutex.protect e.lock (fun () -> e.last <- Some (sc, d, whole));
      Ok sc
  | Error es -> Error (Dsl.located p.dsl ~time:d.time ~frame:d.frame es)

let single_scene p = p.single <- true

(* A still's one scene, where its caller asked for one only ({!single_scene}), is the
   load's description compiled once: the program lets its objects go ({!Dsl.release}),
   and the compile lets each go as it is made into primitives, so that a large scene is
   not held twice. A caller that asks for more scenes of a still (the live preview, the
   benchmarks) keeps the load's description for them. *)
let releasable ?body_state p ~share ~time ~frame =
  p.single && (not share) && body_state = None && Float.equal time 0. && frame = 0
  && Dsl.animation p.dsl = None
  && (not (blurred p))
  && Dsl.bodies p.dsl = []
  && not (Dsl.released p.dsl)

(* The scenes of an animated program share what does not change, from the first one on:
   the statements that do not depend on the instant are not evaluated again, and the
   objects they build are compiled and indexed once, as a part of their own (the first
   scene made the long way would build that index twice: once over every object, once
   over the fixed ones). A program without an animation has no such part: its first
   scene is made the long way, every statement evaluated. *)
let scene_and_description ?body_state ?progress ?cancel ?index p ~time ~frame =
  let later = Atomic.fetch_and_add p.made 1 > 0 in
  let share = later || Option.is_some (Dsl.animation p.dsl) in
  if releasable ?body_state p ~share ~time ~frame then
    let d = Dsl.release p.dsl in
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
      let files = List.sort_uniq compare (List.map (Dsl.scene_relative p.dsl) d.files) in
      (sc, files))
    (scene_and_description ?body_state ?progress ?cancel p ~time ~frame)

let scene_at ?body_state ?progress ?cancel ?index p ~time ~frame =
  Result.map fst
    (scene_and_description ?body_state ?progress ?cancel ?index p ~time ~frame)

(* In order, up to the first that fails. *)
let scenes ?body_state ?progress ?cancel p ~times ~frame =
  let rec go acc = function
    | [] -> Ok (Array.of_list (List.rev acc))
    | time :: rest -> (
        match scene_with_files ?body_state ?progress ?cancel p ~time ~frame with
        | Ok r -> go (r :: acc) rest
        | Error es -> Error es)
  in
  go [] (Array.to_list times)

(* ---------------------------------------------------------------------------------- *)
(* lancer check *)

(* The description [sc] was made from: the last one compiled, or made again (for
   [objects], when the one compiled let its objects go). *)
let description ?(objects = false) p (sc : Scene.t) =
  let e = p in
  match Mutex.protect e.lock (fun () -> e.last) with
  | Some (s, d, whole) when s == sc && (whole || not objects) -> Some d
  | _ -> (
      match describe p ~time:sc.time ~frame:sc.frame with
      | Ok d -> Some d
      | Error _ -> None)

(* What check prints beside the scene: the program's animation, bodies, physics and
   warnings (those at time 0). *)
let for_report p (d : D.t) =
  let f = Dsl.first p.dsl in
  {
    d with
    animation = f.animation;
    bodies = f.bodies;
    physics = f.physics;
    warnings = f.warnings;
  }

let rendered p sc = Compile.rendered p.assets sc

let summary p (sc : Scene.t) =
  match description p sc with
  | Some d -> Scene_report.summary ~empty:(Dsl.empty p.dsl) (for_report p d) (rendered p sc)
  | None -> ""

let to_json ?body_state p (sc : Scene.t) =
  let d =
    match description ~objects:true p sc with
    | Some d -> d
    | None -> { (Dsl.first p.dsl) with objects = []; time = sc.time; frame = sc.frame }
  in
  let state =
    match body_state with
    | Some f -> Some f
    | None -> (
        try physics_state p ~time:sc.time with Sys.Break -> raise Sys.Break | _ -> None)
  in
  Scene_report.json ?state (for_report p d) (rendered p sc)

(* ---------------------------------------------------------------------------------- *)
(* For the command line and the job layer *)

let truncated_physics p =
  if bodies p = [] then None
  else
    match simulate p ~until:0. with
    | Ok tr when Physics.truncated tr ->
        Some (match List.rev (Physics.events tr) with e :: _ -> e.time | [] -> 0.)
    | _ -> None

let source ~builtin p : Source.t =
  {
    file = file p;
    builtin;
    animation = animation p;
    evaluate =
      (fun ~progress ~cancel ~time ~frame ->
        match scene_with_files ?progress ?cancel p ~time ~frame with
        | Ok r -> r
        | Error errors -> raise (Job_error.Scene { errors; note = "" }));
    inputs = (fun () -> inputs p);
    names = (fun () -> named_files p);
    text_digest = (fun () -> text_digest p);
    input_digest = input_digest p;
  }
