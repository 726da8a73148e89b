let tmpdir prefix =
  let d =
    Filename.concat
      (Filename.get_temp_dir_name ())
      (Printf.sprintf "%s-%d-%d" prefix (Unix.getpid ()) (Random.bits ()))
  in
  Unix.mkdir d 0o755;
  d

let write_file p s = Out_channel.with_open_bin p (fun oc -> output_string oc s)
let read_file p = In_channel.with_open_bin p In_channel.input_all

let scene_files dir subs =
  List.concat_map
    (fun sub ->
      let d = Filename.concat dir sub in
      Sys.readdir d |> Array.to_list |> List.sort compare
      |> List.filter (fun f -> Filename.check_suffix f ".rts")
      |> List.map (Filename.concat d))
    subs

let contains s sub =
  let n = String.length s and m = String.length sub in
  let rec go i = i + m <= n && (String.sub s i m = sub || go (i + 1)) in
  go 0

let run ?(prefix = "") ~exe ~dir args =
  let out = Filename.temp_file "lancer" ".out"
  and err = Filename.temp_file "lancer" ".err" in
  let cmd =
    Printf.sprintf "cd %s && %s %s %s >%s 2>%s </dev/null" (Filename.quote dir) prefix
      (Filename.quote exe)
      (String.concat " " (List.map Filename.quote args))
      out err
  in
  let status = Sys.command cmd in
  let o = read_file out and e = read_file err in
  Sys.remove out;
  Sys.remove err;
  (status, o, e)

let check_status msg expected (st, _, e) =
  Alcotest.(check int) (msg ^ "\n" ^ e) expected st

let says msg (_, out, err) sub =
  Alcotest.(check bool)
    (Printf.sprintf "%s: %S in\n%s%s" msg sub out err)
    true
    (contains (out ^ err) sub)

let spawn ~exe ~dir args =
  let null = Unix.openfile "/dev/null" [ Unix.O_RDWR ] 0 in
  let cwd = Sys.getcwd () in
  Sys.chdir dir;
  let pid = Unix.create_process exe (Array.of_list (exe :: args)) null null null in
  Sys.chdir cwd;
  Unix.close null;
  pid

let wait_status pid = match snd (Unix.waitpid [] pid) with Unix.WEXITED n -> n | _ -> -1

let status_text = function
  | Unix.WEXITED n -> Printf.sprintf "exit %d" n
  | Unix.WSIGNALED n -> Printf.sprintf "killed by signal %d" n
  | Unix.WSTOPPED n -> Printf.sprintf "stopped by signal %d" n

let quality_rows ~exe ~dir scene knob =
  let st, out, err =
    run
      ~prefix:("XDG_CACHE_HOME=" ^ Filename.quote (Filename.concat dir "cache"))
      ~exe ~dir
      [ "bench"; "quality"; scene; "--domains"; "1"; "--json" ]
  in
  if st <> 0 then Alcotest.failf "bench quality failed (%d): %s" st err;
  let open Yojson.Safe.Util in
  Yojson.Safe.from_string out |> member "rows" |> to_list
  |> List.filter (fun r -> r |> member "knob" |> to_string = knob)
  |> List.map (fun r ->
         (r |> member "value" |> to_string, r |> member "rmse" |> to_number))

let pixels path =
  match Lancer_image.Image.read_raster path with
  | Ok r ->
      Printf.sprintf "%d×%d×%d×%d:" r.width r.height r.channels r.depth
      ^ Bytes.to_string r.samples
  | Error m -> Alcotest.failf "%s" m
