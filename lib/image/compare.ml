type t = {
  width : int;
  height : int;
  max_diff : int;
  rmse : float;
  psnr : float;
  over : int;
  over_share : float;
}

let pixel_diff a b k =
  let d c = abs (Char.code (Bytes.get a (k + c)) - Char.code (Bytes.get b (k + c))) in
  max (d 0) (max (d 1) (d 2))

let compare ?(threshold = 1) (wa, ha, a) (wb, hb, b) =
  if wa <> wb || ha <> hb then
    Error (Printf.sprintf "the images differ in size: %d×%d and %d×%d" wa ha wb hb)
  else
    let n = wa * ha in
    let max_diff = ref 0 and sum2 = ref 0. and over = ref 0 in
    for p = 0 to n - 1 do
      let k = 3 * p in
      for c = 0 to 2 do
        let d = Char.code (Bytes.get a (k + c)) - Char.code (Bytes.get b (k + c)) in
        sum2 := !sum2 +. Float.of_int (d * d)
      done;
      let m = pixel_diff a b k in
      if m > !max_diff then max_diff := m;
      if m > threshold then incr over
    done;
    let rmse = if n = 0 then 0. else Float.sqrt (!sum2 /. Float.of_int (3 * n)) in
    let psnr = if rmse = 0. then Float.infinity else 20. *. Float.log10 (255. /. rmse) in
    Ok
      {
        width = wa;
        height = ha;
        max_diff = !max_diff;
        rmse;
        psnr;
        over = !over;
        over_share = (if n = 0 then 0. else Float.of_int !over /. Float.of_int n);
      }

let diff_image ?(threshold = 1) (w, h, a) (_, _, b) =
  let out = Bytes.create (3 * w * h) in
  for p = 0 to (w * h) - 1 do
    let k = 3 * p in
    let m = pixel_diff a b k in
    if m > threshold then (
      Bytes.set out k (Char.chr (min 255 (128 + (m * 2))));
      Bytes.set out (k + 1) '\000';
      Bytes.set out (k + 2) '\000')
    else
      for c = 0 to 2 do
        Bytes.set out (k + c) (Char.chr (Char.code (Bytes.get a (k + c)) / 4))
      done
  done;
  out

let within ?(max_diff = 1) ?(max_share = 0.) c =
  c.max_diff <= max_diff || (c.over_share <= max_share && max_share > 0.)

let pp ppf c =
  Format.fprintf ppf
    "max difference %d/255, RMSE %.3f, PSNR %s, %d pixels (%.3f%%) over the threshold"
    c.max_diff c.rmse
    (if Float.is_finite c.psnr then Printf.sprintf "%.2f dB" c.psnr else "inf dB")
    c.over (100. *. c.over_share)

type outcome =
  | Same of t
  | Updated of string
  | Different of { figures : t; actual : string; diff : string }
  | Missing of { actual : string }

let sibling golden suffix = Filename.remove_extension golden ^ suffix

(* The golden's directory, made when missing (the first update of a new project). *)
let rec make_dir d =
  if Sys.file_exists d then
    if Sys.is_directory d then Ok () else Error (Printf.sprintf "%s is not a directory" d)
  else
    let parent = Filename.dirname d in
    let ( let* ) = Result.bind in
    let* () = if parent = d then Ok () else make_dir parent in
    match Unix.mkdir d 0o755 with
    | () | (exception Unix.Unix_error (Unix.EEXIST, _, _)) -> Ok ()
    | exception Unix.Unix_error (e, _, _) ->
        Error
          (Printf.sprintf "cannot create the directory %s: %s" d (Unix.error_message e))

(* After a pass or an update, the images of an earlier failure are out of date. *)
let remove_stale golden =
  List.iter
    (fun suffix ->
      let p = sibling golden suffix in
      if Sys.file_exists p then try Sys.remove p with Sys_error _ -> ())
    [ ".actual.png"; ".diff.png" ]

let golden ?(tolerance = 1) ?(max_share = 0.) ~update ~golden ((w, h, bytes) as actual) =
  let ( let* ) = Result.bind in
  if update then (
    let* () = make_dir (Filename.dirname golden) in
    let* () = Image.write_rgb8 golden w h bytes in
    remove_stale golden;
    Ok (Updated golden))
  else if not (Sys.file_exists golden) then
    let a = sibling golden ".actual.png" in
    let* () = make_dir (Filename.dirname golden) in
    let* () = Image.write_rgb8 a w h bytes in
    Ok (Missing { actual = a })
  else
    let* ((gw, gh, _) as expected) = Image.read_rgb8 golden in
    let* () =
      if (gw, gh) = (w, h) then Ok ()
      else
        Error
          (Printf.sprintf
             "the golden %s is %d×%d but the image is %d×%d: render at the golden's \
              size, or remake the golden"
             golden gw gh w h)
    in
    let* figures = compare ~threshold:tolerance expected actual in
    if within ~max_diff:tolerance ~max_share figures then (
      remove_stale golden;
      Ok (Same figures))
    else
      let a = sibling golden ".actual.png" and d = sibling golden ".diff.png" in
      let* () = Image.write_rgb8 a w h bytes in
      let* () =
        Image.write_rgb8 d w h (diff_image ~threshold:tolerance expected actual)
      in
      Ok (Different { figures; actual = a; diff = d })
