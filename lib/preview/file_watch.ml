(* Watching the files a preview shows: inotify on their directories, or polling. *)

open Lwt.Infix

let split p = (Filename.dirname p, Filename.basename p)

(* Call [changed] (at most every few tens of milliseconds) when a file of [inputs ()]
   is written, replaced or removed: inotify on their directories (an editor that saves
   by renaming replaces the file itself), polling their status twice a second where
   inotify is not available or [poll] asks for it. *)
let watch ~poll inputs changed =
  let debounce = ref None in
  let fire () =
    match !debounce with
    | Some _ -> ()
    | None ->
        debounce :=
          Some
            ( Lwt_unix.sleep 0.03 >|= fun () ->
              debounce := None;
              changed () )
  in
  let polling () =
    (* Modification time (to the nanosecond, as an integer), size and inode: a file
       rewritten in place or replaced by a rename. *)
    let stamp p =
      match Unix.stat p with
      | s -> Some (Int64.of_float (s.st_mtime *. 1e9), s.st_size, s.st_ino)
      | exception Unix.Unix_error _ -> None
    in
    let snapshot () = List.map (fun p -> (p, stamp p)) (inputs ()) in
    let rec go last =
      Lwt_unix.sleep 0.5 >>= fun () ->
      let now = snapshot () in
      (* A new input set (after a reload) is a new baseline, except for the files it shares. *)
      let differs =
        List.exists
          (fun (p, s) ->
            match List.assoc_opt p last with Some s' -> s <> s' | None -> false)
          now
      in
      if differs then fire ();
      go now
    in
    go (snapshot ())
  in
  let inotify fd =
    let watched = Hashtbl.create 4 in
    let update () =
      List.iter
        (fun p ->
          let d, _ = split p in
          if not (Hashtbl.mem watched d) then
            match
              Lwt_inotify.add_watch' fd d
                Inotify.[ S_Close_write; S_Moved_to; S_Create; S_Delete; S_Modify ]
            with
            | w -> Hashtbl.replace watched d (Inotify.int_of_watch w)
            | exception Unix.Unix_error _ -> ())
        (inputs ())
    in
    let dir_of w =
      Hashtbl.fold
        (fun d w' acc -> if w' = Inotify.int_of_watch w then Some d else acc)
        watched None
    in
    let rec refresh () =
      update ();
      Lwt_unix.sleep 0.25 >>= refresh
    in
    let rec go () =
      Lwt_inotify.read fd >>= fun (w, kinds, _, name) ->
      let relevant =
        List.mem Inotify.Q_overflow kinds
        ||
        match (dir_of w, name) with
        | Some d, Some n -> List.exists (fun p -> split p = (d, n)) (inputs ())
        | _ -> false
      in
      if relevant then fire ();
      go ()
    in
    Lwt.pick [ refresh (); go () ]
  in
  if poll then polling ()
  else match Lwt_inotify.create' () with fd -> inotify fd | exception _ -> polling ()
