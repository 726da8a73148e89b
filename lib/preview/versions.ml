(* The versions of lancer watch's preview and their passes. Two sides share one record:
   the server (Lwt, on the main domain) and the renderer (its own domain, with the render
   pool). The server asks for a new version by raising [wanted] and cancelling the token
   of the version being rendered, which the render polls as any render does (between
   tiles and inside them). The renderer publishes server-sent events into [outbox] and
   wakes the server through a pipe. *)

open Lancer

exception Cancelled

type params = { quality : Quality.t option; frame : int; play : bool }

type shared = {
  lock : Mutex.t;
  cond : Condition.t;
  wanted : int Atomic.t;  (** the newest version asked for *)
  mutable started : int;  (** the version the renderer last took *)
  mutable current : Cancel.t;  (** the token of that version's render *)
  mutable reload : bool;  (** read the files again *)
  mutable params : params;
  mutable outbox : (string * string) list;  (** (event, JSON data), newest first *)
  mutable images : (int * string) list;
      (** (sequence number, PNG bytes), newest first, a few *)
  mutable inputs : string list;  (** the files to watch *)
  wake_w : Unix.file_descr;
}

let kept_images = 8

let with_lock sh f =
  Mutex.lock sh.lock;
  Fun.protect ~finally:(fun () -> Mutex.unlock sh.lock) f

(* Ask for a new version; [reload] when the files changed. *)
let request sh ?(reload = false) f =
  with_lock sh (fun () ->
      sh.params <- f sh.params;
      if reload then sh.reload <- true;
      Atomic.incr sh.wanted;
      Cancel.cancel sh.current;
      Condition.signal sh.cond)

let wake sh =
  try ignore (Unix.write_substring sh.wake_w "x" 0 1) with Unix.Unix_error _ -> ()

let publish sh ev data =
  with_lock sh (fun () -> sh.outbox <- (ev, Yojson.Safe.to_string data) :: sh.outbox);
  wake sh

(* ---------------------------------------------------------------------------------- *)
(* The renderer *)

(* The PNG bytes of an image, through camlimages and a file in a private directory. *)
let png_bytes tmp (sc : Scene.t) (fb : Framebuffer.t) =
  let path = Filename.concat tmp "view.png" in
  match
    Image.write_rgb8 path fb.width fb.height (Image.to_bytes sc.settings.gamma fb)
  with
  | Error m -> failwith m
  | Ok () -> In_channel.with_open_bin path In_channel.input_all

(* One pass of a version through the one tile loop, over the pool: the whole image, or
   with [stride = k] one sample per k×k block, at the block's middle pixel (a complete
   picture of ⌈w/k⌉×⌈h/k⌉ pixels with exactly the camera of the full image). A newer
   version cancels it at its next poll. *)
let render_pass pool cancel ?stride sc =
  try Render.render ?pool ~cancel ?stride sc
  with Sys.Break when Cancel.cancelled cancel -> raise Cancelled

(* What the page shows of the settings of the image shown: [chosen] when --max-error
   chose them. *)
let knobs ?chosen (o : Options.t) (sc : Scene.t) =
  let s = sc.settings in
  `Assoc
    [
      ( "quality",
        `String
          (match (chosen, o.quality) with
          | Some c, _ -> c
          | None, Some q -> Quality.to_string q
          | None, None -> "the scene's own") );
      ("size", `String (Printf.sprintf "%d×%d" s.width s.height));
      ("samples", `String (Printf.sprintf "%d×%d" s.samples s.samples));
      ( "adaptive",
        `String (if s.adaptive > 0. then Printf.sprintf "%g" s.adaptive else "off") );
      ("depth", `Int s.depth);
    ]

let quality_name = function Some q -> Quality.to_string q | None -> "scene"

(* What watch shows of an error located in a file: all of it for a file in the scene's
   directory tree, and only its file, line, column and message for a file outside it
   (unless [any_line]), so that a scene that includes any file the user may read cannot
   have its lines shown on the page. The tree and the file are taken as the system
   resolves them (symbolic links followed); a file that cannot be resolved is outside. *)
let shown_errors ~any_line scene =
  let root =
    try Some (Unix.realpath (Filename.dirname scene)) with Unix.Unix_error _ -> None
  in
  let inside file =
    match (root, Unix.realpath file) with
    | Some r, p -> p = r || String.starts_with ~prefix:(if r = "/" then r else r ^ "/") p
    | None, _ -> false
    | exception Unix.Unix_error _ -> false
  in
  fun (e : Diagnostic.t) ->
    if any_line || inside e.file then e else { e with source_line = None }

(* The text of an error that ends a version, each located error through [show_error]. *)
let describe show_error e =
  fst
    (Job_error.describe
       (match e with
       | Job_error.Scene { errors; note } ->
           Job_error.Scene { errors = List.map show_error errors; note }
       | e -> e))

(* Load the scene: the program, or the text lancer prints for its errors and the files
   they name (to be watched too). *)
let load show_error path =
  match Scene_file.read (Some path) with
  | exception (Job_error.User _ as e) -> Error (describe show_error e, [])
  | filename, text -> (
      match Program.load_string ~filename text with
      | Ok p -> Ok p
      | Error errs ->
          Error
            ( Job_error.errors_text (List.map show_error errs),
              List.map (fun (e : Diagnostic.t) -> e.file) errs ))

type version = { t0 : float; reload : bool; params : params; cancel : Cancel.t }

(* An error that ends a version: on the page, and in the terminal running the server (even
   with --quiet, which silences only the timings), as lancer prints it elsewhere. *)
let fail sh text =
  publish sh "failure" (`Assoc [ ("text", `String text) ]);
  prerr_string (if String.ends_with ~suffix:"\n" text then text else text ^ "\n");
  flush stderr

let log quiet fmt = Printf.ksprintf (fun s -> if not quiet then print_endline s) fmt

let render_version ?max_error sh show_error (o : Options.t) pool tmp prog seq v =
  let cancelled () = Cancel.cancelled v.cancel in
  let path = Option.get o.scene in
  let failed text files =
    with_lock sh (fun () ->
        sh.inputs <- List.sort_uniq compare ((path :: files) @ sh.inputs));
    fail sh text
  in
  let t_build = Unix.gettimeofday () in
  let loaded =
    match !prog with
    | Some p when not v.reload -> Ok p
    | _ -> (
        match load show_error path with
        | Ok p ->
            prog := Some p;
            with_lock sh (fun () -> sh.inputs <- Program.inputs p);
            wake sh;
            Ok p
        | Error (text, files) ->
            (* The next version, whatever it changes, reads the files again. *)
            prog := None;
            Error (text, files))
  in
  match loaded with
  | Error (text, files) -> failed text files
  | Ok p -> (
      let fps, frames =
        match Program.animation p with Some (fps, n) -> (fps, n) | None -> (24., 1)
      in
      let frame = max 0 (min (frames - 1) v.params.frame) in
      let time = Float.of_int frame /. fps in
      let o = { o with quality = v.params.quality } in
      let coarse_q =
        match o.quality with Some Quality.Draft -> Quality.Draft | _ -> Quality.Preview
      in
      (* The scene is evaluated once; each pass's options apply over it (and an open
         shutter's instants are made for each, as many as its options say). *)
      let evaluated =
        let src = Scene_file.source o p in
        try
          let sc, _ = src.evaluate ~progress:None ~cancel:None ~time ~frame in
          let coarse = { o with quality = Some coarse_q; samples = None } in
          let pass o =
            let ov = Options.overrides o in
            fst (Scenes.with_instants src ov (Overrides.apply ov sc) ~time ~frame)
          in
          let plain = pass o in
          (* With --max-error, the settings it chooses, searched once the coarse passes
             are shown. *)
          let final =
            match max_error with
            | None -> lazy plain
            | Some m ->
                lazy
                  (let o = { o with quality = None } in
                   let c =
                     try
                       Budget.choose ~cancel:v.cancel ~pool ~domains:1 o src (pass o)
                         ~time ~frame m
                     with Sys.Break when Cancel.cancelled v.cancel -> raise Cancelled
                   in
                   if not o.quiet then print_endline (Budget.text c);
                   c.scene)
          in
          Ok (plain, final, pass coarse)
        with (Job_error.User _ | Job_error.Scene _) as e ->
          Error (describe show_error e)
      in
      (* A frame may read files that frame 0 does not (an image chosen by [frame]): they
         are watched from the first version that reads them. *)
      with_lock sh (fun () ->
          sh.inputs <- List.sort_uniq compare (Program.inputs p @ sh.inputs));
      match evaluated with
      | Error text -> failed text []
      | Ok (sc, final, coarse) ->
          let build = Unix.gettimeofday () -. t_build in
          publish sh "ok" (`Assoc []);
          publish sh "scene"
            (`Assoc
               [
                 ("file", `String path);
                 ("quality", `String (quality_name o.quality));
                 ("frame", `Int frame);
                 ( "animation",
                   match Program.animation p with
                   | Some (fps, n) -> `Assoc [ ("fps", `Float fps); ("frames", `Int n) ]
                   | None -> `Null );
               ]);
          let summary = try Program.summary p sc with _ -> "" in
          let base = Filename.remove_extension (Filename.basename path) in
          let name =
            if frames > 1 then Printf.sprintf "%s_%04d.png" base frame else base ^ ".png"
          in
          let final_differs =
            max_error <> None
            ||
            match o.quality with
            | Some (Quality.Draft | Quality.Preview) -> false
            | _ -> true
          in
          let passes =
            [
              (`Coarse 8, "1 sample per 8×8 pixels");
              (`Coarse 4, "1 sample per 4×4 pixels");
              (`Coarse 2, "1 sample per 2×2 pixels");
              ( `Full (lazy coarse),
                if final_differs then Quality.to_string coarse_q ^ " quality" else "done"
              );
            ]
            @ if final_differs && not v.params.play then [ (`Full final, "done") ] else []
          in
          let n = List.length passes in
          let first = ref None in
          let done_passes = ref [] in
          List.iteri
            (fun idx (pass, label) ->
              let t = Unix.gettimeofday () in
              let shown, fb, st =
                match pass with
                | `Coarse k ->
                    let fb, st = render_pass pool v.cancel ~stride:k coarse in
                    (coarse, fb, st)
                | `Full s ->
                    let s = Lazy.force s in
                    let fb, st = render_pass pool v.cancel s in
                    (s, fb, st)
              in
              let secs = Unix.gettimeofday () -. t in
              if cancelled () then raise Cancelled;
              let bytes = png_bytes tmp shown fb in
              incr seq;
              let s = !seq in
              with_lock sh (fun () ->
                  sh.images <-
                    (s, bytes) :: List.filteri (fun i _ -> i < kept_images - 1) sh.images);
              let last = idx = n - 1 in
              if !first = None then first := Some (Unix.gettimeofday () -. v.t0);
              let pname =
                match pass with
                | `Coarse k -> Printf.sprintf "%d×%d blocks" k k
                | `Full _ when last -> "full image"
                | `Full _ -> label
              in
              done_passes :=
                `Assoc
                  [
                    ("name", `String pname);
                    ("seconds", `Float secs);
                    ("rays", `Int (Counters.total_rays st));
                  ]
                :: !done_passes;
              publish sh "image"
                (`Assoc
                   [
                     ("seq", `Int s);
                     ( "label",
                       `String
                         (if last then
                            Printf.sprintf "%s (%d×%d)" label sc.settings.width
                              sc.settings.height
                          else label) );
                     ("last", `Bool last);
                     ("frame", `Int frame);
                     ("width", `Int sc.settings.width);
                     ("height", `Int sc.settings.height);
                     ("name", `String name);
                   ]);
              if last then (
                let rays = Counters.total_rays st in
                publish sh "stats"
                  (`Assoc
                     [
                       ("build_seconds", `Float build);
                       ("passes", `List (List.rev !done_passes));
                       ( "rays_per_second",
                         `Float (if secs > 0. then Float.of_int rays /. secs else 0.) );
                       ( "knobs",
                         knobs
                           ?chosen:
                             (match (max_error, pass) with
                             | Some m, `Full _ when not v.params.play ->
                                 Some
                                   (Printf.sprintf "chosen by --max-error %g"
                                      (Budget.limit_value m))
                             | _ -> None)
                           o shown );
                       ("summary", `String summary);
                     ]);
                log o.quiet
                  "%s: frame %d, %d×%d: first image %.3f s after the change, full image \
                   %.3f s"
                  path frame sc.settings.width sc.settings.height
                  (Option.value !first ~default:0.)
                  (Unix.gettimeofday () -. v.t0)))
            passes)

let renderer ?max_error sh show_error (o : Options.t) ~domains ~tmp () =
  Render.with_pool domains (fun pool ->
      let prog = ref None and seq = ref 0 in
      let rec loop () =
        let v =
          with_lock sh (fun () ->
              while Atomic.get sh.wanted = sh.started do
                Condition.wait sh.cond sh.lock
              done;
              let gen = Atomic.get sh.wanted in
              sh.started <- gen;
              sh.current <- Cancel.create ();
              let r = sh.reload in
              sh.reload <- false;
              {
                t0 = Unix.gettimeofday ();
                reload = r;
                params = sh.params;
                cancel = sh.current;
              })
        in
        (try render_version ?max_error sh show_error o pool tmp prog seq v with
        | Cancelled -> ()
        | e -> fail sh (describe show_error e));
        loop ()
      in
      loop ())

(* ---------------------------------------------------------------------------------- *)
(* What the server sees of it *)

type t = shared

let create (o : Options.t) ~wake =
  {
    lock = Mutex.create ();
    cond = Condition.create ();
    wanted = Atomic.make 1;
    started = 0;
    current = Cancel.create ();
    reload = true;
    params = { quality = o.quality; frame = 0; play = false };
    outbox = [];
    images = [];
    inputs = Option.to_list o.scene;
    wake_w = wake;
  }

let start ?max_error sh (o : Options.t) ~any_line ~domains ~tmp =
  let show_error = shown_errors ~any_line (Option.get o.scene) in
  ignore (Domain.spawn (renderer ?max_error sh show_error o ~domains ~tmp))

let events sh =
  with_lock sh (fun () ->
      let e = List.rev sh.outbox in
      sh.outbox <- [];
      e)

let image sh k = with_lock sh (fun () -> List.assoc_opt k sh.images)
let inputs sh = with_lock sh (fun () -> sh.inputs)
