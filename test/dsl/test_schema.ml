(* The schema of the language (dsl/schema.ml) is what the checker and the evaluation do:
   every field of every block kind is accepted and no other, required fields are
   required, defaults are the values used when a field is left out, and numbers outside
   a field's range are refused where they are written. Both take the fields, their
   defaults and ranges from the schema: these tests guard how they read them (a default
   as the literal it is, a range with its bounds included or not), and that they have
   none of their own. *)

module Dsl = Lancer_dsl.Dsl
module Error = Lancer_dsl.Error
module Schema = Lancer_dsl.Schema

let errors_text es = String.concat "" (List.map Error.to_string es)

(* The mistakes of a program of one file, the checker's and the run's. *)
let eval_errors text = Pipeline.errors text

(* A valid block of each shape: its required fields. *)
let shape_fields = function
  | "sphere" -> [ ("center", "(0, 0, 0)"); ("radius", "1") ]
  | "plane" -> [ ("normal", "(0, 1, 0)") ]
  | "parallelogram" ->
      [ ("origin", "(0, 0, 0)"); ("edge1", "(1, 0, 0)"); ("edge2", "(0, 1, 0)") ]
  | "triangle" -> [ ("a", "(0, 0, 0)"); ("b", "(1, 0, 0)"); ("c", "(0, 1, 0)") ]
  | "paraboloid" -> [ ("vertex", "(0, 0, 0)"); ("radius", "1"); ("height", "1") ]
  | "box" -> [ ("min", "(0, 0, 0)"); ("max", "(1, 1, 1)") ]
  | "cylinder" -> [ ("base", "(0, 0, 0)"); ("top", "(0, 1, 0)"); ("radius", "1") ]
  | "disk" -> [ ("center", "(0, 0, 0)"); ("normal", "(0, 1, 0)"); ("radius", "1") ]
  | "mesh" -> [ ("file", "\"../../scenes/gallery/torus.obj\"") ]
  | "cone" ->
      [
        ("base", "(0, 0, 0)");
        ("top", "(0, 1, 0)");
        ("base_radius", "1");
        ("top_radius", "0");
      ]
  | "torus" -> [ ("center", "(0, 0, 0)"); ("major", "1"); ("minor", "0.25") ]
  | "height_field" ->
      [ ("file", "\"../../scenes/gallery/maps/terrain.png\""); ("size", "(1, 1, 1)") ]
  | k -> Alcotest.failf "no valid %s in this test" k

let items_text fields =
  String.concat ", " (List.map (fun (n, v) -> Printf.sprintf "%s: %s" n v) fields)

let shape_required k = items_text (shape_fields k)
let sphere = "sphere { center: (0, 0, 0), radius: 1 }"

(* A value of the field's type, in its range. *)
let sample (fl : Schema.field) =
  let number () =
    List.find (Schema.in_range fl.range) [ 1.; 0.; 0.5; 30.; 1e-150; 1e-9 ]
    |> Printf.sprintf "%g"
  in
  match fl.ty with
  | Number | Integer -> number ()
  | Boolean -> "true"
  | File -> "\"x.obj\""
  | Choice l -> Printf.sprintf "\"%s\"" (List.hd l)
  | Vector | Direction | Colour -> "(0, 1, 0)"
  | Material | Base_material -> "material { }"
  | Texture -> "checker((1, 1, 1), (0, 0, 0), 1)"
  | Bump -> "noise(1, 0.1)"
  | Scale -> "2"
  | Background -> "(0, 0, 0)"
  | Fog -> "fog((1, 1, 1), 5)"
  | Gamma -> "2.2"
  | Interval -> "(0, 0.5)"

(* What a field needs beside it to apply. *)
let context (b : Schema.block) (fl : Schema.field) =
  (match fl.condition with
  | Kind_in (k :: _) -> [ Printf.sprintf "kind: \"%s\"" k ]
  | With n -> (
      match Schema.fields_named b n with
      | f :: _ -> [ n ^ ": " ^ sample f ]
      | [] -> [ n ^ ": (0, 0, 0)" ])
  | _ -> [])
  @ (match b.chosen_by with Some c when c <> fl.name -> [ c ^ ": (0, 5, 0)" ] | _ -> [])
  @
  if Schema.is_shape b.id then
    [ items_text (List.filter (fun (n, _) -> n <> fl.name) (shape_fields b.id)) ]
  else []

(* A program with block [b] holding [items] (field: value texts, comma-separated). *)
let program (b : Schema.block) items =
  let items = String.concat ", " (List.filter (fun s -> s <> "") items) in
  match b.keyword with
  | "material" -> Printf.sprintf "%s\nlet m = material { %s }" sphere items
  | "body" -> Printf.sprintf "body ball { %s %s }" sphere items
  | k when b.holds_objects -> Printf.sprintf "%s { %s %s }" k sphere items
  | k -> Printf.sprintf "%s { %s }" k items

let unknown_field (e : Error.t) = String.starts_with ~prefix:"unknown field" e.message

let test_fields_accepted () =
  List.iter
    (fun (b : Schema.block) ->
      List.iter
        (fun (fl : Schema.field) ->
          let text =
            program b (context b fl @ [ Printf.sprintf "%s: %s" fl.name (sample fl) ])
          in
          match List.filter unknown_field (eval_errors text) with
          | [] -> ()
          | es -> Alcotest.failf "%s: `%s` is refused:\n%s" b.id fl.name (errors_text es))
        b.fields;
      let plain = { (List.hd b.fields) with name = ""; condition = Always } in
      let text = program b (context b plain @ [ "bogus_field: 1" ]) in
      let expected = Printf.sprintf "unknown field `bogus_field` in %s" b.keyword in
      if not (List.exists (fun (e : Error.t) -> e.message = expected) (eval_errors text))
      then Alcotest.failf "%s: a field not in the schema is accepted:\n%s" b.id text)
    Schema.blocks

let test_required () =
  List.iter
    (fun id ->
      let b = Option.get (Schema.find id) in
      let required =
        List.filter_map
          (fun (fl : Schema.field) ->
            if fl.default = Required then Some fl.name else None)
          b.fields
      in
      Alcotest.(check (list string))
        (id ^ ": the required fields")
        (List.sort compare required)
        (List.sort compare (List.map fst (shape_fields id)));
      Alcotest.(check (list string))
        (id ^ " with its required fields is valid")
        []
        (List.map Error.to_string (eval_errors (program b [ shape_required id ])));
      List.iter
        (fun name ->
          let others = List.filter (fun (n, _) -> n <> name) (shape_fields id) in
          let text = Printf.sprintf "%s { %s }" id (items_text others) in
          let expected = Printf.sprintf "%s needs a `%s` field" id name in
          if
            not
              (List.exists (fun (e : Error.t) -> e.message = expected) (eval_errors text))
          then Alcotest.failf "no %S for:\n%s" expected text)
        required)
    Schema.shapes

(* The whole scene, as lancer check --json gives it. *)
let json text =
  match Lancer.Program.load_string ~filename:"test.rts" text with
  | Error es -> Alcotest.failf "%s\n%s" text (errors_text es)
  | Ok p -> (
      match Lancer.Program.scene_at p ~time:0. ~frame:0 with
      | Error es -> Alcotest.failf "%s\n%s" text (errors_text es)
      | Ok sc -> Yojson.Safe.to_string (Lancer.Program.to_json p sc))

let test_defaults () =
  let checked = ref 0 in
  List.iter
    (fun (b : Schema.block) ->
      List.iter
        (fun (fl : Schema.field) ->
          match fl.default with
          | Value v ->
              let ctx = context b fl in
              let ctx = if b.id = "material" then [] else ctx in
              let with_ items =
                if b.id = "material" then
                  Printf.sprintf
                    "sphere { center: (0, 0, 0), radius: 1, material: material { %s } }"
                    (String.concat ", " items)
                else program b (ctx @ items)
              in
              incr checked;
              Alcotest.(check string)
                (Printf.sprintf "%s: leaving out `%s` is `%s: %s`" b.id fl.name fl.name v)
                (json (with_ []))
                (json (with_ [ Printf.sprintf "%s: %s" fl.name v ]))
          | Required | Absent _ -> ())
        b.fields)
    Schema.blocks;
  Alcotest.(check bool) "defaults were compared" true (!checked >= 50)

let num x =
  let s = Printf.sprintf "%.17g" x in
  String.concat "" (String.split_on_char '+' s)

(* Values just outside a field's range, and just inside. *)
let outside (r : Schema.range) =
  let below = function
    | Schema.Incl a -> [ a -. Float.max (Float.abs a *. 0.5) 0.5 ]
    | Excl a -> [ a ]
    | Unbounded -> []
  and above = function
    | Schema.Incl b -> [ b +. Float.max (Float.abs b *. 0.5) 0.5 ]
    | Excl b -> [ b ]
    | Unbounded -> []
  in
  match r with
  | Any -> []
  | Real (a, b) -> below a @ above b
  | Whole (a, b) -> [ Float.of_int a -. 1.; Float.of_int b +. 1.; Float.of_int a +. 0.5 ]

let inside (r : Schema.range) =
  let tiny a = Float.max (Float.abs a *. 1e-9) 1e-9 in
  match r with
  | Any -> []
  | Real (a, b) -> (
      (match a with Incl a -> [ a ] | Excl a -> [ a +. tiny a ] | Unbounded -> [])
      @ match b with Incl b -> [ b ] | Excl b -> [ b -. tiny b ] | Unbounded -> [])
  | Whole (a, b) -> [ Float.of_int a; Float.of_int b ]

(* Fields whose other checks refuse a value in range: a spot's angles must keep
   inner ≤ outer, and a very long animation has too many frames. *)
let partner = function "inner" -> [ "outer: 180" ] | "outer" -> [ "inner: 0" ] | _ -> []

(* Whether the evaluator reports an error at the value of [name: value], the last item of
   block [b]'s program. *)
let refused_at_value b (fl : Schema.field) value =
  let text =
    program b (context b fl @ partner fl.name @ [ Printf.sprintf "%s: %s" fl.name value ])
  in
  let lines = String.split_on_char '\n' text in
  let last = List.nth lines (List.length lines - 1) in
  let key = fl.name ^ ": " ^ value in
  let rec find i =
    if String.sub last i (String.length key) = key then i else find (i + 1)
  in
  let col = find 0 + String.length fl.name + 3 in
  ( text,
    List.exists
      (fun (e : Error.t) -> e.line = List.length lines && e.col = col)
      (eval_errors text) )

let test_choices () =
  let checked = ref 0 in
  List.iter
    (fun (b : Schema.block) ->
      List.iter
        (fun (fl : Schema.field) ->
          match fl.ty with
          | Choice l ->
              List.iter
                (fun c ->
                  incr checked;
                  let text, refused = refused_at_value b fl (Printf.sprintf "%S" c) in
                  if refused then Alcotest.failf "%s: %S is refused:\n%s" b.id c text)
                l;
              let text, refused = refused_at_value b fl "\"bogus\"" in
              if not refused then
                Alcotest.failf "%s: \"bogus\" is accepted:\n%s" b.id text
          | _ -> ())
        b.fields)
    Schema.blocks;
  Alcotest.(check int) "the camera's kinds and the physics methods" 6 !checked

let test_ranges () =
  let checked = ref 0 in
  List.iter
    (fun (b : Schema.block) ->
      List.iter
        (fun (fl : Schema.field) ->
          (* A pair's range is each number's. *)
          let at_value x =
            refused_at_value b fl
              (if fl.ty = Interval then Printf.sprintf "(%s, %s)" (num x) (num x)
               else num x)
          in
          List.iter
            (fun x ->
              incr checked;
              let text, refused = at_value x in
              if not refused then
                Alcotest.failf "%s: %s is accepted:\n%s" b.id (num x) text)
            (outside fl.range);
          List.iter
            (fun x ->
              if not (fl.name = "duration" && x > 1e6) then (
                incr checked;
                let text, refused = at_value x in
                if refused then
                  Alcotest.failf "%s: %s is refused:\n%s\n%s" b.id (num x) text
                    (errors_text (eval_errors text))))
            (inside fl.range))
        b.fields)
    Schema.blocks;
  Alcotest.(check bool) "ranges were checked" true (!checked >= 100)

(* The scene a program describes, checked and evaluated with [schema]. *)
let described ?schema text =
  match Pipeline.run ?schema text with
  | Ok d ->
      (* A body is where its statement is, up to its end, which moves with its text. *)
      let nowhere =
        { Lancer.Loc.file = ""; line = 0; col = 0; end_line = 0; end_col = 0 }
      in
      {
        d with
        bodies =
          List.map
            (fun (b : Lancer.Description.body) -> { b with loc = nowhere })
            d.bodies;
        (* Each object's material as it reads, its colour in it: a material that differs
           from another in its colour alone may be held as that one. *)
        objects =
          List.map
            (fun (o : Lancer.Description.obj) ->
              { o with material = Lancer.Description.object_material o })
            d.objects;
      }
  | Error es -> Alcotest.failf "%s\n%s" text (errors_text es)

(* Another value of the field's type than its default, within its range. *)
let other (fl : Schema.field) default =
  let first l = List.find (fun v -> v <> default) l in
  match fl.ty with
  | Number | Integer | Gamma ->
      first
        (List.filter
           (fun v -> Schema.in_range fl.range (float_of_string v))
           [ "60"; "2"; "3"; "0.5" ])
  | Boolean -> first [ "true"; "false" ]
  | Vector | Direction | Colour | Background -> first [ "(0.25, 0.5, 0.75)"; "(1, 1, 1)" ]
  | Choice l -> first (List.rev_map (Printf.sprintf "%S") l)
  | _ -> Alcotest.failf "no other value of `%s` in this test" fl.name

(* What a field needs beside it besides [context], for any value: a spot's angles keep
   inner ≤ outer, an aperture needs a focal distance. *)
let beside = function
  | "inner" -> [ "outer: 180" ]
  | "outer" -> [ "inner: 0" ]
  | "aperture" -> [ "focal_distance: 1" ]
  | _ -> []

(* The schema with one field's default replaced. *)
let with_default (b : Schema.block) (fl : Schema.field) v =
  List.map
    (fun (b' : Schema.block) ->
      if b'.id <> b.id then b'
      else
        {
          b' with
          fields =
            List.map
              (fun fl' ->
                if fl' == fl then { fl' with Schema.default = Value v } else fl')
              b'.fields;
        })
    Schema.blocks

(* The evaluator has no defaults of its own: given a schema whose default of a field is
   another value, it evaluates a block without the field as if that value were written. *)
let test_schema_defaults_used () =
  let checked = ref 0 in
  List.iter
    (fun (b : Schema.block) ->
      List.iter
        (fun (fl : Schema.field) ->
          match fl.default with
          | Value v ->
              let v' = other fl v in
              let with_ items =
                let items = beside fl.name @ items in
                if b.id = "material" then
                  Printf.sprintf
                    "sphere { center: (0, 0, 0), radius: 1, material: material { %s } }"
                    (String.concat ", " items)
                else program b (context b fl @ items)
              in
              let left_out = with_ [] in
              let written = with_ [ Printf.sprintf "%s: %s" fl.name v' ] in
              let changed = described ~schema:(with_default b fl v') left_out in
              incr checked;
              if changed = described left_out then
                Alcotest.failf
                  "%s: a default of `%s: %s` in the schema changes nothing:\n%s" b.id
                  fl.name v' left_out;
              if changed <> described written then
                Alcotest.failf
                  "%s: with a default of `%s: %s` in the schema, leaving it out is not \
                   writing it:\n\
                   %s"
                  b.id fl.name v' left_out
          | Required | Absent _ -> ())
        b.fields)
    Schema.blocks;
  Alcotest.(check bool) "defaults were changed" true (!checked >= 50)

(* Where the scene description has defaults of its own (a scene without a settings block,
   an object without a material, …), they are the schema's. *)
let test_description_defaults () =
  let sphere = "sphere { center: (0, 0, 0), radius: 1 }" in
  let d = described sphere in
  let check_same what a b =
    if a <> b then Alcotest.failf "%s differs from the schema's defaults" what
  in
  check_same "Settings.default" Lancer.Settings.default
    (described ("settings { }\n" ^ sphere)).settings;
  check_same "Camera.default" Lancer.Camera.default
    (described ("camera { }\n" ^ sphere)).camera;
  check_same "Settings.default (no settings block)" Lancer.Settings.default d.settings;
  check_same "Description.default_physics" Lancer.Description.default_physics
    (Option.get (described ("physics { }\n" ^ sphere)).physics);
  let material text =
    match (described text).objects with
    | [ o ] ->
        Option.value
          (Lancer.Description.object_material o)
          ~default:Lancer.Description.default_material
    | _ -> Alcotest.fail "one object"
  in
  check_same "Description.default_material" Lancer.Description.default_material
    (material "sphere { center: (0, 0, 0), radius: 1, material: material { } }")

(* A material is made from its fields' values as the schema's ranges allow them, without
   the description checking it again: every number a material field's range holds (at
   each end of it, the others at their defaults) is one the description accepts. *)
let test_material_ranges () =
  let block = Option.get (Schema.find "material") in
  let ends (r : Schema.range) =
    match r with
    | Any -> [ -1e300; 1e300 ]
    | Whole (lo, hi) -> [ Float.of_int lo; Float.of_int hi ]
    | Real (lo, hi) ->
        let low = function
          | Schema.Incl x -> [ x ]
          | Excl x -> [ Float.succ x ]
          | Unbounded -> [ -1e300 ]
        and high = function
          | Schema.Incl x -> [ x ]
          | Excl x -> [ Float.pred x ]
          | Unbounded -> [ 1e300 ]
        in
        low lo @ high hi
  in
  let numbers = List.filter (fun (fl : Schema.field) -> fl.ty = Number) block.fields in
  Alcotest.(check bool) "the material has number fields" true (List.length numbers >= 7);
  List.iter
    (fun (fl : Schema.field) ->
      List.iter
        (fun x ->
          let d = Lancer.Description.default_material in
          let m : Lancer.Description.material =
            match fl.name with
            | "ambient" -> { d with ambient = x }
            | "diffuse" -> { d with diffuse = x }
            | "specular" -> { d with specular = x }
            | "shininess" -> { d with shininess = x }
            | "reflection" -> { d with reflection = x }
            | "transparency" -> { d with transparency = x }
            | "ior" -> { d with ior = x }
            | "metallic" -> { d with metallic = x }
            | "filter" -> { d with filter = x }
            | n -> Alcotest.failf "a material field %s this test does not know" n
          in
          match Lancer.Description.validate_material m with
          | Ok () -> ()
          | Error e -> Alcotest.failf "%s: %g is in its range, but %s" fl.name x e)
        (ends fl.range))
    numbers

let () =
  Alcotest.run "schema"
    [
      ( "the evaluator follows the schema",
        [
          Alcotest.test_case "every field of every block kind is accepted, no other"
            `Quick test_fields_accepted;
          Alcotest.test_case "required fields are required" `Quick test_required;
          Alcotest.test_case "defaults are what a missing field means" `Quick
            test_defaults;
          Alcotest.test_case "every choice of a string field is accepted, no other" `Quick
            test_choices;
          Alcotest.test_case "numbers out of range are refused at the value" `Quick
            test_ranges;
        ] );
      ( "the schema is the evaluator's one source",
        [
          Alcotest.test_case
            "a default changed in the schema is what a missing field means" `Quick
            test_schema_defaults_used;
          Alcotest.test_case "the scene description's own defaults are the schema's"
            `Quick test_description_defaults;
          Alcotest.test_case
            "every number a material field's range holds, the description accepts" `Quick
            test_material_ranges;
        ] );
    ]
