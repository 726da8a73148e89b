module Dsl = Lancer_dsl.Dsl
module D = Description

(* ---------------------------------------------------------------------------------- *)
(* Physics: the bodies move through the static objects of the scene at time 0. *)

exception Refused of Diagnostic.t

let at dsl (loc : Loc.t) msg = Diagnostic.make ?source:(Dsl.source dsl loc.file) loc msg

let colliders_of dsl =
  match Physics.colliders (Dsl.first dsl).objects with
  | Ok cs -> cs
  | Error o ->
      raise
        (Refused
           (at dsl o.loc
              (Printf.sprintf
                 "bodies cannot collide with this %s: physics follows a CSG object only \
                  when it is a union or merge of planes, parallelograms and boxes"
                 o.kind)))

(* The animation's duration; 0 for a still. *)
let duration dsl =
  match Dsl.animation dsl with Some (fps, n) -> Float.of_int n /. fps | None -> 0.

(* The motion of the bodies over [0, until]. *)
let simulation dsl ~until =
  let w = Option.value (Dsl.physics dsl) ~default:Physics.default_world in
  (* A fixed-step method keeps every step: refuse what would not fit in memory. *)
  let max_steps = 10_000_000. in
  (if w.method_ <> Physics.Exact && until /. w.step > max_steps then
     let msg =
       Printf.sprintf
         "the physics step %g s over %g s would take %.3g steps per body; the limit is \
          %.0f (use a larger step or the exact method)"
         w.step until (until /. w.step) max_steps
     in
     raise
       (Refused
          (match (Dsl.first dsl).physics_loc with
          | Some loc -> at dsl loc msg
          | None -> Diagnostic.file_error (Dsl.file dsl) msg)));
  Physics.simulate w (colliders_of dsl) (Dsl.bodies dsl) ~until

(* A loaded program and what it makes once for all its scenes: the images and meshes
   they read, the motion of its bodies once asked for, and its static part compiled. *)
type t = {
  dsl : Dsl.t;
  assets : Compile.assets;
  single : bool;  (** loaded for one scene only *)
  static : Compile.static option Lazy.t;
      (** the static part compiled, for an animation whose static statements build
          objects; forced under [lock] *)
  motion : Physics.trajectory Lazy.t;
      (** the simulation of the bodies over the animation (over no time for a still);
          forced under [lock] *)
  lock : Mutex.t;  (** over [static], [motion] and [on_disk] *)
  made : Compile.stream option Atomic.t;
      (** the load's objects, compiled as the load made them ({!Dsl.emitted}), until the
          scene at time 0, frame 0 takes them *)
  on_disk : (string, string) Hashtbl.t;
      (** the MD5 of input files this run has not decoded, as they were when asked *)
  colours : Diagnostic.t list;
      (** {!Scene_report.colour_warnings} of the scene at time 0, made at the load, before
          its objects may go *)
}

(* Whether the program's camera has an open shutter (at time 0): a still is then made at
   several instants ({!scenes}), which share its static part as an animation's frames do. *)
let blurred_dsl dsl = Camera.motion_blur (Dsl.first dsl).camera

let of_dsl ~single ?made assets dsl =
  let made = if Dsl.emitted dsl then made else None in
  {
    dsl;
    assets;
    single;
    static =
      lazy
        (match (Dsl.animation dsl, Dsl.static dsl) with
        | None, _ when not (blurred_dsl dsl) -> None
        | _, st when List.for_all (fun (_, objs) -> List.is_empty objs) st -> None
        | _, st -> Some (Compile.static assets st));
    motion = lazy (simulation dsl ~until:(duration dsl));
    lock = Mutex.create ();
    made = Atomic.make (Option.map fst made);
    on_disk = Hashtbl.create 4;
    colours =
      Dsl.located dsl ~time:0. ~frame:0
        (match made with
        | Some (_, colours) ->
            Scene_report.colour_warnings_of ~source:(Dsl.source dsl) colours
              (Dsl.first dsl).lights
        | None -> Scene_report.colour_warnings ~source:(Dsl.source dsl) (Dsl.first dsl));
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

(* A program loaded for one scene ([single]) that is a still has its objects compiled as
   its load makes them (and their colours noted), instead of a description of them all
   held until the scene is compiled: a large scene is never held twice, and the
   collector never has to follow the description. *)
let loaded ~single a load =
  if single then
    let made = Compile.stream a and colours = Scene_report.colours () in
    let emit o =
      Compile.add made o;
      Scene_report.note_object colours o
    in
    Result.map (of_dsl ~single ~made:(made, colours) a) (load ~emit:(Some emit))
  else Result.map (of_dsl ~single a) (load ~emit:None)

let load_file ?(single = false) ?(digests = true) ?after_read path =
  let a = Compile.assets ~digests ?after_read () in
  loaded ~single a (fun ~emit -> Dsl.load_file ~files:(Compile.check_files a) ?emit path)

let load_string ?(single = false) ?progress ?(digests = true) ?after_read ?filename text =
  let a = Compile.assets ~digests ?after_read () in
  loaded ~single a (fun ~emit ->
      Dsl.load_string ?progress ~files:(Compile.check_files a) ?emit ?filename text)

let load_bundle ?(single = false) ?progress ?(digests = true) b =
  let a = Compile.assets ~digests () in
  loaded ~single a (fun ~emit ->
      Dsl.load_bundle ?progress ~files:(Compile.check_files a) ?emit b)

(* What a record says of an input: the digest of the bytes this run decoded, or, for a
   file it has not decoded (yet), of the file on disk, once. *)
let input_digest p rel =
  let path = Loc.relative_to (file p) rel in
  match Compile.digest p.assets path with
  | Some d -> d
  | None ->
      Mutex.protect p.lock (fun () ->
          match Hashtbl.find_opt p.on_disk path with
          | Some d -> d
          | None ->
              let d = try Digest.to_hex (Digest.file path) with Sys_error _ -> "-" in
              Hashtbl.replace p.on_disk path d;
              d)

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
(* Physics *)

let colliders p = colliders_of p.dsl

(* The simulation that samples [time]: the animation's, made once, or for a later time
   one of its own (which would sample the animation's times as the animation's does). *)
let trajectory p ~time =
  if time <= duration p.dsl then Mutex.protect p.lock (fun () -> Lazy.force p.motion)
  else simulation p.dsl ~until:time

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

(* The bodies where the simulation has them at [time], unless [body_state] says. *)
let body_state_at ?body_state p ~time ~frame =
  Result.map_error
    (Dsl.located p.dsl ~time ~frame)
    (guard p (fun () ->
         Ok (match body_state with Some f -> Some f | None -> physics_state p ~time)))

let describe ?body_state ?progress ?cancel p ~time ~frame =
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
  | None ->
      Result.bind (body_state_at ?body_state p ~time ~frame) (fun body_state ->
          Dsl.describe ?body_state ?progress ?cancel
            ~files:(Compile.check_files p.assets)
            p.dsl ~time ~frame)

(* ---------------------------------------------------------------------------------- *)
(* Scenes *)

(* The static part compiled, made by the first scene that asks. *)
let static p = Mutex.protect p.lock (fun () -> Lazy.force p.static)
let blurred p = blurred_dsl p.dsl

(* The scene [make] compiles of [d], its problems located as the program's. *)
let compiled p (d : D.t) make =
  Result.map_error
    (Dsl.located p.dsl ~time:d.time ~frame:d.frame)
    (guard p (fun () -> make ~source:(Dsl.source p.dsl)))

let compile ?progress ?index ?static ?objects ?parts p (d : D.t) =
  compiled p d (fun ~source ->
      Compile.compile ~source ?progress ?index ?static ?objects ?parts p.assets d)

(* The scene at [time] and [frame], and its description (without its objects when they
   were handed to the compile, or given as parts).

   A program loaded for one scene ([single]) whose load compiled its objects as it made
   them ({!loaded}) has them made into the scene at time 0, frame 0. Otherwise it has its
   load's description compiled for a still at time 0, frame 0: the program lets its
   objects go ({!Dsl.release}), and the compile lets each go as it is made into
   primitives, so that a large scene is not held twice. An animation's scenes (those
   indexed) are the static part, compiled once, joined with what the other statements
   build at that instant. Any other scene is described, then compiled. *)
let scene_and_description ?body_state ?progress ?cancel ?(index = true) p ~time ~frame =
  let at_load =
    p.single && body_state = None && Float.equal time 0. && frame = 0
    && Dsl.animation p.dsl = None
    && (not (blurred p))
    && Dsl.bodies p.dsl = []
  in
  (* Taken by the first scene that asks (any other, or a later one, evaluates the
     program again). *)
  let made = Atomic.exchange p.made None in
  let released = if at_load then Dsl.release p.dsl else None in
  match (made, released) with
  | Some made, _ when at_load ->
      let d = Dsl.first p.dsl in
      Result.map
        (fun sc -> (sc, d))
        (compiled p d (fun ~source -> Compile.finish ~source ?progress ~index made d))
  | _, Some d ->
      let objects = d.objects and d = { d with objects = [] } in
      Result.map (fun sc -> (sc, d)) (compile ?progress ~index ~objects p d)
  | _, None -> (
      match if index then guard p (fun () -> Ok (static p)) else Ok None with
      | Error es -> Error (Dsl.located p.dsl ~time ~frame es)
      | Ok (Some static) ->
          Result.bind (body_state_at ?body_state p ~time ~frame) (fun body_state ->
              Result.bind
                (Dsl.describe_parts ?body_state ?progress ?cancel
                   ~files:(Compile.check_files p.assets)
                   p.dsl ~time ~frame)
                (fun (d, parts) ->
                  Result.map
                    (fun sc -> (sc, d))
                    (compile ?progress ~index ~static ~parts p d)))
      | Ok None ->
          Result.bind (describe ?body_state ?progress ?cancel p ~time ~frame) (fun d ->
              Result.map (fun sc -> (sc, d)) (compile ?progress ~index p d)))

let scene ?body_state ?progress ?cancel ?index p ~time ~frame =
  Result.map fst
    (scene_and_description ?body_state ?progress ?cancel ?index p ~time ~frame)

let scene_at = scene

let scenes ?body_state ?progress ?cancel ?index p ~times ~frame =
  let n = Array.length times in
  let rec go k acc =
    if k = n then Ok (Array.of_list (List.rev acc))
    else
      match scene ?body_state ?progress ?cancel ?index p ~time:times.(k) ~frame with
      | Ok sc -> go (k + 1) (sc :: acc)
      | Error es -> Error es
  in
  go 0 []

let scene_with_files ?body_state ?progress ?cancel p ~time ~frame =
  Result.map
    (fun (sc, (d : D.t)) ->
      let files = List.sort_uniq compare (List.map (Dsl.scene_relative p.dsl) d.files) in
      (sc, files))
    (scene_and_description ?body_state ?progress ?cancel p ~time ~frame)

(* {!scene_with_files} at each of [times], in order, up to the first that fails. *)
let scenes_with_files ?body_state ?progress ?cancel p ~times ~frame =
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

(* What check prints beside the scene: the program's animation, bodies, physics and
   warnings (those at time 0). *)
let for_report p (d : D.t) =
  let f = Dsl.first p.dsl in
  {
    d with
    animation = f.animation;
    bodies = f.bodies;
    physics = f.physics;
    warnings = f.warnings @ p.colours;
  }

let rendered p sc = Compile.rendered p.assets sc

(* The description [sc] was made from, described again; at time 0, frame 0 of a program
   that let its objects go, the load's without them (all a summary reads). *)
let description p (sc : Scene.t) =
  if Float.equal sc.time 0. && sc.frame = 0 && Dsl.released p.dsl then
    Some (Dsl.first p.dsl)
  else Result.to_option (describe p ~time:sc.time ~frame:sc.frame)

let summary p (sc : Scene.t) =
  match description p sc with
  | Some d ->
      Scene_report.summary ~empty:(Dsl.empty p.dsl) (for_report p d) (rendered p sc)
  | None -> ""

(* The warnings read nothing of the description at [sc]'s time but its file: the
   program's at time 0 serve, without evaluating it again; and of the scene only its
   counts, without listing its objects as a summary does. *)
let warnings p (sc : Scene.t) =
  Scene_report.warnings ~empty:(Dsl.empty p.dsl) ~objects:(Scene.object_count sc)
    ~lights:(Array.length sc.lights)
    (for_report p (Dsl.first p.dsl))

let to_json ?body_state p (sc : Scene.t) =
  let d =
    match describe p ~time:sc.time ~frame:sc.frame with
    | Ok d -> d
    | Error _ -> { (Dsl.first p.dsl) with objects = []; time = sc.time; frame = sc.frame }
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

let as_scenes ~builtin p : Scenes.t =
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
