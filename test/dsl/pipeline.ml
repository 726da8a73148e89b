open Lancer_dsl

let file = "test.rts"

let parse text =
  match Syntax.parse ~file text with
  | Ok stmts -> stmts
  | Error e -> Alcotest.failf "syntax error: %s" (Error.to_string e)

let sources text =
  let s = Hashtbl.create 1 in
  Hashtbl.replace s file text;
  s

let checked ?schema ?types text =
  Check.program ?schema ?types ~sources:(sources text) (parse text)

let both ?schema ?types ?(time = 0.) ?(frame = 0) ?objects text =
  let p, static = checked ?schema ?types text in
  let r =
    Run.run ?objects ~file ~sources:(sources text) ~time ~frame (Compile.program p)
  in
  (static, r)

let run ?schema ?types ?time ?frame ?objects text =
  match both ?schema ?types ?time ?frame ?objects text with
  | [], r -> r
  | static, Ok _ -> Error (Run.sort_errors static)
  | static, Error es -> Error (Run.sort_errors (static @ es))

let run_errors ?types text =
  match both ?types ~objects:false text with _, Ok _ -> [] | _, Error es -> es

let errors ?schema ?types text =
  match run ?schema ?types ~objects:false text with Ok _ -> [] | Error es -> es
