type t = {
  file : string;
  builtin : bool;
  animation : (float * int) option;
  evaluate :
    progress:(string -> unit) option ->
    cancel:Cancel.t option ->
    time:float ->
    frame:int ->
    Scene.t * string list;
  inputs : unit -> string list;
  names : unit -> string list;
  text_digest : unit -> string;
  input_digest : string -> string;
}

(* Frames per second of a time without an animation block, as [time_of] takes it. *)
let still_fps = 24.

let with_instants ?progress ?cancel t o (sc : Scene.t) ~time ~frame =
  if not (Camera.motion_blur sc.camera) then (sc, [])
  else
    let fps = match t.animation with Some (fps, _) -> fps | None -> still_fps in
    let moments =
      Array.map
        (fun s ->
          let m, fs = t.evaluate ~progress ~cancel ~time:(time +. (s /. fps)) ~frame in
          (Overrides.apply o m, fs))
        (Camera.shutter_times sc.camera)
    in
    match Scene.with_moments sc (Array.map fst moments) with
    | Ok sc -> (sc, List.concat (Array.to_list (Array.map snd moments)))
    | Error m -> Job_error.user "frame %d: %s" frame m

let scene ?progress ?cancel t o ~time ~frame =
  let sc, files = t.evaluate ~progress ~cancel ~time ~frame in
  let sc, more =
    with_instants ?progress ?cancel t o (Overrides.apply o sc) ~time ~frame
  in
  if more = [] then (sc, files) else (sc, List.sort_uniq String.compare (files @ more))

let reads t =
  List.filter_map
    (fun p ->
      if String.equal p t.file then if t.builtin then None else Some (p, "the scene")
      else
        match String.lowercase_ascii (Filename.extension p) with
        | ".rts" -> Some (p, "a file the scene includes")
        | ".obj" -> Some (p, "a mesh the scene uses")
        | _ -> Some (p, "an image the scene uses"))
    (t.inputs ())

let max_time = 1e9
let user = Job_error.user

let time_of t ~time ~frame =
  match (time, frame) with
  | Some _, Some _ -> user "give either --time or --frame, not both"
  | Some tm, None ->
      if not (Float.is_finite tm) then user "--time must be a finite number";
      (* Beyond this the frame number (time × fps, fps ≤ 1000) would not fit an integer. *)
      if Float.abs tm > max_time then
        user "--time must be within ±1e9 seconds (got %g)" tm;
      let fps = match t.animation with Some (fps, _) -> fps | None -> still_fps in
      (tm, int_of_float (Float.floor ((tm *. fps) +. 1e-9)))
  | None, Some k -> (
      if k < 0 then user "--frame must be at least 0 (got %d)" k;
      match t.animation with
      | None ->
          user
            "--frame %d: the scene has no animation block, so it has no frames (use \
             --time to set the time)"
            k
      | Some (_, count) when k >= count ->
          user "--frame %d: the animation has frames 0..%d" k (count - 1)
      | Some (fps, _) -> (Float.of_int k /. fps, k))
  | None, None -> (0., 0)
