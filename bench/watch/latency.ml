(* How long a save takes to show in lancer watch: from the rename that saves the scene to
   the first (coarse) image announced on the event stream, and to the full image. The
   showcase at 640×480 with its own settings, with the colour of one sphere changed on
   each save; the median of 5 saves (after a first render that is not counted).

     dune exec -- bench/watch/latency.exe [LANCER] [EXTRA OPTIONS…]   (or: make bench-watch) *)

open Watch_client

let () =
  let exe =
    if Array.length Sys.argv > 1 then Sys.argv.(1) else "_build/default/bin/main.exe"
  in
  let extra =
    if Array.length Sys.argv > 2 then
      Array.to_list (Array.sub Sys.argv 2 (Array.length Sys.argv - 2))
    else []
  in
  let exe =
    if Filename.is_relative exe then Filename.concat (Sys.getcwd ()) exe else exe
  in
  let showcase = In_channel.with_open_bin "scenes/showcase.rts" In_channel.input_all in
  let dir = Run_lancer.tmpdir "lancer-latency" in
  let path = Filename.concat dir "s.rts" in
  let marker = "color: (0.85, 0.2, 0.15)" in
  let version k =
    let i = Option.get (find showcase marker) in
    String.sub showcase 0 i
    ^ Printf.sprintf "color: (0.85, %.2f, 0.15)" (0.2 +. (0.1 *. Float.of_int k))
    ^ String.sub showcase
        (i + String.length marker)
        (String.length showcase - i - String.length marker)
  in
  Run_lancer.write_file path (version 0);
  let s = start ~exe ~dir ([ "s.rts"; "--width"; "640"; "--height"; "480" ] @ extra) in
  let e = events s in
  let last ev j = ev = "image" && to_bool (member "last" j) in
  ignore (wait_for e ~timeout:600. "the first full image" last);
  (* Each save is followed by lancer render of the same scene, on this machine at about the
     same moment: the load of a shared machine changes from minute to minute. *)
  let render () =
    let t = Unix.gettimeofday () in
    let st, _, err =
      Run_lancer.run ~exe ~dir
        ([ "render"; "s.rts"; "-o"; "r.png"; "-q"; "--width"; "640"; "--height"; "480" ]
        @ extra)
    in
    if st <> 0 then prerr_string err;
    Unix.gettimeofday () -. t
  in
  let runs =
    List.init 5 (fun k ->
        Unix.sleepf 0.5;
        let t0 = Unix.gettimeofday () in
        atomic_write path (version (k + 1));
        ignore (wait_for e ~timeout:600. "a coarse image" (fun ev _ -> ev = "image"));
        let t1 = Unix.gettimeofday () in
        ignore (wait_for e ~timeout:600. "the full image" last);
        let t2 = Unix.gettimeofday () in
        let r = render () in
        Printf.printf
          "save %d: first image %.3f s, full image %.3f s; lancer render %.3f s\n%!"
          (k + 1) (t1 -. t0) (t2 -. t0) r;
        (t1 -. t0, t2 -. t0, r))
  in
  close_events e;
  ignore (stop s);
  let median l = List.nth (List.sort Float.compare l) (List.length l / 2) in
  Printf.printf
    "median of 5 saves: first (coarse) image %.3f s, full image %.2f s; lancer render of \
     the same: %.2f s\n"
    (median (List.map (fun (a, _, _) -> a) runs))
    (median (List.map (fun (_, b, _) -> b) runs))
    (median (List.map (fun (_, _, c) -> c) runs))
