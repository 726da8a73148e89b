type blocks = All | Count of int

let user = Job_error.user
let bs = Provenance.block_size

(* The record an image holds. *)
let record_of image bytes =
  (match Image.format_of_path image with
  | Ok Image.Png -> ()
  | _ ->
      user
        "%s: lancer verify reads PNG images (the record of where an image came from is \
         one of their text chunks)"
        image);
  match Png.texts bytes with
  | Error m -> user "%s: %s" image m
  | Ok texts -> (
      match List.assoc_opt Provenance.keyword texts with
      | None ->
          user
            "%s holds no lancer record (it was written by another program, by a lancer \
             before %s, or its text was removed): there is nothing to check it against"
            image Version.v
      | Some t -> (
          match Provenance.of_text t with Ok r -> r | Error m -> user "%s: %s" image m))

(* Each file the record names that is now missing or holds other bytes. *)
let inputs_changed ~scene (r : Provenance.t) =
  List.filter_map
    (fun (f, md5) ->
      let p = match scene with Some s -> Loc.relative_to s f | None -> f in
      match Digest.file p with
      | exception Sys_error _ ->
          Some (Printf.sprintf "%s is missing (the scene read it)" p)
      | d when Digest.to_hex d <> md5 ->
          Some (Printf.sprintf "%s has changed since the image was written" p)
      | _ -> None)
    r.files

(* [k] distinct block numbers below [n], chosen by [seed]. *)
let choose ~seed n k =
  let st = Random.State.make seed in
  let a = Array.init n Fun.id in
  let k = min n k in
  for i = 0 to k - 1 do
    let j = i + Random.State.int st (n - i) in
    let t = a.(i) in
    a.(i) <- a.(j);
    a.(j) <- t
  done;
  Array.to_list (Array.sub a 0 k)

let seed_of samples =
  let d = Digest.string (Bytes.unsafe_to_string samples) in
  Array.init 4 (fun i -> Int32.to_int (String.get_int32_le d (4 * i)))

let pixel_text (r : Raster.t) x y =
  String.concat ", " (List.init r.channels (fun c -> string_of_int (Raster.get r x y c)))

let run ?cancel ?(domains = 1) ~blocks image =
  let bytes = match Image.read_bytes image with Ok b -> b | Error m -> user "%s" m in
  let r = record_of image bytes in
  let img =
    match Image.raster_of_string ~path:image bytes with
    | Ok i -> i
    | Error m -> user "%s" m
  in
  if r.version <> Version.v then
    Printf.printf "note: %s was written by lancer %s; this is lancer %s\n%!" image
      r.version Version.v;
  let nx, ny = Provenance.block_count img in
  let n = nx * ny in
  if String.length r.blocks <> 8 * n then
    user "%s: its size, %d×%d, is not the one its record was written for" image img.width
      img.height;
  let now = Provenance.blocks img in
  let edited =
    List.filter
      (fun k -> String.sub now (8 * k) 8 <> String.sub r.blocks (8 * k) 8)
      (List.init n Fun.id)
  in
  let scene =
    match r.scene with
    | None -> None
    | Some "-" ->
        user
          "%s was rendered from a scene on standard input: there is no file to render it \
           again from"
          image
    | Some s ->
        Some
          (if Filename.is_relative s then Filename.concat (Filename.dirname image) s
           else s)
  in
  let missing =
    match scene with
    | Some s when not (Sys.file_exists s) ->
        [ Printf.sprintf "%s, the scene, is missing" s ]
    | _ -> inputs_changed ~scene r
  in
  if missing <> [] then (
    Printf.printf "not reproduced: what %s was rendered from is not there as it was\n"
      image;
    List.iter (Printf.printf "  %s\n") missing;
    false)
  else
    let o = { Options.default with scene } in
    let prog = Scene_file.load ~single:(Float.equal r.time 0. && r.frame = 0) scene in
    let src = Scene_file.source o prog in
    if src.text_digest () <> r.scene_digest then (
      Printf.printf
        "not reproduced: %s (or a file it includes) has changed since %s was written\n"
        (Option.value scene ~default:"the built-in showcase")
        image;
      false)
    else
      let sc, _ = Scenes.scene ?cancel src r.options ~time:r.time ~frame:r.frame in
      (* An image rendered with --max-error: the settings it chose, as its record keeps
         them. *)
      let sc =
        match r.max_error with
        | None -> sc
        | Some b ->
            (try Budget.check_values b.values
             with Job_error.User m -> user "%s: its record's max_error: %s" image m);
            fst
              (Budget.apply ?cancel src r.options sc ~time:r.time ~frame:r.frame b.values)
      in
      let sw = sc.settings.width and sh = sc.settings.height in
      let crop = if r.crop then r.region else None in
      let ox, oy = match crop with Some c -> (c.x0, c.y0) | None -> (0, 0) in
      let ew, eh =
        match crop with Some c -> (c.x1 - c.x0, c.y1 - c.y0) | None -> (sw, sh)
      in
      if ew <> img.width || eh <> img.height then
        user "%s is %d×%d; its scene and options give %d×%d" image img.width img.height ew
          eh;
      let chosen =
        match blocks with
        | All -> List.init n Fun.id
        | Count k ->
            List.sort_uniq compare (choose ~seed:(seed_of img.samples) n k @ edited)
      in
      let fb = Framebuffer.create sw sh in
      (* Outside a region: the background, as the render left it. *)
      if r.region <> None then
        for j = 0 to sh - 1 do
          for i = 0 to sw - 1 do
            Framebuffer.set fb i j sc.settings.background
          done
        done;
      let alpha = if r.alpha then Some (Float.Array.make (sw * sh) 0.) else None in
      let rect k =
        let bx = k mod nx and by = k / nx in
        let x0 = bx * bs and y0 = by * bs in
        (x0, y0, min img.width (x0 + bs), min img.height (y0 + bs))
      in
      let work k =
        let x0, y0, x1, y1 = rect k in
        let x0 = x0 + ox and y0 = y0 + oy and x1 = x1 + ox and y1 = y1 + oy in
        let x0, y0, x1, y1 =
          match r.region with
          | Some g -> (max x0 g.x0, max y0 g.y0, min x1 g.x1, min y1 g.y1)
          | None -> (x0, y0, x1, y1)
        in
        if x0 < x1 && y0 < y1 then
          Render.render_tile ?alpha sc (Task.create ?cancel ()) fb x0 y0 x1 y1
      in
      let todo = Array.of_list chosen in
      Render.with_pool ?cancel domains (fun pool ->
          match pool with
          | None -> Array.iter work todo
          | Some p -> Pool.parallel_for p (Array.length todo) (fun i -> work todo.(i)));
      Option.iter Cancel.check cancel;
      let again = Image.encode ~gamma:sc.settings.gamma ~bits:r.bits ?alpha ?crop fb in
      if again.channels <> img.channels || again.depth <> img.depth then
        user "%s has %d channels of %d bits; its record gives %d of %d" image img.channels
          img.depth again.channels again.depth;
      let differs =
        List.filter_map
          (fun k ->
            let x0, y0, x1, y1 = rect k in
            let count = ref 0 and first = ref None in
            for y = y0 to y1 - 1 do
              for x = x0 to x1 - 1 do
                let same = ref true in
                for c = 0 to img.channels - 1 do
                  if Raster.get img x y c <> Raster.get again x y c then same := false
                done;
                if not !same then (
                  incr count;
                  if !first = None then first := Some (x, y))
              done
            done;
            match !first with
            | None -> None
            | Some (x, y) ->
                Some
                  (Printf.sprintf
                     "block %d (pixels %d–%d × %d–%d): %d pixel%s differ%s, first (%d, \
                      %d): the image has (%s), lancer renders (%s)"
                     k x0 (x1 - 1) y0 (y1 - 1) !count
                     (if !count = 1 then "" else "s")
                     (if !count = 1 then "s" else "")
                     x y (pixel_text img x y) (pixel_text again x y)))
          chosen
      in
      let edited_lines =
        List.map
          (fun k ->
            let x0, y0, x1, y1 = rect k in
            Printf.sprintf
              "block %d (pixels %d–%d × %d–%d) was edited after lancer wrote it" k x0
              (x1 - 1) y0 (y1 - 1))
          edited
      in
      if differs = [] && edited = [] then (
        Printf.printf
          "reproduced: %d of the %d blocks of %s rendered again are the same, sample for \
           sample, and every block is as lancer wrote it\n"
          (List.length chosen) n image;
        true)
      else (
        Printf.printf "not reproduced: %s\n" image;
        List.iter (Printf.printf "  %s\n") (edited_lines @ differs);
        false)
