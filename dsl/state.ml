module D = Description
open Value

let max_objects = D.max_objects
let max_steps = 20_000_000
let max_depth = 1000

(* Address space one object costs while the scene is built and rendered: 200 000 spheres
   took 462 MB at their peak (the objects, the garbage collector's free space, the
   BVH), 2.3 KB each; with a margin. *)
let bytes_per_object = 2560

(* What the runtime reserves before any object: the minor heaps of the 128 domains it could
   run (256 MB at the default size), and the program itself. *)
let baseline_bytes = 320_000_000

let memory_refusal st objects =
  match st.hooks.address_limit with
  | Some limit
    when Float.of_int objects *. Float.of_int bytes_per_object
         > Float.of_int (limit - baseline_bytes) ->
      Some
        (Msg.memory ~objects ~limit ~baseline:baseline_bytes ~per_object:bytes_per_object)
  | _ -> None

let seen st (loc : Loc.t) msg =
  let key = (loc.file, loc.line, loc.col, msg) in
  Hashtbl.mem st.out.seen key
  ||
  (Hashtbl.add st.out.seen key ();
   false)

let report st (loc : Loc.t) msg =
  if not (seen st loc msg) then
    st.out.errors <-
      Error.make ?source:(Hashtbl.find_opt st.hooks.sources loc.file) loc msg
      :: st.out.errors

let warn st (loc : Loc.t) msg =
  if not (seen st loc ("warning: " ^ msg)) then
    st.out.warnings <-
      Error.warning ?source:(Hashtbl.find_opt st.hooks.sources loc.file) loc msg
      :: st.out.warnings

let use_path : D.file_use -> string = function
  | Picture im -> im.path
  | Model { path; _ } | Heights { path; _ } -> path

let use st u =
  Hashtbl.replace st.out.used (use_path u) ();
  st.hooks.on_file u

let create ?body_state ?on_objects ?cancel ~on_file ~sources ~time ~frame () =
  let rec st =
    {
      hooks =
        {
          time;
          time_v = VNum time;
          frame_v = VNum (Float.of_int frame);
          body_state;
          on_objects;
          on_file;
          cancel;
          address_limit = Address_space.limit ();
          sources;
        };
      count = { objects = 0; steps = 0; loops = 1.; depth = 0 };
      out =
        {
          errors = [];
          warnings = [];
          seen = Hashtbl.create 16;
          settings = None;
          camera = None;
          animation = None;
          physics = None;
          lights = [];
          bodies = [];
          used = Hashtbl.create 4;
        };
      tell =
        {
          report = (fun loc msg -> report st loc msg);
          use = (fun u -> use st u);
          share = Value.sharing ();
        };
    }
  in
  st

let limit st loc msg =
  report st loc msg;
  raise Abort

(* An interrupt is felt here too: evaluation may run where a signal does not raise at
   once (inside a pool of domains). *)
let poll st loc =
  if st.count.steps land 4095 = 0 then Option.iter Cancel.check st.hooks.cancel;
  if st.count.steps > max_steps then limit st loc (Msg.steps_limit max_steps)

let[@inline] step st loc =
  let c = st.count in
  c.steps <- c.steps + 1;
  if c.steps land 4095 = 0 || c.steps > max_steps then poll st loc

let enter st loc =
  step st loc;
  if st.count.depth >= max_depth then limit st loc (Msg.depth_limit max_depth);
  st.count.depth <- st.count.depth + 1

let leave st = st.count.depth <- st.count.depth - 1

let put scope o =
  match scope.emit with Some f -> f o | None -> scope.sink := o :: !(scope.sink)

let add_object st scope loc o =
  let c = st.count in
  c.objects <- c.objects + 1;
  if c.objects land 0xFFFF = 0 then Option.iter (fun f -> f c.objects) st.hooks.on_objects;
  if c.objects > max_objects then limit st loc (Msg.objects_limit max_objects);
  if c.objects land 1023 = 0 then Option.iter (limit st loc) (memory_refusal st c.objects);
  put scope o

let loop st loc ~range ~count ~per_iteration =
  let c = st.count in
  (* Refused before it starts when this loop, run inside the loops around it, would go
     past the step limit: nested loops fail at once instead of after minutes. *)
  let total = Float.max 0. count *. c.loops in
  if count > 1e15 || total +. Float.of_int c.steps > Float.of_int max_steps then
    limit st loc
      (Msg.loop_runs ~count ~loops:c.loops ~total ~steps:max_steps ~objects:max_objects);
  (* The same for the object limit: each iteration builds at least the objects written
     in the loop's body. *)
  if
    per_iteration > 0.
    && (total *. per_iteration) +. Float.of_int c.objects > Float.of_int max_objects
  then
    limit st loc
      (Msg.loop_builds ~total ~each:per_iteration ~count ~loops:c.loops ~built:c.objects
         ~objects:max_objects);
  (match range with
  | Some (start, stop, step) when count <= 0. ->
      warn st loc (Msg.loop_zero start stop step)
  | _ -> ());
  (* And for memory: objects that would not fit under the process's limit are refused
     before they are built (the runtime would abort, not raise, once it runs out). *)
  if per_iteration > 0. && total < 1e15 then
    Option.iter (limit st loc)
      (memory_refusal st (c.objects + int_of_float (total *. per_iteration)))

let body_at st name =
  let (b : D.body), _ =
    List.find (fun ((b : D.body), _) -> b.name = name) st.out.bodies
  in
  match Option.bind st.hooks.body_state (fun f -> f name st.hooks.time) with
  | Some pv -> pv
  | None -> (b.center, b.velocity)
