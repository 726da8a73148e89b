open Lancer
module Dsl = Lancer_dsl.Dsl

type program = Dsl.t
type error = Diagnostic.t

let source_problem = Dsl.source_problem
let load ?progress ?digests ~filename text =
  Program.load_string ?progress ?digests ~filename text
type bundle = Dsl.bundle

let bundle = Dsl.bundle
let load_bundle ?progress b = Program.load_bundle ?progress b
let animation = Dsl.animation
let inputs = Dsl.inputs

let truncated_physics prog =
  if Dsl.bodies prog = [] then None
  else
    match Program.simulate prog ~until:0. with
    | Ok tr when Physics.truncated tr ->
        Some (match List.rev (Physics.events tr) with e :: _ -> e.time | [] -> 0.)
    | _ -> None

let scene_at ?index prog ~time ~frame = Program.scene_at ?index prog ~time ~frame
let single_scene = Program.single_scene
let summary prog sc = Program.summary prog sc
let to_json prog sc = Program.to_json prog sc

let source ~builtin prog : Lancer_job.Source.t =
  {
    file = Dsl.file prog;
    builtin;
    animation = Dsl.animation prog;
    evaluate =
      (fun ~progress ~cancel ~time ~frame ->
        match Program.scene_with_files ?progress ?cancel prog ~time ~frame with
        | Ok r -> r
        | Error errors -> raise (Lancer_job.Job_error.Scene { errors; note = "" }));
    inputs = (fun () -> Dsl.inputs prog);
    names = (fun () -> Dsl.named_files prog);
    text_digest = (fun () -> Dsl.text_digest prog);
    input_digest = Program.input_digest prog;
  }
