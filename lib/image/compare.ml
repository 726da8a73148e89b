type metric = Rmse of float | Psnr of float | Flip of float | Ssim of float

let check_metric m =
  let between name lo hi v =
    if v >= lo && v <= hi then Ok ()
    else Error (Printf.sprintf "%s must be between %g and %g (got %g)" name lo hi v)
  in
  match m with
  | Rmse v -> between "an RMSE limit" 0. 255. v
  | Psnr v -> between "a PSNR limit" 0. Float.infinity v
  | Flip v -> between "a mean FLIP limit" 0. 1. v
  | Ssim v -> between "an SSIM limit" (-1.) 1. v

let passes m v = match m with Rmse l | Flip l -> v <= l | Psnr l | Ssim l -> v >= l

let pp_judged ppf (m, v) =
  let name, digits, l =
    match m with
    | Rmse l -> ("RMSE", 3, l)
    | Psnr l -> ("PSNR", 2, l)
    | Flip l -> ("mean FLIP", 4, l)
    | Ssim l -> ("SSIM", 4, l)
  in
  let value =
    match m with
    | Psnr _ when not (Float.is_finite v) -> "inf"
    | _ -> Printf.sprintf "%.*f" digits v
  in
  let unit = match m with Psnr _ -> " dB" | _ -> "" in
  Format.fprintf ppf "%s %s%s %s %g%s" name value unit
    (match (m, passes m v) with
    | (Rmse _ | Flip _), true -> "<="
    | (Rmse _ | Flip _), false -> ">"
    | (Psnr _ | Ssim _), true -> ">="
    | (Psnr _ | Ssim _), false -> "<")
    l unit

type t = {
  width : int;
  height : int;
  max_diff : int;
  rmse : float;
  psnr : float;
  over : int;
  over_share : float;
  judged : (metric * float) option;
}

let pixel_diff a b k =
  let d c = abs (Char.code (Bytes.get a (k + c)) - Char.code (Bytes.get b (k + c))) in
  max (d 0) (max (d 1) (d 2))

let figures ~threshold (wa, ha, a) (wb, hb, b) =
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
        judged = None;
      }

let size_error (wa, ha, _) (wb, hb, _) =
  if wa <> wb || ha <> hb then
    Error (Printf.sprintf "the images differ in size: %d×%d and %d×%d" wa ha wb hb)
  else Ok ()

let measure m a b =
  let ( let* ) = Result.bind in
  let* () = size_error a b in
  match m with
  | Rmse _ -> Result.map (fun c -> c.rmse) (figures ~threshold:1 a b)
  | Psnr _ -> Result.map (fun c -> c.psnr) (figures ~threshold:1 a b)
  | Flip _ -> Ok (Flip.mean (Flip.error_map a b))
  | Ssim _ -> Ssim.ssim a b

let compare ?(threshold = 1) ?metric a b =
  let ( let* ) = Result.bind in
  let* c = figures ~threshold a b in
  match metric with
  | None -> Ok c
  | Some m ->
      let* () = check_metric m in
      let* v =
        match m with Rmse _ -> Ok c.rmse | Psnr _ -> Ok c.psnr | _ -> measure m a b
      in
      Ok { c with judged = Some (m, v) }

let flip_image a b = Flip.grey (Flip.error_map a b)

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
  match c.judged with
  | Some (m, v) -> passes m v
  | None -> c.max_diff <= max_diff || (c.over_share <= max_share && max_share > 0.)

let pp ppf c =
  Format.fprintf ppf
    "max difference %d/255, RMSE %.3f, PSNR %s, %d pixels (%.3f%%) over the threshold"
    c.max_diff c.rmse
    (if Float.is_finite c.psnr then Printf.sprintf "%.2f dB" c.psnr else "inf dB")
    c.over (100. *. c.over_share);
  Option.iter (Format.fprintf ppf "; %a" pp_judged) c.judged

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

let golden ?(tolerance = 1) ?(max_share = 0.) ?metric ~update ~golden
    ((w, h, bytes) as actual) =
  let ( let* ) = Result.bind in
  let* () = match metric with Some m -> check_metric m | None -> Ok () in
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
    let* figures = compare ~threshold:tolerance ?metric expected actual in
    if within ~max_diff:tolerance ~max_share figures then (
      remove_stale golden;
      Ok (Same figures))
    else
      let a = sibling golden ".actual.png" and d = sibling golden ".diff.png" in
      let* () = Image.write_rgb8 a w h bytes in
      let* () =
        Image.write_rgb8 d w h
          (match metric with
          | Some _ -> flip_image expected actual
          | None -> diff_image ~threshold:tolerance expected actual)
      in
      Ok (Different { figures; actual = a; diff = d })
