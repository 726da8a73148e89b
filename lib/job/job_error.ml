exception User of string
exception Scene of { errors : Diagnostic.t list; note : string }
exception Interrupted of string

let user fmt = Printf.ksprintf (fun s -> raise (User s)) fmt
