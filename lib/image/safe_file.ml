(* Who wrote a temporary file: the host and its process-id namespace, so that a process id
   is only ever judged where it means something. Shards of one job on several nodes may
   share an output directory (over NFS): a file of another node is never removed. *)
let owner =
  let clean s =
    String.map
      (fun c -> match c with 'a' .. 'z' | 'A' .. 'Z' | '0' .. '9' | '.' -> c | _ -> '_')
      s
  in
  let host = try clean (Unix.gethostname ()) with Unix.Unix_error _ -> "host" in
  let ns =
    match Unix.readlink "/proc/self/ns/pid" with
    | l ->
        String.concat ""
          (List.filter (fun s -> s <> "") (String.split_on_char ':' (clean l)))
    | exception Unix.Unix_error _ -> "0"
  in
  host ^ "_" ^ ns

let temp_path path =
  let dir = Filename.dirname path and base = Filename.basename path in
  Filename.concat dir
    (Printf.sprintf ".%s.tmp-%s-%d-%d" base owner (Unix.getpid ())
       (Random.State.bits (Random.State.make_self_init ())))

(* The owner and process id in a temporary name ".NAME.tmp-OWNER-PID-RAND", if it is one. *)
let temp_owner_pid name =
  let digits s =
    s <> "" && String.length s < 10 && String.for_all (fun c -> c >= '0' && c <= '9') s
  in
  let marker = ".tmp-" in
  let n = String.length name and m = String.length marker in
  if n < 2 || name.[0] <> '.' then None
  else
    (* The last ".tmp-" in the name: NAME itself may hold one. *)
    let rec find i =
      if i < 1 then None else if String.sub name i m = marker then Some i else find (i - 1)
    in
    match find (n - m) with
    | None -> None
    | Some i -> (
        match String.split_on_char '-' (String.sub name (i + m) (n - i - m)) with
        | [ owner; pid; rand ] when owner <> "" && digits pid && digits rand ->
            Some (owner, int_of_string pid)
        | _ -> None)

let running pid =
  match Unix.kill pid 0 with
  | () -> true
  | exception Unix.Unix_error (Unix.ESRCH, _, _) -> false
  | exception Unix.Unix_error _ -> true (* it exists, but belongs to someone else *)

let remove_stale dir =
  match Sys.readdir dir with
  | exception Sys_error _ -> []
  | names ->
      Array.to_list names
      |> List.filter_map (fun name ->
             match temp_owner_pid name with
             | Some (o, pid)
               when String.equal o owner && pid <> Unix.getpid () && not (running pid)
               -> (
                 let p = Filename.concat dir name in
                 match Unix.lstat p with
                 | { st_kind = Unix.S_REG; _ } -> (
                     try
                       Sys.remove p;
                       Some (p, pid)
                     with Sys_error _ -> None)
                 | _ | (exception Unix.Unix_error _) -> None)
             | _ -> None)

(* The reason of a failure, without the name of the temporary file: the user only knows
   the path they asked for. *)
let describe ~tmp = function
  | Sys_error m ->
      let t = tmp ^ ": " in
      let lt = String.length t in
      if String.length m > lt && String.sub m 0 lt = t then
        String.sub m lt (String.length m - lt)
      else m
  | Unix.Unix_error (e, _, _) -> Unix.error_message e
  | Failure m -> m
  | e -> Printexc.to_string e

let read_only path =
  match Unix.stat path with
  | { st_kind = Unix.S_REG; st_perm; _ } -> (
      if Unix.getuid () = 0 then st_perm land 0o222 = 0
      else
        try
          Unix.access path [ Unix.W_OK ];
          false
        with Unix.Unix_error _ -> true)
  | _ -> false
  | exception Unix.Unix_error _ -> false

let check_writable path =
  let dir = Filename.dirname path in
  if Sys.file_exists path && Sys.is_directory path then
    Error (Printf.sprintf "cannot write %s: is a directory" path)
  else if not (Sys.file_exists dir) then
    Error (Printf.sprintf "cannot write %s: directory %s does not exist" path dir)
  else if not (Sys.is_directory dir) then
    Error (Printf.sprintf "cannot write %s: %s is not a directory" path dir)
  else if read_only path then
    Error
      (Printf.sprintf
         "cannot write %s: the file is read-only (make it writable or remove it first)"
         path)
  else Ok ()

(* A device or a pipe (/dev/stdout, /dev/null, a FIFO) cannot be replaced by a rename,
   and must not be: running as root, that would swap the device node for a file. *)
let is_special path =
  match (Unix.stat path).st_kind with
  | Unix.S_CHR | Unix.S_BLK | Unix.S_FIFO | Unix.S_SOCK -> true
  | _ -> false
  | exception Unix.Unix_error _ -> false

(* Every step that can fail is checked: the writes (output raises on an error), the
   flush, the fsync and the close. *)
let write_channel ~sync oc f =
  match
    f oc;
    flush oc;
    if sync then Unix.fsync (Unix.descr_of_out_channel oc);
    close_out oc
  with
  | () -> ()
  | exception e ->
      close_out_noerr oc;
      raise e

let write path f =
  match check_writable path with
  | Error e -> Error e
  | Ok () when is_special path -> (
      match
        write_channel ~sync:false (open_out_gen [ Open_wronly; Open_binary ] 0o666 path) f
      with
      | () -> Ok ()
      | exception Sys.Break -> raise Sys.Break
      | exception e ->
          Error (Printf.sprintf "cannot write %s: %s" path (describe ~tmp:path e)))
  | Ok () -> (
      let tmp = temp_path path in
      match
        let oc =
          open_out_gen [ Open_wronly; Open_creat; Open_excl; Open_binary ] 0o666 tmp
        in
        write_channel ~sync:true oc f;
        Unix.rename tmp path
      with
      | () -> Ok ()
      | exception e ->
          (try Sys.remove tmp with Sys_error _ -> ());
          (match e with Sys.Break -> raise e | _ -> ());
          Error (Printf.sprintf "cannot write %s: %s" path (describe ~tmp e)))
