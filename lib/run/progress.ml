type mode = Off | Terminal | Lines

type t = {
  mode : mode;
  enabled : bool;
  label : string;
  total : int;
  start : float;
  last : float Atomic.t;
  rays : int Atomic.t;
  lock : Mutex.t;
}

let create ?mode ~label ~total () =
  let mode =
    match mode with
    | Some m -> m
    | None -> if Unix.isatty Unix.stderr then Terminal else Off
  in
  let now = Unix.gettimeofday () in
  {
    mode;
    enabled = mode <> Off;
    label;
    total;
    start = now;
    last = Atomic.make 0.;
    rays = Atomic.make 0;
    lock = Mutex.create ();
  }

let hms s =
  let s = int_of_float (Float.max 0. s) in
  if s >= 3600 then Printf.sprintf "%dh%02dm" (s / 3600) (s / 60 mod 60)
  else if s >= 60 then Printf.sprintf "%dm%02ds" (s / 60) (s mod 60)
  else Printf.sprintf "%ds" s

let update ?(rays = 0) p done_ =
  if p.enabled then
    let all_rays = Atomic.fetch_and_add p.rays rays + rays in
    let now = Unix.gettimeofday () in
    let last = Atomic.get p.last in
    let every = if p.mode = Lines then 2. else 0.2 in
    if (now -. last >= every || done_ = p.total) && Atomic.compare_and_set p.last last now
    then
      Mutex.protect p.lock (fun () ->
          let el = now -. p.start in
          let rate = if el > 0. then Float.of_int done_ /. el else 0. in
          let left = if rate > 0. then Float.of_int (p.total - done_) /. rate else 0. in
          let speed =
            if all_rays > 0 && el > 0. then
              Printf.sprintf "%.2f M rays/s" (Float.of_int all_rays /. el /. 1e6)
            else Printf.sprintf "%.1f %s/s" rate p.label
          in
          Printf.eprintf "%s%s %d/%d (%3.0f%%)  %s  elapsed %s  left %s%s%!"
            (if p.mode = Terminal then "\r\027[K" else "")
            p.label done_ p.total
            (100. *. Float.of_int done_ /. Float.of_int (max 1 p.total))
            speed (hms el) (hms left)
            (if p.mode = Lines then "\n" else ""))

let finish p =
  if p.mode = Terminal then
    Mutex.protect p.lock (fun () ->
        prerr_string "\r\027[K";
        flush stderr)

(* ---- What a command's options ask for ---- *)

let for_options (o : Options.t) ~label ~total =
  let mode =
    if o.quiet then Off
    else if Unix.isatty Unix.stderr then Terminal
    else if o.progress then Lines
    else Off
  in
  create ~mode ~label ~total ()

(* What the build is doing, on the progress channel: one line redrawn in place on a
   terminal, lines with --progress, nothing otherwise. *)
let building (o : Options.t) what =
  match (o.quiet, Unix.isatty Unix.stderr, o.progress) with
  | true, _, _ -> ()
  | false, true, _ -> Printf.eprintf "\r\027[Kbuilding: %s…%!" what
  | false, false, true -> Printf.eprintf "building: %s\n%!" what
  | false, false, false -> ()

let built (o : Options.t) =
  if (not o.quiet) && Unix.isatty Unix.stderr then Printf.eprintf "\r\027[K%!"

let writing (o : Options.t) path f =
  let path = if path = "-" then "the image to standard output" else path in
  (match (o.quiet, Unix.isatty Unix.stderr, o.progress) with
  | true, _, _ | false, false, false -> ()
  | false, true, _ -> Printf.eprintf "\r\027[Kwriting %s…%!" path
  | false, false, true -> Printf.eprintf "writing %s\n%!" path);
  Fun.protect ~finally:(fun () -> built o) f

let build o f =
  let t0 = Unix.gettimeofday () in
  let r = Fun.protect ~finally:(fun () -> built o) (fun () -> f (building o)) in
  (r, Unix.gettimeofday () -. t0)
