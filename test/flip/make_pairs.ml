(* Writes the synthetic image pairs of the FLIP and SSIM test into a directory, as
   NAME.ref.png and NAME.test.png: edge cases generated from formulas, so that they can be
   made again. Usage: make_pairs DIR *)

let w = 64
let h = 48

let image ?(w = w) ?(h = h) f =
  let b = Bytes.create (3 * w * h) in
  for y = 0 to h - 1 do
    for x = 0 to w - 1 do
      let r, g, bl = f x y in
      let k = 3 * ((y * w) + x) in
      let clip v = Char.chr (max 0 (min 255 v)) in
      Bytes.set b k (clip r);
      Bytes.set b (k + 1) (clip g);
      Bytes.set b (k + 2) (clip bl)
    done
  done;
  (w, h, b)

let grey v _ _ = (v, v, v)
let gradient x y = (x * 255 / (w - 1), y * 255 / (h - 1), 128)

let ramp x _ =
  let v = x * 255 / (w - 1) in
  (v, v, v)

(* A deterministic noise in -a..a. *)
let noise a x y =
  let s = ref (x * 73856093 lxor (y * 19349663)) in
  for _ = 1 to 3 do
    s := ((!s * 1103515245) + 12345) land 0x7fffffff
  done;
  (!s mod ((2 * a) + 1)) - a

let pairs =
  [
    ("identical", image gradient, image gradient);
    ("black_white", image (grey 0), image (grey 255));
    ( "one_pixel",
      image (grey 128),
      image (fun x y -> if x = 20 && y = 30 then (255, 0, 0) else (128, 128, 128)) );
    ( "thin_lines",
      image (grey 255),
      image (fun x y -> if x = 31 || y = 17 || x = y then (0, 0, 0) else (255, 255, 255))
    );
    ( "gradient_banding",
      image ramp,
      image (fun x y ->
          let r, _, _ = ramp x y in
          let v = r / 32 * 32 in
          (v, v, v)) );
    ( "noise",
      image (fun x y -> (100 + x, 80 + y, 140)),
      image (fun x y ->
          (100 + x + noise 20 x y, 80 + y + noise 20 (x + 7) y, 140 + noise 20 x (y + 5)))
    );
    ( "colour_shift",
      image gradient,
      image (fun x y ->
          let r, g, b = gradient x y in
          (g, b, r)) );
    ( "checker_blur",
      image (fun x y ->
          if ((x / 4) + (y / 4)) mod 2 = 0 then (230, 230, 230) else (20, 20, 20)),
      image (fun x y ->
          if ((x / 4) + (y / 4)) mod 2 = 0 then (150, 150, 150) else (100, 100, 100)) );
    ( "tiny",
      image ~w:3 ~h:2 (fun x y -> (x * 100, y * 200, 50)),
      image ~w:3 ~h:2 (fun x _ -> (x * 90, 255, 0)) );
  ]

let () =
  let dir = Sys.argv.(1) in
  List.iter
    (fun (name, (wa, ha, a), (wb, hb, b)) ->
      let write suffix w h bytes =
        match Lancer.Image.write_rgb8 (Filename.concat dir (name ^ suffix)) w h bytes with
        | Ok () -> ()
        | Error m -> failwith m
      in
      write ".ref.png" wa ha a;
      write ".test.png" wb hb b)
    pairs
