module Schema = Lancer_dsl.Schema

let default_text : Schema.default -> string = function
  | Required -> "required"
  | Value v -> Printf.sprintf "`%s`" v
  | Absent s -> s

let meaning (fl : Schema.field) =
  let c = Schema.condition_text fl.condition in
  fl.doc
  ^ (if c = "" then "" else Printf.sprintf " (%s)" c)
  ^ if fl.repeats then "; may be given several times, applied in order" else ""

let row cells = "| " ^ String.concat " | " cells ^ " |"

let field_rows (fl : Schema.field) =
  [
    Printf.sprintf "`%s`" fl.name;
    Schema.value_text fl;
    default_text fl.default;
    meaning fl;
  ]

let table header rows =
  String.concat "\n"
    ((row header :: row (List.map (fun _ -> "---") header) :: List.map row rows) @ [])

let block_table id =
  match Schema.find id with
  | Some b ->
      table [ "field"; "value"; "default"; "meaning" ] (List.map field_rows b.fields)
  | None -> failwith ("no block " ^ id)

let own (b : Schema.block) =
  let common = Schema.names_of (Option.get (Schema.find "group")) in
  List.filter (fun (fl : Schema.field) -> not (List.mem fl.name common)) b.fields

(* Every shape: a line each (fields, defaults, what it is), then every field. *)
let objects () =
  let shapes = List.filter_map Schema.find Schema.shapes in
  let summary (b : Schema.block) =
    let names =
      List.map
        (fun (fl : Schema.field) ->
          match fl.default with
          | Value v -> Printf.sprintf "`%s: %s`" fl.name v
          | _ -> Printf.sprintf "`%s`" fl.name)
        (own b)
    in
    [
      Printf.sprintf "`%s`" b.id;
      (String.concat ", " names ^ if b.doc = "" then "" else " — " ^ b.doc);
    ]
  in
  let detail (b : Schema.block) =
    List.mapi
      (fun i fl -> (if i = 0 then Printf.sprintf "`%s`" b.id else "") :: field_rows fl)
      (own b)
  in
  table
    [ "object"; "fields (required unless a default is shown)" ]
    (List.map summary shapes)
  ^ "\n\n"
  ^ table
      [ "object"; "field"; "value"; "default"; "meaning" ]
      (List.concat_map detail shapes)

let common () =
  table
    [ "field"; "value"; "default"; "meaning" ]
    (List.map field_rows (Option.get (Schema.find "group")).fields)

(* Every built-in, in the table's order: how it is written, and its line. *)
let builtins () =
  table [ "built-in"; "meaning" ]
    (List.map
       (fun (b : Lancer_dsl.Builtins.t) -> [ Printf.sprintf "`%s`" b.usage; b.doc ])
       Lancer_dsl.Builtins.all)

(* Every named colour of the library, from its lines [let NAME = (r, g, b)  // #HEX (css)]. *)
let colours () =
  let file = "lancer/colors.rts" in
  let text = Option.get (Lancer_dsl.Library.builtin file) in
  let row line =
    match String.index_opt line '=' with
    | Some i when String.starts_with ~prefix:"let " line ->
        let name = String.trim (String.sub line 4 (i - 4)) in
        let rest = String.sub line (i + 1) (String.length line - i - 1) in
        let value, css =
          match String.index_opt rest '/' with
          | Some j ->
              ( String.trim (String.sub rest 0 j),
                String.trim (String.sub rest (j + 2) (String.length rest - j - 2)) )
          | None -> (String.trim rest, "")
        in
        Some [ Printf.sprintf "`%s`" name; css; Printf.sprintf "`%s`" value ]
    | _ -> None
  in
  table
    [ "colour"; "CSS value (name)"; "linear RGB" ]
    (List.filter_map row (String.split_on_char '\n' text))

let section id =
  match id with
  | "colours" -> colours ()
  | "objects" -> objects ()
  | "common" -> common ()
  | "builtins" -> builtins ()
  | id -> block_table id

let marker line =
  let p = "<!-- fields: " and s = " -->" in
  if String.equal line "<!-- builtins -->" then Some "builtins"
  else if String.equal line "<!-- colours -->" then Some "colours"
  else if String.starts_with ~prefix:p line && String.ends_with ~suffix:s line then
    Some
      (String.sub line (String.length p)
         (String.length line - String.length p - String.length s))
  else None

let () =
  let text = In_channel.with_open_bin Sys.argv.(1) In_channel.input_all in
  let lines = String.split_on_char '\n' text in
  let rec go acc = function
    | [] -> List.rev acc
    | l :: rest -> (
        match marker l with
        | None -> go (l :: acc) rest
        | Some id ->
            let rec skip = function
              | [] -> failwith (Printf.sprintf "the section %s has no <!-- end -->" id)
              | "<!-- end -->" :: r -> r
              | _ :: r -> skip r
            in
            go ("<!-- end -->" :: section id :: l :: acc) (skip rest))
  in
  print_string (String.concat "\n" (go [] lines))
