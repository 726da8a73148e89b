type mode = Off | Terminal | Lines

type t = {
  mode : mode;
  enabled : bool;
  label : string;
  total : int;
  start : float;
  every : float;  (** seconds between two lines *)
  last : float Atomic.t;  (** when the last line was printed (or when the wait began) *)
  printed : bool Atomic.t;  (** whether a line was printed *)
  rays : int Atomic.t;
  lock : Mutex.t;
}

let interval_variable = "LANCER_PROGRESS_INTERVAL"

(* The interval the variable sets: [None] for "off". *)
let interval ~default =
  match Sys.getenv_opt interval_variable with
  | Some "off" -> None
  | Some v -> (
      match Float.of_string_opt v with
      | Some s when s >= 0. && Float.is_finite s -> Some s
      | _ -> Some default)
  | None -> Some default

let create ?mode ?every ?(wait = false) ~label ~total () =
  let mode =
    match mode with
    | Some m -> m
    | None -> if Unix.isatty Unix.stderr then Terminal else Off
  in
  let every =
    match (every, mode) with
    | Some e, _ -> e
    | None, Lines -> Option.value (interval ~default:2.) ~default:2.
    | None, (Terminal | Off) -> 0.2
  in
  let now = Unix.gettimeofday () in
  {
    mode;
    enabled = mode <> Off;
    label;
    total;
    start = now;
    every;
    last = Atomic.make (if wait then now else 0.);
    printed = Atomic.make false;
    rays = Atomic.make 0;
    lock = Mutex.create ();
  }

let hms s =
  let s = int_of_float (Float.min 1e9 (Float.max 0. s)) in
  if s >= 3600 then Printf.sprintf "%dh%02dm" (s / 3600) (s / 60 mod 60)
  else if s >= 60 then Printf.sprintf "%dm%02ds" (s / 60) (s mod 60)
  else Printf.sprintf "%ds" s

let line ~label ~done_ ~total ?share ~elapsed ~rays () =
  let share =
    match share with
    | Some f -> Float.min 1. (Float.max 0. f)
    | None -> Float.of_int done_ /. Float.of_int (max 1 total)
  in
  let left =
    if share >= 1. then "0s"
    else if share > 0. && elapsed > 0. then hms (elapsed *. (1. -. share) /. share)
    else "?"
  in
  let speed =
    if rays > 0 && elapsed > 0. then
      Printf.sprintf "%.2f M rays/s" (Float.of_int rays /. elapsed /. 1e6)
    else
      Printf.sprintf "%.1f %s/s"
        (if elapsed > 0. then Float.of_int done_ /. elapsed else 0.)
        label
  in
  Printf.sprintf "%s %d/%d (%3.0f%%)  %s  elapsed %s  left %s" label done_ total
    (100. *. share) speed (hms elapsed) left

let update ?(rays = 0) ?share p done_ =
  if p.enabled then
    let all_rays = Atomic.fetch_and_add p.rays rays + rays in
    let now = Unix.gettimeofday () in
    let last = Atomic.get p.last in
    (* The last unit is shown when lines were (on a terminal, always: it is cleared). *)
    let final = done_ = p.total && (p.mode = Terminal || Atomic.get p.printed) in
    if (now -. last >= p.every || final) && Atomic.compare_and_set p.last last now then
      Mutex.protect p.lock (fun () ->
          Atomic.set p.printed true;
          Printf.eprintf "%s%s%s%!"
            (if p.mode = Terminal then "\r\027[K" else "")
            (line ~label:p.label ~done_ ~total:p.total ?share ~elapsed:(now -. p.start)
               ~rays:all_rays ())
            (if p.mode = Lines then "\n" else ""))

let finish p =
  if p.mode = Terminal then
    Mutex.protect p.lock (fun () ->
        prerr_string "\r\027[K";
        flush stderr)

(* ---- What a command's options ask for ---- *)

(* Without a terminal and without --progress, a line every few seconds once a command
   has run that long: a short command stays silent, a long one is seen in a log. *)
let quiet_interval = 5.

let for_options (o : Options.t) ~label ~total =
  if o.quiet then create ~mode:Off ~label ~total ()
  else if Unix.isatty Unix.stderr then create ~mode:Terminal ~label ~total ()
  else if o.progress then create ~mode:Lines ~label ~total ()
  else
    match interval ~default:quiet_interval with
    | None -> create ~mode:Off ~label ~total ()
    | Some every -> create ~mode:Lines ~every ~wait:true ~label ~total ()

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
