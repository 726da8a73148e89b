(* Where the memory of a million objects goes, stage by stage: the description the
   language makes, the compiled primitives, their materials and the acceleration
   structure, in words per object, for spheres with the default material and with a
   colour each computed in the loop. *)

open Lancer

(* The grid of [Language]'s benchmarks, n × n spheres; with [colour], each with a
   material of its own whose colour the loop computes. *)
let program ~colour n =
  Language.grid_header n
  ^ Printf.sprintf
      "for i in 0 to n - 1 { for j in 0 to n - 1 { sphere { center: (i - n / 2, 0.4, j - \
       n / 2), radius: 0.4%s } } }\n"
      (if colour then ", material: material { color: (i / n, j / n, 0.5) }" else "")

let words x = Float.of_int (Obj.reachable_words (Obj.repr x))

let run ~grid ~colour ~json =
  if grid < 1 then raise (Job_error.User "--grid must be at least 1");
  let n = Float.of_int (grid * grid) in
  let fail es =
    raise
      (Job_error.User
         ("the benchmark's program failed: "
         ^ String.concat "" (List.map Diagnostic.to_string es)))
  in
  let p =
    match
      Program.load_string ~single:true ~filename:"bench.rts" (program ~colour grid)
    with
    | Ok p -> p
    | Error es -> fail es
  in
  (* The load's description (held by the program until its scene lets it go). *)
  let description =
    match Program.describe p ~time:0. ~frame:0 with
    | Ok d -> words d.objects /. n
    | Error es -> fail es
  in
  let sc =
    match Program.scene p ~time:0. ~frame:0 with Ok s -> s | Error es -> fail es
  in
  let objects = words sc.objects /. n in
  let materials =
    let ms = Array.map (fun (o : Primitive.t) -> o.material) sc.objects in
    (words ms -. Float.of_int (Array.length ms + 1)) /. n
  in
  let accel = words sc.accel /. n in
  let top = Float.of_int (Gc.quick_stat ()).top_heap_words /. n in
  let rows =
    [
      ("description_words_per_object", description);
      ("primitive_words_per_object", objects);
      ("material_words_per_object", materials);
      ("accel_words_per_object", accel);
      ("top_heap_words_per_object", top);
    ]
  in
  if json then
    print_endline
      (Yojson.Safe.pretty_to_string
         (`Assoc
            (("objects", `Int (grid * grid))
            :: ("colour_each", `Bool colour)
            :: List.map (fun (k, v) -> (k, `Float v)) rows)))
  else (
    Printf.printf "%d spheres from a loop%s, words per object at each stage\n\n"
      (grid * grid)
      (if colour then ", each with a colour of its own" else "");
    print_endline "| stage | words per object |";
    print_endline "|---|---:|";
    List.iter
      (fun (k, v) ->
        Printf.printf "| %s | %.1f |\n" (String.concat " " (String.split_on_char '_' k)) v)
      rows)
