open Lancer
module Dsl = Lancer_dsl.Dsl

type outcome = Compare.outcome =
  | Same of Compare.t
  | Updated of string
  | Different of { figures : Compare.t; actual : string; diff : string }
  | Missing of { actual : string }

let updating () = match Sys.getenv_opt "LANCER_UPDATE_GOLDEN" with Some ("1" | "true" | "yes") -> true | _ -> false

(* dune runs tests in _build/default/<dir>; goldens live in <source root>/<dir>. *)
let source_path p =
  if not (Filename.is_relative p) then p
  else
    match Sys.getenv_opt "DUNE_SOURCEROOT" with
    | None -> p
    | Some root -> (
        let cwd = Sys.getcwd () in
        let marker = Filename.concat "_build" "default" in
        match Str_find.find cwd marker with
        | None -> p
        | Some i ->
            let rel = String.sub cwd (i + String.length marker) (String.length cwd - i - String.length marker) in
            let rel = if String.length rel > 0 && rel.[0] = '/' then String.sub rel 1 (String.length rel - 1) else rel in
            Filename.concat (Filename.concat root rel) p)

let render_scene ?width ?height ?(domains = 1) path =
  let errs e = String.concat "\n" (List.map (Format.asprintf "%a" Lancer_dsl.Error.pp) e) in
  match Dsl.load_file path with
  | Error e -> Error (errs e)
  | Ok prog -> (
      match Dsl.scene_at prog ~time:0. ~frame:0 with
      | Error e -> Error (errs e)
      | Ok sc -> (
          let s = sc.settings in
          let s' = { s with width = Option.value width ~default:s.width; height = Option.value height ~default:s.height } in
          match if s' = s then Ok sc else Scene.with_settings sc s' with
          | Error m -> Error m
          | Ok sc ->
              let fb, _ = Render.with_pool domains (fun pool -> Render.render ?pool sc) in
              Ok (fb.width, fb.height, Image.to_bytes sc.settings.gamma fb)))

let compare_golden ?tolerance ?max_share ~golden actual =
  Compare.golden ?tolerance ?max_share ~update:(updating ()) ~golden:(source_path golden) actual

let check ?tolerance ?max_share ?width ?height ~scene ~golden () =
  match render_scene ?width ?height (source_path scene) with
  | Error m -> Alcotest.failf "%s: %s" scene m
  | Ok img -> (
      match compare_golden ?tolerance ?max_share ~golden img with
      | Error m -> Alcotest.failf "%s: %s" golden m
      | Ok (Same _) | Ok (Updated _) -> ()
      | Ok (Missing { actual }) ->
          Alcotest.failf "no golden image %s yet; the render is in %s (accept it with LANCER_UPDATE_GOLDEN=1)" (source_path golden) actual
      | Ok (Different { figures; actual; diff }) ->
          Alcotest.failf "%s differs from its golden %s: %a\n  actual image: %s\n  diff image:   %s\n  (if the change is intended: LANCER_UPDATE_GOLDEN=1)"
            scene (source_path golden) Compare.pp figures actual diff)

let test_case ?(speed = `Quick) ?tolerance ?max_share ?width ?height name ~scene ~golden () =
  Alcotest.test_case name speed (fun () -> check ?tolerance ?max_share ?width ?height ~scene ~golden ())
