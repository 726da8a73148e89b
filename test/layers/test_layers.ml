(* Reads the dune files of the library's layers and checks that every dependency on a
   lancer library points down. dune itself refuses a cycle; this catches a new arrow that
   would make no cycle but break the layering (the language using the renderer, say). *)

let root = "../.."

let read path =
  let ic = open_in_bin path in
  Fun.protect
    ~finally:(fun () -> close_in ic)
    (fun () -> really_input_string ic (in_channel_length ic))

(* The names in the (libraries …) field of every stanza of a dune file: a dune file is
   s-expressions, and the field's words run to the first unbalanced ')'. *)
let libraries text =
  let re = Str.regexp "(libraries" in
  let rec from pos acc =
    match Str.search_forward re text pos with
    | exception Not_found -> List.rev acc
    | i ->
        let j = ref (i + String.length "(libraries") and depth = ref 0 in
        let b = Buffer.create 64 in
        while !depth >= 0 && !j < String.length text do
          (match text.[!j] with
          | '(' -> incr depth
          | ')' -> decr depth
          | c -> if !depth = 0 then Buffer.add_char b c);
          incr j
        done;
        let words =
          String.split_on_char ' '
            (String.map (function '\n' | '\t' -> ' ' | c -> c) (Buffer.contents b))
          |> List.filter (( <> ) "")
        in
        from !j (List.rev_append words acc)
  in
  from 0 []

(* Layer ranks, bottom first; image and physics share a rank (neither uses the other),
   and so do the renderer and the language (lancer_dsl, in dsl/: beside the renderer,
   under the job layer that joins them). *)
let layers =
  [
    ("math", 0);
    ("diag", 1);
    ("description", 2);
    ("image", 3);
    ("physics", 3);
    ("render", 4);
    ("job", 5);
  ]

let language_rank = 4

let rank lib =
  let prefix = "lancer_" in
  let n = String.length prefix in
  if lib = "lancer_dsl" then Some language_rank
  else if String.length lib > n && String.sub lib 0 n = prefix then
    List.assoc_opt (String.sub lib n (String.length lib - n)) layers
  else if lib = "lancer" || (String.length lib > 7 && String.sub lib 0 7 = "lancer.") then
    Some max_int (* the umbrella, or a public name: never below anything *)
  else None

let test_library (name, r) () =
  let deps = libraries (read (Filename.concat root ("lib/" ^ name ^ "/dune"))) in
  List.iter
    (fun d ->
      match rank d with
      | Some rd when rd >= r ->
          Alcotest.failf
            "lancer_%s (layer %d) uses %s (layer %s): an arrow that does not point down"
            name r d
            (if rd = max_int then "the umbrella" else string_of_int rd)
      | _ -> ())
    deps

let test_language () =
  let deps = libraries (read (Filename.concat root "dsl/dune")) in
  let lancer = List.filter (fun d -> rank d <> None) deps in
  Alcotest.(check (list string))
    "the language's lancer libraries"
    [ "lancer_description"; "lancer_diag"; "lancer_math" ]
    (List.sort compare lancer)

let test_parser () =
  Alcotest.(check (list string))
    "a field over several lines, comments and nested forms" [ "a"; "b"; "c" ]
    (libraries "(library\n (name x)\n (libraries a\n  b (select y from (z -> y.ml)) c))")

let () =
  Alcotest.run "layers"
    [
      ( "lib",
        List.map
          (fun ((n, _) as l) ->
            Alcotest.test_case
              ("lancer_" ^ n ^ " uses only layers under it")
              `Quick (test_library l))
          layers );
      ( "dsl",
        [
          Alcotest.test_case "the language uses only math, diag and description" `Quick
            test_language;
        ] );
      ("reader", [ Alcotest.test_case "reads a libraries field" `Quick test_parser ]);
    ]
