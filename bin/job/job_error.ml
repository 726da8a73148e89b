exception User of string
exception Interrupted of string

let user fmt = Printf.ksprintf (fun s -> raise (User s)) fmt
