let builtin_prefix = "(built in)/"
let files = List.map fst Library_files.all
let builtin p = List.assoc_opt p Library_files.all
let is_library p = String.length p > 7 && String.sub p 0 7 = "lancer/"

(* Where an installed lancer keeps its library: PREFIX/share beside PREFIX/bin. *)
let roots () =
  let env =
    match Sys.getenv_opt "LANCER_PATH" with
    | Some s when s <> "" -> String.split_on_char ':' s
    | _ -> []
  in
  let exe_dir = Filename.dirname Sys.executable_name in
  let exe_dir =
    if Filename.is_relative exe_dir then Filename.concat (Sys.getcwd ()) exe_dir
    else exe_dir
  in
  List.filter (fun d -> d <> "") env
  @ [ Filename.concat (Filename.dirname exe_dir) "share" ]

let locate ~including p =
  let beside = Loc.relative_to including p in
  if Sys.file_exists beside || (not (is_library p)) || not (Filename.is_relative p) then
    beside
  else
    match List.find_opt (fun r -> Sys.file_exists (Filename.concat r p)) (roots ()) with
    | Some r -> Filename.concat r p
    | None -> if Option.is_some (builtin p) then builtin_prefix ^ p else beside

let read path =
  let n = String.length builtin_prefix in
  if String.length path > n && String.sub path 0 n = builtin_prefix then
    match builtin (String.sub path n (String.length path - n)) with
    | Some text -> Ok text
    | None -> Error "no such file in lancer's library"
  else
    try Ok (In_channel.with_open_bin path In_channel.input_all)
    with Sys_error m -> Error m

let names p =
  match builtin p with
  | None -> []
  | Some text ->
      List.filter_map
        (fun line ->
          match String.split_on_char ' ' line with
          | "let" :: name :: _ -> Some name
          | _ -> None)
        (String.split_on_char '\n' text)
