(* Rank 0's serving rate with empty units, under mpirun -np N (make bench-mpi): the job
   of a W×H image over FRAMES frames is cut and handed out exactly as lancer-mpi cuts it,
   but a unit renders nothing, so what is measured is the scheme's own cost per unit:
   receiving a request and the unit's floats, copying them into the frame and answering.
   Every rank has one domain; rank 0 only serves. Rank 0 prints one line:

     ranks N frames F units U tiles T bytes_per_unit B seconds S units_per_s R median_wait_ms M

   usage: mpirun -np N serve_rate.exe W H FRAMES *)
open Lancer
module Mpi = Lancer_mpi.Mpi
module Farm = Lancer_mpi.Farm

let empty : Farm.renderer = fun ~pool:_ _ _ _ -> Counters.zero

let () =
  let w, h, frames =
    match Array.to_list Sys.argv with
    | [ _; w; h; f ] -> (int_of_string w, int_of_string h, int_of_string f)
    | _ ->
        prerr_endline "usage: serve_rate.exe WIDTH HEIGHT FRAMES";
        exit 1
  in
  Mpi.init ();
  let scene =
    let text =
      Printf.sprintf
        "settings { width: %d, height: %d }\n\
         camera { position: (0, 0, -5), look_at: (0, 0, 0) }\n"
        w h
    in
    match Lancer.Program.load_string ~filename:"empty.rts" text with
    | Error _ ->
        prerr_endline "serve_rate: the empty scene did not load";
        Mpi.abort 2
    | Ok prog -> (
        match Lancer.Program.scene prog ~time:0. ~frame:0 with
        | Ok sc -> sc
        | Error _ ->
            prerr_endline "serve_rate: the empty scene did not evaluate";
            Mpi.abort 2)
  in
  let fatal e =
    prerr_endline ("serve_rate: " ^ Printexc.to_string e);
    2
  in
  Mpi.barrier ();
  if Mpi.rank () = 0 then
    let t0 = Unix.gettimeofday () in
    let r =
      Farm.serve ~render:empty ~local:false ~fatal ~pool:None ~domains:1 ~on_tiles:ignore
        ~on_frame:(fun _ _ _ _ -> ())
        (List.init frames (fun k -> (k, fun () -> scene)))
    in
    let secs = Unix.gettimeofday () -. t0 in
    let units = Array.fold_left ( + ) 0 r.units
    and tiles = Array.fold_left ( + ) 0 r.tiles in
    let waits =
      List.concat (Array.to_list (Array.sub r.waits 1 (Array.length r.waits - 1)))
    in
    Printf.printf
      "ranks %d frames %d units %d tiles %d bytes_per_unit %d seconds %.6f units_per_s \
       %.1f median_wait_ms %.4f\n\
       %!"
      (Mpi.size ()) frames units tiles
      (24 * w * h * frames / max 1 units)
      secs
      (Float.of_int units /. secs)
      (1e3 *. Farm.percentile 0.5 waits)
  else
    Farm.work ~render:empty ~describe:Printexc.to_string ~pool:None ~domains:1 (fun _ ->
        (scene, []));
  Mpi.finalize ()
