(* How a job is cut into units (Work.plan, the rule lancer-mpi's server follows): every
   tile handed out once, in order; whole frames when there are frames enough for every
   rank; otherwise units of at most four tiles per domain and never fewer tiles than the
   rank has domains, unless the frame has no more; a still on several ranks is always
   cut. No MPI needed. *)
module Work = Lancer_job.Work

let failures = ref 0

let check name ok =
  if ok then Printf.printf "ok: %s\n" name
  else (
    Printf.printf "FAIL: %s\n" name;
    incr failures)

let () =
  List.iter
    (fun (ranks, domains, frames, tiles) ->
      let units = Work.plan ~ranks ~domains (List.init frames (fun _ -> tiles)) in
      let label =
        Printf.sprintf "%d frame(s) of %d tiles over %d ranks × %d domains" frames tiles
          ranks domains
      in
      (* Every tile once, frames in order. *)
      let per_frame = Array.make frames 0 and ordered = ref true and last = ref 0 in
      List.iter
        (fun (f, k) ->
          if f < !last then ordered := false;
          last := f;
          per_frame.(f) <- per_frame.(f) + k)
        units;
      check
        (label ^ ": every tile is handed out once, frames in order")
        (!ordered && Array.for_all (( = ) tiles) per_frame);
      if ranks = 1 || (frames >= ranks && frames > 1) then
        check (label ^ ": whole frames") (List.for_all (fun (_, k) -> k = tiles) units)
      else (
        check
          (label ^ ": at most four tiles per domain")
          (List.for_all (fun (_, k) -> k <= 4 * domains) units);
        (* Only a frame's last unit may be smaller than the domain count. *)
        let rec small_only_last = function
          | (f, k) :: ((f', _) :: _ as rest) ->
              (k >= domains || f' <> f) && small_only_last rest
          | _ -> true
        in
        check
          (label ^ ": no unit leaves a domain idle but a frame's last")
          (small_only_last units)))
    [
      (1, 1, 1, 2040);
      (2, 1, 1, 2040);
      (16, 16, 1, 2040);
      (1024, 16, 1, 2040);
      (1024, 1, 1, 2040);
      (16, 16, 48, 135);
      (64, 16, 48, 135);
      (1024, 16, 48, 135);
      (4, 2, 2, 9);
    ];
  (* The case the rule is for: a 1080p still (60×34 tiles) over 1024 ranks of 16 domains
     is cut into 128 units of 16 tiles, not 2040 of one tile that would each leave 15
     domains idle. *)
  let units = Work.plan ~ranks:1024 ~domains:16 [ 2040 ] in
  check
    "a 1080p still over 1024 ranks × 16 domains is 128 units of 16 tiles, the last of 8"
    (List.length units = 128
    && List.for_all (fun (_, k) -> k = 16) (List.filteri (fun i _ -> i < 127) units));
  if !failures > 0 then exit 1
