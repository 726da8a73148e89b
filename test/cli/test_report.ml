(* The one way lancer reports a failure (Job_error.describe): the text and exit status of each kind,
   as doc/reference/command-line.md ("Exit status and errors") documents them; and a
   program's scenes as the job layer gets them (Program.as_scenes). *)
open Lancer

let contains s sub =
  let n = String.length s and m = String.length sub in
  let rec go i = i + m <= n && (String.sub s i m = sub || go (i + 1)) in
  go 0

let outcome = Alcotest.(pair string int)

let statuses () =
  Alcotest.check outcome "a user error" ("lancer: no such file\n", 1)
    (Job_error.describe (Job_error.User "no such file"));
  Alcotest.check outcome "a file the system refuses"
    ("lancer: out.png: No space\n", 1)
    (Job_error.describe (Sys_error "out.png: No space"));
  Alcotest.check outcome "an interrupt"
    ("\nlancer: interrupted; no output was written\n", 130)
    (Job_error.describe Sys.Break);
  Alcotest.check outcome "an interrupt, saying what became of the output"
    ("\nlancer: the frames are kept\n", 130)
    (Job_error.describe ~interrupted:"the frames are kept" Sys.Break);
  Alcotest.check outcome "an interrupt during the final write"
    ("\nlancer: interrupted; a.png was written in full first\n", 130)
    (Job_error.describe (Job_error.Interrupted "a.png was written in full first"));
  Alcotest.(check int) "out of memory" 1 (snd (Job_error.describe Out_of_memory));
  let text, status = Job_error.describe Not_found in
  Alcotest.(check int) "anything else is an internal error" 2 status;
  Alcotest.(check bool)
    ("named a bug, to report: " ^ text)
    true
    (contains text "internal error: Not_found" && contains text "please report it")

let scene_errors () =
  let e1 = Diagnostic.file_error "a.rts" "not a scene"
  and e2 = Diagnostic.file_error "b.rts" "not a scene either" in
  let each = Format.asprintf "%a" Diagnostic.pp in
  Alcotest.check outcome "every located error, as the language prints it"
    (each e1 ^ "\n" ^ each e2, 1)
    (Job_error.describe (Job_error.Scene { errors = [ e1; e2 ]; note = "" }));
  Alcotest.check outcome "and the note after them"
    (each e1 ^ "lancer: 1 of the 3 frames checked (0..2) fail: 1\n", 1)
    (Job_error.describe
       (Job_error.Scene
          { errors = [ e1 ]; note = "1 of the 3 frames checked (0..2) fail: 1" }));
  Alcotest.(check string)
    "a worker's failure is the message alone" "cannot write"
    (Job_error.message (Job_error.User "cannot write"));
  Alcotest.(check string)
    "or the internal error" "internal error: Not_found" (Job_error.message Not_found)

(* A scene that only fails at frame 3 (a radius of 0): the job layer sees the failure as the job
   layer's own located error, and the overrides apply to the scenes that evaluate. *)
let source () =
  let text =
    {|settings { width: 20, height: 10 }
animation { fps: 4, frames: 4 }
camera { position: (0, 1, -5), look_at: (0, 1, 0) }
light { position: (-3, 5, -4) }
sphere { center: (0, 1, 0), radius: 1.5 - frame * 0.5 }
|}
  in
  let prog =
    match Program.load_string ~filename:"frames.rts" text with
    | Ok p -> p
    | Error _ -> Alcotest.fail "the scene does not load"
  in
  let src = Program.as_scenes ~builtin:false prog in
  Alcotest.(check (option (pair (float 0.) int)))
    "its animation"
    (Some (4., 4))
    src.animation;
  let sc, _ =
    Scenes.scene src { Overrides.none with width = Some 8 } ~time:0.25 ~frame:1
  in
  Alcotest.(check (pair int int))
    "frame 1, overridden" (8, 10)
    (sc.settings.width, sc.settings.height);
  match src.evaluate ~progress:None ~cancel:None ~time:0.75 ~frame:3 with
  | _ -> Alcotest.fail "frame 3 evaluated"
  | exception Job_error.Scene { errors; _ } ->
      Alcotest.(check bool)
        "located in the file" true
        (errors <> []
        && List.for_all (fun (e : Diagnostic.t) -> e.file = "frames.rts") errors)

let () =
  Alcotest.run "report"
    [
      ( "report",
        [
          Alcotest.test_case "statuses and messages" `Quick statuses;
          Alcotest.test_case "located errors and their note" `Quick scene_errors;
        ] );
      ("source", [ Alcotest.test_case "a program as the job layer sees it" `Quick source ]);
    ]
