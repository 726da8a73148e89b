let user = Job_error.user
let showcase = Showcase.text
let showcase_file = "showcase.rts"

(* A scene named "-" is read from standard input, once however often it is asked for; its
   errors are located in "<stdin>" and its includes are found from the current
   directory. *)
let stdin_name = "<stdin>"

let stdin_text =
  lazy
    (if Unix.isatty Unix.stdin then
       prerr_endline "lancer: reading the scene from standard input (end it with Ctrl-D)";
     set_binary_mode_in stdin true;
     try In_channel.input_all stdin
     with Sys_error m -> user "cannot read the scene from standard input: %s" m)

let read = function
  | None -> (showcase_file, showcase)
  | Some "-" -> (stdin_name, Lazy.force stdin_text)
  | Some path ->
      if not (Sys.file_exists path) then user "%s: no such file" path;
      if Sys.is_directory path then user "%s: is a directory, not a scene file" path;
      Option.iter
        (fun m -> user "%s: cannot read the scene: %s" path m)
        (Program.source_problem path);
      let text =
        try In_channel.with_open_bin path In_channel.input_all
        with Sys_error m -> user "%s" m
      in
      (path, text)

(* An exact simulation that gave up after Physics.max_events is worth a warning: the
   bodies move on without colliding after that. *)
let warn_truncated prog =
  Option.iter
    (fun time ->
      Printf.eprintf
        "lancer: warning: the physics simulation stopped handling collisions after %d \
         events (at %.6g s); bodies fly freely from there\n\
         %!"
        Physics.max_events time)
    (Program.truncated_physics prog)

let load_source ?single ?progress ?digests (filename, text) =
  match Program.load_string ?single ?progress ?digests ~filename text with
  | Ok p ->
      warn_truncated p;
      p
  | Error errs when filename = showcase_file && text == showcase ->
      user "the built-in showcase does not load:\n%s" (Job_error.errors_text errs)
  | Error errors -> raise (Job_error.Scene { errors; note = "" })

let load_bundle b =
  match Program.load_bundle b with
  | Ok p -> p
  | Error errors -> raise (Job_error.Scene { errors; note = "" })

let load ?single ?progress ?digests scene =
  load_source ?single ?progress ?digests (read scene)

let source (o : Options.t) prog = Program.as_scenes ~builtin:(o.scene = None) prog

let default_output (o : Options.t) =
  match (o.output, o.scene) with
  | Some p, _ -> p
  | None, None -> "showcase.png"
  | None, Some "-" ->
      user
        "a scene read from standard input has no name to make the image's from: give one \
         with -o FILE"
  | None, Some s -> Filename.remove_extension (Filename.basename s) ^ ".png"
