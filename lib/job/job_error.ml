exception User of string
exception Scene of { errors : Diagnostic.t list; note : string }
exception Interrupted of string

let user fmt = Printf.ksprintf (fun s -> raise (User s)) fmt

(* ---- What lancer says of a failure ---- *)

let errors_text errs =
  String.concat "\n" (List.map (Format.asprintf "%a" Diagnostic.pp) errs)

let scene_text errors note =
  errors_text errors ^ if note = "" then "" else "lancer: " ^ note ^ "\n"

let internal e =
  Printf.sprintf
    "lancer: internal error: %s\n\
     This is a bug in lancer; please report it with the scene and the command at\n\
     https://github.com/lancer/lancer/issues\n"
    (Printexc.to_string e)

(* Domain.spawn fails so when the system has no room for a new domain's thread or the
   runtime none for its state: memory, not a bug. *)
let domain_failure m =
  String.starts_with ~prefix:"failed to create domain" m
  || String.equal m "failed to allocate domain"

let out_of_memory_text () =
  match Address_space.limit () with
  | Some bytes ->
      Printf.sprintf
        "lancer: out of memory under the address-space limit (ulimit -v %d); raise it, \
         or try a smaller image, fewer objects or fewer --domains\n"
        (bytes / 1024)
  | None | (exception _) ->
      "lancer: out of memory (try a smaller image or fewer objects)\n"

let describe ?(interrupted = "interrupted; no output was written")
    ?(out_of_memory = out_of_memory_text) = function
  | User m -> ("lancer: " ^ m ^ "\n", 1)
  | Scene { errors; note } -> (scene_text errors note, 1)
  | Sys.Break | Fun.Finally_raised Sys.Break -> ("\nlancer: " ^ interrupted ^ "\n", 130)
  | Interrupted what -> ("\nlancer: interrupted; " ^ what ^ "\n", 130)
  | Out_of_memory -> (out_of_memory (), 1)
  | Failure m when domain_failure m -> (out_of_memory (), 1)
  | Sys_error m -> ("lancer: " ^ m ^ "\n", 1)
  | e -> (internal e, 2)

let message = function
  | User m -> m
  | Scene { errors; note } -> scene_text errors note
  | e -> "internal error: " ^ Printexc.to_string e
