let palette = [| "#1f77b4"; "#d62728"; "#2ca02c"; "#9467bd"; "#ff7f0e"; "#8c564b" |]

let write path rows =
  let w = 720. and h = 440. and ml = 70. and mr = 170. and mt = 30. and mb = 50. in
  let finite = List.filter (fun (_, _, _, p) -> Float.is_finite p) rows in
  let ps = List.map (fun (_, _, _, p) -> p) finite in
  let ts = List.map (fun (_, _, t, _) -> Float.log10 (Float.max t 1e-4)) rows in
  let pmax = List.fold_left Float.max 20. ps +. 5. and pmin = Float.max 0. (List.fold_left Float.min 60. ps -. 5.) in
  let tmin = List.fold_left Float.min Float.infinity ts -. 0.1 and tmax = List.fold_left Float.max Float.neg_infinity ts +. 0.1 in
  let x t = ml +. ((Float.log10 (Float.max t 1e-4) -. tmin) /. (tmax -. tmin) *. (w -. ml -. mr)) in
  let y p = let p = if Float.is_finite p then p else pmax in mt +. ((pmax -. p) /. (pmax -. pmin) *. (h -. mt -. mb)) in
  let b = Buffer.create 4096 in
  let pr fmt = Printf.bprintf b fmt in
  pr "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" font-family=\"sans-serif\" font-size=\"12\">\n" w h;
  pr "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n";
  pr "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n" ml (h -. mb) (w -. mr) (h -. mb);
  pr "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n" ml mt ml (h -. mb);
  pr "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">wall time (s, log scale)</text>\n" ((ml +. w -. mr) /. 2.) (h -. 12.);
  pr "<text x=\"16\" y=\"%.1f\" transform=\"rotate(-90 16 %.1f)\" text-anchor=\"middle\">PSNR against the reference (dB)</text>\n" ((mt +. h -. mb) /. 2.) ((mt +. h -. mb) /. 2.);
  let k = ref (Float.ceil (tmin *. 2.) /. 2.) in
  while !k <= tmax do
    let t = 10. ** !k in
    pr "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%g</text>\n" (x t) (h -. mb +. 16.) (Float.round (t *. 1000.) /. 1000.);
    k := !k +. 0.5
  done;
  let p = ref (Float.ceil (pmin /. 10.) *. 10.) in
  while !p <= pmax do
    pr "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%.0f</text>\n" (ml -. 6.) (y !p +. 4.) !p;
    pr "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n" ml (y !p) (w -. mr) (y !p);
    p := !p +. 10.
  done;
  let knobs = List.sort_uniq compare (List.map (fun (k, _, _, _) -> k) rows) in
  List.iteri
    (fun i knob ->
      let col = palette.(i mod Array.length palette) in
      let pts = List.filter (fun (k, _, _, _) -> k = knob) rows in
      pr "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.5\" points=\"%s\"/>\n" col
        (String.concat " " (List.map (fun (_, _, t, p) -> Printf.sprintf "%.1f,%.1f" (x t) (y p)) pts));
      List.iter
        (fun (_, v, t, p) ->
          pr "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\" fill=\"%s\"><title>%s %s: %.3f s, %s</title></circle>\n" (x t) (y p) col knob v t
            (if Float.is_finite p then Printf.sprintf "%.2f dB" p else "identical"))
        pts;
      pr "<text x=\"%.1f\" y=\"%.1f\" fill=\"%s\">%s</text>\n" (w -. mr +. 12.) (mt +. 16. +. (18. *. Float.of_int i)) col knob)
    knobs;
  pr "</svg>\n";
  match Lancer.Image.write_atomic path (fun oc -> Buffer.output_buffer oc b) with
  | Ok () -> ()
  | Error m -> raise (Cli.User_error m)
