let user = Job_error.user

(* A directory the system will not let this process create files in (permissions, a
   read-only file system, /proc): found by creating and removing an empty file there, as
   the temporary file of the write will be, before any rendering. *)
let probe_directory path =
  let dir = Filename.dirname path in
  let special =
    match (Unix.stat path).st_kind with
    | Unix.S_REG | Unix.S_DIR -> false
    | _ -> true
    | exception Unix.Unix_error _ -> false
  in
  if not special then
    let probe =
      Filename.concat dir
        (Printf.sprintf ".lancer-probe-%d-%d" (Unix.getpid ()) (Random.bits ()))
    in
    match
      Unix.openfile probe
        [ Unix.O_WRONLY; Unix.O_CREAT; Unix.O_EXCL; Unix.O_CLOEXEC ]
        0o600
    with
    | fd -> (
        Unix.close fd;
        try Unix.unlink probe with Unix.Unix_error _ -> ())
    | exception Unix.Unix_error (e, _, _) ->
        user "cannot write %s: %s (in directory %s)" path (Unix.error_message e) dir

let check_writable path =
  (match Image.check_writable path with
  | Ok () -> ()
  | Error m -> raise (Job_error.User m));
  probe_directory path

(* The temporary files that a killed run of this machine left where this one is about to
   write: removed before the first write, each named on stderr. *)
let sweep dir =
  List.iter
    (fun (p, pid) ->
      Printf.eprintf
        "lancer: removed %s, a temporary file left by process %d, which is no longer \
         running\n\
         %!"
        p pid)
    (Safe_file.remove_stale dir)

(* Where a path leads, for comparing two names of one file: the file itself resolved when
   it exists, else its directory, so that ./a.png, a.png and a path through a symbolic
   link agree. *)
let where p =
  match Unix.realpath p with
  | r -> r
  | exception Unix.Unix_error _ -> (
      match Unix.realpath (Filename.dirname p) with
      | d -> Filename.concat d (Filename.basename p)
      | exception Unix.Unix_error _ -> p)

type identity = { path : string; resolved : string; inode : (int * int) option }

let identity path =
  {
    path;
    resolved = where path;
    inode =
      (match Unix.stat path with
      | st -> Some (st.st_dev, st.st_ino)
      | exception Unix.Unix_error _ -> None);
  }

(* Also two hard links to one file. *)
let same a b =
  a.resolved = b.resolved
  || match (a.inode, b.inode) with Some x, Some y -> x = y | _ -> false

let refuse ~reads ~names (w, what) =
  List.iter
    (fun (r, rwhat) ->
      if same w r then
        if r.path = w.path then
          user
            "refusing to write %s to %s: that file is %s, read by this run; choose \
             another name"
            what w.path rwhat
        else
          user
            "refusing to write %s to %s: that file is %s (%s), read by this run; choose \
             another name"
            what w.path r.path rwhat)
    reads;
  List.iter
    (fun n ->
      if same w n then
        user
          "refusing to write %s to %s: the scene names that file (\"%s\"), so some frame \
           may read it; choose another name"
          what w.path n.path)
    names

let guard_writes ?(distinct = true) ?(names = []) ~reads writes =
  let reads = List.map (fun (p, what) -> (identity p, what)) reads in
  let names = List.map identity names in
  let writes = List.map (fun (p, what) -> (identity p, what)) writes in
  List.iter
    (fun ((w, _) as write) ->
      check_writable w.path;
      refuse ~reads ~names write)
    writes;
  List.iter sweep
    (List.sort_uniq String.compare
       (List.map (fun (w, _) -> Filename.dirname w.path) writes));
  if distinct then
    let rec pairs = function
      | [] -> ()
      | (a, wa) :: rest ->
          List.iter
            (fun (b, wb) ->
              if same a b then
                user "%s and %s would be the same file, %s: give each its own name" wa wb
                  a.path)
            rest;
          pairs rest
    in
    pairs writes

let refuse_overwrite ~reads path what =
  refuse
    ~reads:(List.map (fun (p, what) -> (identity p, what)) reads)
    ~names:[]
    (identity path, what)

(* A write is not cut short by an interrupt: an exception raised half-way through the
   encoder or the rename's clean-up would leave a temporary file or a lie. The interrupt
   is answered once the file is whole. *)
let uninterrupted ?cancel what write =
  match cancel with
  | None -> write ()
  | Some c ->
      Cancel.check c;
      let r = Cancel.deferring c write in
      if Cancel.cancelled c then
        raise (Job_error.Interrupted (what ^ " was written in full first"));
      r

let write_image ?cancel ?bits ?alpha ?crop ?record path (sc : Scene.t) fb =
  let text = Option.map Provenance.text record in
  uninterrupted ?cancel path (fun () ->
      match
        Image.save_written ~gamma:sc.settings.gamma ?bits ?alpha ?crop ?text path fb
      with
      | Ok w -> w
      | Error m -> raise (Job_error.User m))

let write_json ?cancel path j =
  uninterrupted ?cancel path (fun () ->
      match
        Image.write_atomic path (fun oc ->
            Yojson.Safe.pretty_to_channel oc j;
            output_char oc '\n')
      with
      | Ok () -> ()
      | Error m -> raise (Job_error.User m))
