let palette = [| "#1f77b4"; "#d62728"; "#2ca02c"; "#9467bd"; "#ff7f0e"; "#8c564b" |]

let escape s =
  let b = Buffer.create (String.length s) in
  String.iter
    (function
      | '<' -> Buffer.add_string b "&lt;"
      | '>' -> Buffer.add_string b "&gt;"
      | '&' -> Buffer.add_string b "&amp;"
      | '"' -> Buffer.add_string b "&quot;"
      | c -> Buffer.add_char b c)
    s;
  Buffer.contents b

let write ?title path rows =
  let w = 760.
  and h = 460.
  and ml = 70.
  and mr = 170.
  and mt = if title = None then 30. else 46.
  and mb = 50. in
  let finite = List.filter (fun (_, _, _, p) -> Float.is_finite p) rows in
  let ps = List.map (fun (_, _, _, p) -> p) finite in
  let any_inf = List.length finite < List.length rows in
  let ts = List.map (fun (_, _, t, _) -> Float.log10 (Float.max t 1e-4)) rows in
  let pmax = List.fold_left Float.max 20. ps +. 5.
  and pmin = Float.max 0. (List.fold_left Float.min 60. ps -. 5.) in
  let tmin = List.fold_left Float.min Float.infinity ts -. 0.1
  and tmax = List.fold_left Float.max Float.neg_infinity ts +. 0.1 in
  let tmin, tmax = if Float.is_finite tmin then (tmin, tmax) else (-1., 0.) in
  let x t =
    ml +. ((Float.log10 (Float.max t 1e-4) -. tmin) /. (tmax -. tmin) *. (w -. ml -. mr))
  in
  let y p =
    let p = if Float.is_finite p then p else pmax in
    mt +. ((pmax -. p) /. (pmax -. pmin) *. (h -. mt -. mb))
  in
  let b = Buffer.create 4096 in
  let pr fmt = Printf.bprintf b fmt in
  pr
    "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" \
     font-family=\"sans-serif\" font-size=\"12\">\n"
    w h;
  pr "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n";
  Option.iter
    (fun t ->
      pr "<text x=\"%.1f\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">%s</text>\n"
        ((ml +. w -. mr) /. 2.)
        (escape t))
    title;
  pr "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n" ml
    (h -. mb) (w -. mr) (h -. mb);
  pr "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n" ml mt ml
    (h -. mb);
  pr
    "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">wall time (s, log scale)</text>\n"
    ((ml +. w -. mr) /. 2.)
    (h -. 12.);
  pr
    "<text x=\"16\" y=\"%.1f\" transform=\"rotate(-90 16 %.1f)\" \
     text-anchor=\"middle\">PSNR against the reference (dB)</text>\n"
    ((mt +. h -. mb) /. 2.)
    ((mt +. h -. mb) /. 2.);
  (* Time ticks at 1, 2 and 5 times the powers of ten, each at its own position. *)
  let span = tmax -. tmin in
  let mults =
    if span > 3. then [ 1. ] else if span > 1.5 then [ 1.; 3. ] else [ 1.; 2.; 5. ]
  in
  for e = int_of_float (Float.floor tmin) to int_of_float (Float.ceil tmax) do
    List.iter
      (fun m ->
        let t = m *. (10. ** Float.of_int e) in
        let lt = Float.log10 t in
        if lt >= tmin && lt <= tmax then (
          pr "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n"
            (x t) (h -. mb) (x t)
            (h -. mb +. 4.);
          pr "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%s</text>\n" (x t)
            (h -. mb +. 17.)
            (Printf.sprintf "%g" t)))
      mults
  done;
  let p = ref (Float.ceil (pmin /. 5.) *. 5.) in
  while !p <= pmax do
    pr "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%.0f</text>\n" (ml -. 6.)
      (y !p +. 4.)
      !p;
    pr "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n" ml
      (y !p) (w -. mr) (y !p);
    p := !p +. 5.
  done;
  if any_inf then
    pr
      "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\" fill=\"#666\">identical (∞ dB) \
       along the top</text>\n"
      (w -. mr)
      (y pmax -. 4.);
  let knobs = List.sort_uniq compare (List.map (fun (k, _, _, _) -> k) rows) in
  (* Value labels beside the points, leaving out those that would overlap one already drawn. *)
  let placed = ref [] in
  let label col px py text =
    (* right of the point, or left of it where it would run into the legend *)
    let width = 6. *. Float.of_int (String.length text) in
    let right = px +. 5. +. width <= w -. mr in
    let lx = if right then px +. 5. else px -. 5. -. width and ly = py -. 5. in
    if
      not
        (List.exists
           (fun (qx, qy) ->
             Float.abs (qx -. lx) < Float.max width 24. && Float.abs (qy -. ly) < 10.)
           !placed)
    then (
      placed := (lx, ly) :: !placed;
      pr "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\" fill=\"%s\">%s</text>\n" lx ly col
        (escape text))
  in
  List.iteri
    (fun i knob ->
      let col = palette.(i mod Array.length palette) in
      let pts = List.filter (fun (k, _, _, _) -> k = knob) rows in
      pr "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.5\" points=\"%s\"/>\n"
        col
        (String.concat " "
           (List.map (fun (_, _, t, p) -> Printf.sprintf "%.1f,%.1f" (x t) (y p)) pts));
      List.iter
        (fun (_, v, t, p) ->
          pr
            "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\" fill=\"%s\"><title>%s %s: %.3f s, \
             %s</title></circle>\n"
            (x t) (y p) col (escape knob) (escape v) t
            (if Float.is_finite p then Printf.sprintf "%.2f dB" p else "identical"))
        pts;
      List.iter (fun (_, v, t, p) -> label col (x t) (y p) v) pts;
      pr "<text x=\"%.1f\" y=\"%.1f\" fill=\"%s\">%s</text>\n"
        (w -. mr +. 12.)
        (mt +. 16. +. (18. *. Float.of_int i))
        col (escape knob))
    knobs;
  pr "</svg>\n";
  match Lancer.Image.write_atomic path (fun oc -> Buffer.output_buffer oc b) with
  | Ok () -> ()
  | Error m -> raise (Lancer.Job_error.User m)
