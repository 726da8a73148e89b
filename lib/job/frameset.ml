(* See frameset.mli. *)

let frame_name ?(ext = "png") k = Printf.sprintf "frame_%04d.%s" k ext
let journal_dir = "lancer-frames.d"
let view_name = "lancer-frames.json"
let binding_name = "scene.json"

type entry = {
  frame : int;
  job : string;
  made_with : (string * string) list; (* what the job is made of, named; [] if unknown *)
  size : int;
  md5 : string;
  inputs : (string * string) list;
}

type t = {
  dir : string;
  ext : string;  (** the frames' extension *)
  jdir : string;
  scene : string;
  job : string;
  made_with : (string * string) list;
  count : int;
  entries : (int, entry list) Hashtbl.t; (* what every run recorded, by frame *)
  journal : string; (* this run's, made on its first entry *)
  mutable fd : Unix.file_descr option;
  mutable synced : float; (* when the journal was last synced *)
  lock : Mutex.t;
}

let unix_msg e = Unix.error_message e

let sync_fd fd =
  match Unix.fsync fd with
  | () -> Ok ()
  | exception Unix.Unix_error ((Unix.EINVAL | Unix.EROFS), _, _) ->
      Ok () (* a file that cannot be synced *)
  | exception Unix.Unix_error (e, _, _) -> Error (unix_msg e)

(* Every byte written; synced too unless [sync] is false. *)
let write_fd ?(sync = true) fd text =
  let rec go off =
    if off < String.length text then
      go (off + Unix.write_substring fd text off (String.length text - off))
  in
  match go 0 with
  | () -> if sync then sync_fd fd else Ok ()
  | exception Unix.Unix_error (e, _, _) -> Error (unix_msg e)

let write_new path text =
  match
    Unix.openfile path [ Unix.O_WRONLY; Unix.O_CREAT; Unix.O_EXCL; Unix.O_CLOEXEC ] 0o644
  with
  | exception Unix.Unix_error (e, _, _) -> Error (unix_msg e)
  | fd -> (
      let r = write_fd fd text in
      match Unix.close fd with
      | () -> r
      | exception Unix.Unix_error (e, _, _) -> if r = Ok () then Error (unix_msg e) else r
      )

(* ---- Entries as JSON lines ---- *)

let entry_json ~ext (e : entry) =
  `Assoc
    [
      ("frame", `Int e.frame);
      ("file", `String (frame_name ~ext e.frame));
      ("job", `String e.job);
      ("made_with", `Assoc (List.map (fun (k, v) -> (k, `String v)) e.made_with));
      ("size", `Int e.size);
      ("md5", `String e.md5);
      ("inputs", `Assoc (List.map (fun (f, d) -> (f, `String d)) e.inputs));
    ]

let entry_of_json ?job j =
  let open Yojson.Safe.Util in
  try
    let job = match job with Some j -> j | None -> to_string (member "job" j) in
    Some
      {
        frame = to_int (member "frame" j);
        job;
        made_with =
          (match member "made_with" j with
          | `Assoc kvs ->
              List.filter_map (function k, `String v -> Some (k, v) | _ -> None) kvs
          | _ -> []);
        size = to_int (member "size" j);
        md5 = to_string (member "md5" j);
        inputs = List.map (fun (f, d) -> (f, to_string d)) (to_assoc (member "inputs" j));
      }
  with _ -> None

let add t (e : entry) =
  Hashtbl.replace t.entries e.frame
    (e :: Option.value (Hashtbl.find_opt t.entries e.frame) ~default:[])

(* A journal cut short by a kill ends in a partial line: every complete line counts. *)
let read_journal t path =
  match In_channel.with_open_bin path In_channel.input_all with
  | exception Sys_error _ -> ()
  | text ->
      List.iter
        (fun line ->
          if line <> "" then
            match Yojson.Safe.from_string line with
            | j -> Option.iter (add t) (entry_of_json j)
            | exception _ -> ())
        (String.split_on_char '\n' text)

let read_view t =
  match Yojson.Safe.from_file (Filename.concat t.dir view_name) with
  | `Assoc kvs -> (
      match (List.assoc_opt "job" kvs, List.assoc_opt "frames" kvs) with
      | Some (`String job), Some (`List fs) ->
          List.iter (fun j -> Option.iter (add t) (entry_of_json ~job j)) fs
      | _ -> ())
  | _ -> ()
  | exception _ -> ()

let read_all t =
  Hashtbl.reset t.entries;
  read_view t;
  match Sys.readdir t.jdir with
  | exception Sys_error _ -> ()
  | names ->
      Array.sort compare names;
      Array.iter
        (fun n ->
          if Filename.check_suffix n ".jsonl" then
            read_journal t (Filename.concat t.jdir n))
        names

(* ---- The directory's scene ---- *)

let read_binding path =
  match Yojson.Safe.from_file path with
  | `Assoc kvs -> (
      match List.assoc_opt "scene" kvs with
      | Some (`String s) -> `Scene s
      | _ -> `Unreadable)
  | _ -> `Unreadable
  | exception Sys_error _ when not (Sys.file_exists path) -> `Missing
  | exception _ -> `Unreadable

let rec bind ~dir ~jdir ~scene attempts =
  let path = Filename.concat jdir binding_name in
  match read_binding path with
  | `Scene s when s = scene -> ()
  | `Scene s ->
      Job_error.user
        "%s holds the frames of another scene, %s (this one is %s): render into another \
         directory, or remove %s to start over (or, if it is the same scene moved, %s)"
        dir s scene dir path
  | `Unreadable when attempts > 0 ->
      (* Another run may be creating it on a file system without hard links: look again. *)
      Unix.sleepf 0.1;
      bind ~dir ~jdir ~scene (attempts - 1)
  | `Unreadable ->
      Job_error.user
        "%s is not a scene record of lancer; remove it, or render into another directory"
        path
  | `Missing -> (
      (* Written whole under a private name, then linked into place: link fails if the
         name exists, atomically, on the server for NFS. *)
      let tmp =
        Filename.concat jdir
          (Printf.sprintf ".scene.json.tmp-%d-%d" (Unix.getpid ()) (Random.bits ()))
      in
      let text = Yojson.Safe.to_string (`Assoc [ ("scene", `String scene) ]) ^ "\n" in
      (match write_new tmp text with
      | Ok () -> ()
      | Error m -> Job_error.user "cannot write %s: %s" path m);
      let linked =
        match Unix.link tmp path with
        | () -> Ok ()
        | exception Unix.Unix_error (Unix.EEXIST, _, _) -> Ok ()
        | exception
            Unix.Unix_error
              ((Unix.EPERM | Unix.EOPNOTSUPP | Unix.ENOSYS | Unix.EMLINK), _, _) -> (
            (* No hard links here: an exclusive create does the same, though a reader may
               see it empty for a moment (hence the second look above). *)
            match
              Unix.openfile path
                [ Unix.O_WRONLY; Unix.O_CREAT; Unix.O_EXCL; Unix.O_CLOEXEC ]
                0o644
            with
            | fd ->
                Fun.protect
                  ~finally:(fun () -> Unix.close fd)
                  (fun () -> write_fd fd text)
            | exception Unix.Unix_error (Unix.EEXIST, _, _) -> Ok ()
            | exception Unix.Unix_error (e, _, _) -> Error (unix_msg e))
        | exception Unix.Unix_error (e, _, _) -> Error (unix_msg e)
      in
      (try Unix.unlink tmp with Unix.Unix_error _ -> ());
      match linked with
      | Error m -> Job_error.user "cannot write %s: %s" path m
      | Ok () -> bind ~dir ~jdir ~scene attempts)

let open_ ?(ext = "png") ?(made_with = []) ~dir ~scene ~job ~count () =
  let jdir = Filename.concat dir journal_dir in
  (try Unix.mkdir jdir 0o755 with
  | Unix.Unix_error (Unix.EEXIST, _, _) when Sys.is_directory jdir -> ()
  | Unix.Unix_error (Unix.EEXIST, _, _) ->
      Job_error.user "%s exists and is not a directory" jdir
  | Unix.Unix_error (e, _, _) -> Job_error.user "cannot create %s: %s" jdir (unix_msg e));
  bind ~dir ~jdir ~scene 20;
  let host = try Unix.gethostname () with Unix.Unix_error _ -> "host" in
  let journal =
    Filename.concat jdir
      (Printf.sprintf "%s-%d-%06x.jsonl" host (Unix.getpid ())
         (Random.State.bits (Random.State.make_self_init ()) land 0xffffff))
  in
  let t =
    {
      dir;
      ext;
      jdir;
      scene;
      job;
      made_with;
      count;
      entries = Hashtbl.create 64;
      journal;
      fd = None;
      synced = 0.;
      lock = Mutex.create ();
    }
  in
  read_all t;
  t

(* ---- Checking a frame ---- *)

let inputs_current ~input_digest (e : entry) =
  List.for_all (fun (f, d) -> String.equal (input_digest f) d) e.inputs

let regular_size path =
  match Unix.lstat path with
  | { Unix.st_kind = Unix.S_REG; st_size; _ } -> Some st_size
  | _ -> None
  | exception Unix.Unix_error _ -> None

let candidates t k ~input_digest =
  List.filter
    (fun (e : entry) -> String.equal e.job t.job && inputs_current ~input_digest e)
    (Option.value (Hashtbl.find_opt t.entries k) ~default:[])

let is_done t k ~input_digest =
  let path = Filename.concat t.dir (frame_name ~ext:t.ext k) in
  match (candidates t k ~input_digest, regular_size path) with
  | [], _ | _, None -> false
  | cs, Some size -> (
      match List.filter (fun e -> e.size = size) cs with
      | [] -> false
      | cs -> (
          match Digest.to_hex (Digest.file path) with
          | md5 -> List.exists (fun e -> String.equal e.md5 md5) cs
          | exception Sys_error _ -> false))

(* What differs between the job an entry was made for and this one, named. *)
let job_change t (e : entry) =
  let shown = function Some "-" | None -> "not given" | Some v -> v in
  let names =
    List.sort_uniq String.compare (List.map fst e.made_with @ List.map fst t.made_with)
  in
  let changed =
    List.filter_map
      (fun n ->
        let before = List.assoc_opt n e.made_with
        and now = List.assoc_opt n t.made_with in
        if String.equal (shown before) (shown now) then None
        else if n = "scene" then Some "the scene (or a file it includes) has changed"
        else Some (Printf.sprintf "%s was %s, is now %s" n (shown before) (shown now)))
      names
  in
  match changed with
  | cs when cs = [] || e.made_with = [] ->
      (* A record of an older lancer, or of the merged view, does not say. *)
      "they were rendered for another version of the scene or other options"
  | cs -> String.concat "; " cs

let why_not_done t k ~input_digest =
  let path = Filename.concat t.dir (frame_name ~ext:t.ext k) in
  match Hashtbl.find_opt t.entries k with
  | None | Some [] -> None
  | Some (latest :: _ as es) -> (
      if is_done t k ~input_digest then None
      else
        match List.filter (fun (e : entry) -> String.equal e.job t.job) es with
        | [] -> Some (job_change t latest)
        | e :: _ -> (
            match
              List.find_opt (fun (f, d) -> not (String.equal (input_digest f) d)) e.inputs
            with
            | Some (f, _) -> Some (Printf.sprintf "%s, which they read, has changed" f)
            | None when regular_size path = None -> Some "their files are missing"
            | None -> Some "their files are not the ones that were written"))

(* ---- Recording ---- *)

let journal_fd t =
  match t.fd with
  | Some fd -> fd
  | None -> (
      match
        Unix.openfile t.journal
          [ Unix.O_WRONLY; Unix.O_APPEND; Unix.O_CREAT; Unix.O_CLOEXEC ]
          0o644
      with
      | fd ->
          t.fd <- Some fd;
          fd
      | exception Unix.Unix_error (e, _, _) ->
          Job_error.user "cannot record frames in %s: %s" t.journal (unix_msg e))

let record t k ~(written : Image.written) ~inputs =
  let size = written.size and md5 = Lazy.force written.md5 in
  let e = { frame = k; job = t.job; made_with = t.made_with; size; md5; inputs } in
  let line = Yojson.Safe.to_string (entry_json ~ext:t.ext e) ^ "\n" in
  Mutex.protect t.lock (fun () ->
      let fd = journal_fd t in
      (* Synced at most once a second (and when closed): an entry whose frame did not reach
         the disk is caught by the frame's MD5 anyway, and a sync per frame would cost a
         millisecond each (8 000 tiny frames: 8 s). *)
      let now = Unix.gettimeofday () in
      let sync = now -. t.synced >= 1. in
      match write_fd ~sync fd line with
      | Ok () ->
          if sync then t.synced <- now;
          add t e
      | Error m ->
          Job_error.user "cannot record %s in %s: %s" (frame_name ~ext:t.ext k) t.journal
            m)

let close t =
  Mutex.protect t.lock (fun () ->
      let fd = t.fd in
      t.fd <- None;
      Option.iter
        (fun fd ->
          let r = sync_fd fd in
          match (r, Unix.close fd) with
          | Ok (), () -> ()
          | Error m, () -> Job_error.user "cannot record frames in %s: %s" t.journal m
          | exception Unix.Unix_error (e, _, _) ->
              Job_error.user "cannot record frames in %s: %s" t.journal (unix_msg e))
        fd)

(* ---- The merged view ---- *)

let drop_view t =
  try Unix.unlink (Filename.concat t.dir view_name) with Unix.Unix_error _ -> ()

let finish t ~input_digest =
  close t;
  read_all t;
  let chosen =
    List.init t.count (fun k ->
        match regular_size (Filename.concat t.dir (frame_name ~ext:t.ext k)) with
        | None -> None
        | Some size ->
            List.find_opt
              (fun e -> e.size = size)
              (List.rev (candidates t k ~input_digest)))
  in
  if List.for_all Option.is_some chosen then (
    let frames =
      List.map
        (fun e ->
          match entry_json ~ext:t.ext (Option.get e) with
          | `Assoc kvs ->
              `Assoc (List.filter (fun (k, _) -> k <> "job" && k <> "made_with") kvs)
          | j -> j)
        chosen
    in
    Files.write_json
      (Filename.concat t.dir view_name)
      (`Assoc
         [ ("scene", `String t.scene); ("job", `String t.job); ("frames", `List frames) ]);
    true)
  else false
