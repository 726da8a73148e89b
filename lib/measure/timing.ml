(* Timings shared by the measurements: medians, a render's wall time, a child process's. *)

open Lancer

let median xs =
  let a = Array.of_list xs in
  Array.sort Float.compare a;
  let n = Array.length a in
  if n = 0 then Float.nan
  else if n mod 2 = 1 then a.(n / 2)
  else 0.5 *. (a.((n / 2) - 1) +. a.(n / 2))

let render ?pool ?on_tile sc =
  let t0 = Unix.gettimeofday () in
  let fb, st = Render.render ?pool ?on_tile sc in
  (Unix.gettimeofday () -. t0, fb, st)

(* Wall time of [exe] run with [args], its output thrown away; [None] with its status
   when it fails. *)
let child exe args =
  let null = Unix.openfile "/dev/null" [ Unix.O_WRONLY ] 0 in
  let t0 = Unix.gettimeofday () in
  let pid =
    Fun.protect
      ~finally:(fun () -> Unix.close null)
      (fun () ->
        Unix.create_process exe (Array.of_list (exe :: args)) Unix.stdin null null)
  in
  let _, st = Unix.waitpid [] pid in
  let dt = Unix.gettimeofday () -. t0 in
  match st with
  | Unix.WEXITED 0 -> Ok dt
  | Unix.WEXITED c | Unix.WSIGNALED c | Unix.WSTOPPED c -> Error c
