let user = Job_error.user

type encoding = {
  bits : int option;
  alpha : bool;
  region : Image.region option;
  crop : bool;
  format : Image.format option;
}

let default_encoding =
  { bits = None; alpha = false; region = None; crop = false; format = None }

let is_stdout p = p = "-"

(* The format of an output: its extension, or --format for standard output. *)
let format_of ?format path =
  if is_stdout path then Option.value format ~default:Image.Png
  else
    match (Image.format_of_path path, format) with
    | Error m, _ -> raise (Job_error.User m)
    | Ok f, Some g when f <> g ->
        user
          "--format %s, but -o %s has the extension of another format; --format is for \
           -o - (standard output)"
          (Image.format_name g) path
    | Ok f, _ -> f

let check_output ?format path =
  ignore (format_of ?format path);
  if is_stdout path then (
    if Unix.isatty Unix.stdout then
      user
        "-o - writes the image to standard output, which is a terminal here; redirect it \
         (-o - > image.png) or pipe it")
  else Files.check_writable path

(* --stats takes a value: [lancer render --stats scene.rts] means the scene was taken as
   its value. A statistics file is JSON; lancer's own kinds of files are refused. *)
let check_stats_name = function
  | None -> ()
  | Some p -> (
      match String.lowercase_ascii (Filename.extension p) with
      | (".rts" | ".png" | ".ppm" | ".obj" | ".gif" | ".mp4") as e ->
          let kind =
            match e with
            | ".rts" -> "a scene"
            | ".obj" -> "a mesh"
            | ".gif" | ".mp4" -> "a video"
            | _ -> "an image"
          in
          user
            "--stats %s: statistics are written as JSON, and that name is %s's; did \
             --stats take the scene as its value? Write --stats FILE.json"
            p kind
      | _ -> ())

(* What can be refused once the scene's size is known. *)
let check_encoding e ~out (sc : Scene.t) =
  if e.crop && e.region = None then user "--crop needs --region x0,y0,x1,y1";
  (match e.region with
  | Some r ->
      let w = sc.settings.width and h = sc.settings.height in
      if
        not
          (0 <= r.x0 && r.x0 < r.x1 && r.x1 <= w && 0 <= r.y0 && r.y0 < r.y1 && r.y1 <= h)
      then
        user
          "--region %d,%d,%d,%d is not inside the %d×%d image: it needs 0 <= x0 < x1 <= \
           %d and 0 <= y0 < y1 <= %d"
          r.x0 r.y0 r.x1 r.y1 w h w h
  | None -> ());
  let fmt = format_of ?format:e.format out in
  Option.iter (user "--bits %s") (Image.bits_problem fmt e.bits);
  if e.alpha && not (fmt = Image.Png || fmt = Image.Exr) then
    user "--alpha needs a PNG or EXR output: a %s file has no alpha channel"
      (String.uppercase_ascii (Image.format_name fmt))

(* The records an animation keeps in its frames directory (Frameset's names): no other
   output may replace them. *)
let refuse_frames_records paths =
  List.iter
    (fun (p, what) ->
      if
        String.equal (Filename.basename p) Frameset.view_name
        || String.equal (Filename.basename (Filename.dirname p)) Frameset.journal_dir
      then
        user
          "%s %s would replace a record of an animation's frames directory: write it \
           elsewhere"
          what p)
    paths

let stats_to_stdout (o : Options.t) =
  match o.stats with Some p -> is_stdout p | None -> false

(* The statistics' file, if they go to one ([--stats -]: to standard output). *)
let stats_file (o : Options.t) = if stats_to_stdout o then None else o.stats

let guard_render (o : Options.t) src ~out =
  if is_stdout out && stats_to_stdout o then
    user "--stats - and -o - would both write to standard output: give --stats a file";
  let stats = stats_file o in
  refuse_frames_records
    ((if is_stdout out then [] else [ (out, "-o") ])
    @ match stats with Some p -> [ (p, "--stats") ] | None -> []);
  Files.guard_writes ~reads:(Scenes.reads src)
    ((if is_stdout out then [] else [ (out, "the image") ])
    @ match stats with Some p -> [ (p, "the statistics") ] | None -> [])

(* Standard output carries the image's bytes and nothing else; a reader that goes away
   (a closed pipe) is an error to report, not a signal that kills. *)
let write_stdout ?(what = "the image") bytes =
  Sys.set_signal Sys.sigpipe Sys.Signal_ignore;
  set_binary_mode_out stdout true;
  match
    output_string stdout bytes;
    flush stdout
  with
  | () -> ()
  | exception Sys_error m -> user "cannot write %s to standard output: %s" what m

let write_stats_stdout j =
  write_stdout ~what:"the statistics" (Yojson.Safe.pretty_to_string j ^ "\n")

let write_image ?cancel ?(encoding = default_encoding) ?alpha ?record path (sc : Scene.t)
    fb =
  let crop = if encoding.crop then encoding.region else None in
  if is_stdout path then
    Files.uninterrupted ?cancel "the image on standard output" (fun () ->
        match
          Image.file_of
            (format_of ?format:encoding.format path)
            ~gamma:sc.settings.gamma ?bits:encoding.bits ?alpha ?crop
            ?text:(Option.map Provenance.text record)
            fb
        with
        | Ok bytes -> write_stdout bytes
        | Error m -> user "cannot write the image to standard output: %s" m)
  else
    ignore (Files.write_image ?cancel ?bits:encoding.bits ?alpha ?crop ?record path sc fb)
