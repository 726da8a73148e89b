open Lancer

type outcome = Compare.outcome =
  | Same of Compare.t
  | Updated of string
  | Different of { figures : Compare.t; actual : string; diff : string }
  | Missing of { actual : string }

let updating () =
  match Sys.getenv_opt "LANCER_UPDATE_GOLDEN" with
  | Some ("1" | "true" | "yes") -> true
  | _ -> false

(* dune runs tests in <root>/_build/default/<dir>; goldens live in <root>/<dir>. The
   source root and the build directory's root, when running so. *)
let dune_roots () =
  match Sys.getenv_opt "DUNE_SOURCEROOT" with
  | None | Some "" -> None
  | Some root -> (
      let cwd = Sys.getcwd () in
      let marker = Filename.concat "_build" "default" in
      match Str_find.find cwd marker with
      | None -> None
      | Some i ->
          let build = String.sub cwd 0 (i + String.length marker) in
          let rel =
            String.sub cwd (String.length build) (String.length cwd - String.length build)
          in
          let rel =
            if String.length rel > 0 && rel.[0] = '/' then
              String.sub rel 1 (String.length rel - 1)
            else rel
          in
          Some (root, build, rel))

let source_path p =
  if not (Filename.is_relative p) then p
  else
    match dune_roots () with
    | None -> p
    | Some (root, _, rel) -> Filename.concat (Filename.concat root rel) p

let errs e = String.concat "\n" (List.map (Format.asprintf "%a" Lancer_dsl.Error.pp) e)

(* The time and frame asked for, as [lancer render --time/--frame] takes them. *)
let time_and_frame ?time ?frame prog =
  let fps = match Program.animation prog with Some (fps, _) -> fps | None -> 24. in
  match (time, frame) with
  | Some _, Some _ -> Error "give either ~time or ~frame, not both"
  | Some t, None when not (Float.is_finite t) -> Error "~time must be a finite number"
  | Some t, None -> Ok (t, int_of_float (Float.floor ((t *. fps) +. 1e-9)))
  | None, Some k -> (
      match Program.animation prog with
      | _ when k < 0 -> Error (Printf.sprintf "~frame must be at least 0 (got %d)" k)
      | None ->
          Error
            (Printf.sprintf
               "~frame:%d: the scene has no animation block, so it has no frames" k)
      | Some (_, count) when k >= count ->
          Error (Printf.sprintf "~frame:%d: the animation has frames 0..%d" k (count - 1))
      | Some (fps, _) -> Ok (Float.of_int k /. fps, k))
  | None, None -> Ok (0., 0)

(* The program and its render, as lancer render makes it ({!Scenes.scene}): the quality
   preset first, then the explicit settings; an open shutter's instants too. *)
let render_program ?width ?height ?samples ?quality ?time ?frame ?(domains = 1) path =
  let ( let* ) = Result.bind in
  let* prog = Result.map_error errs (Program.load_file path) in
  let* time, frame = time_and_frame ?time ?frame prog in
  let overrides = { Overrides.none with width; height; samples; quality } in
  let* sc =
    match Scenes.scene (Program.as_scenes ~builtin:false prog) overrides ~time ~frame with
    | sc, _ -> Ok sc
    | exception Job_error.Scene { errors; _ } -> Error (errs errors)
    | exception Job_error.User m -> Error m
  in
  let fb, _ = Render.with_pool domains (fun pool -> Render.render ?pool sc) in
  Ok (prog, (sc, time, frame), (fb.width, fb.height, Image.to_bytes sc.settings.gamma fb))

let render_scene ?width ?height ?samples ?quality ?time ?frame ?domains path =
  Result.map
    (fun (_, _, img) -> img)
    (render_program ?width ?height ?samples ?quality ?time ?frame ?domains path)

(* Under dune a test sees only its dependencies, copied into the build directory, and is
   run again only when one of them changes. The scene is read from the source tree, so a
   file it reads that is not a dependency would leave the test passing on stale inputs:
   each such file is named, with what to add. *)
let undeclared_inputs files =
  match dune_roots () with
  | None -> []
  | Some (root, build, rel) ->
      let root_slash = Filename.concat root "" in
      let under p pre =
        String.length p >= String.length pre && String.sub p 0 (String.length pre) = pre
      in
      List.filter_map
        (fun p ->
          if under p root_slash && not (under p (Filename.concat root "_build")) then
            let in_root =
              String.sub p (String.length root_slash)
                (String.length p - String.length root_slash)
            in
            let copy = Filename.concat build in_root in
            let same a b =
              try Digest.file a = Digest.file b with Sys_error _ -> false
            in
            (* A copy left by another rule is stale as soon as the file changes. *)
            if Sys.file_exists copy && same copy p then None
            else
              (* The path as the test's own directory sees it. *)
              let dir = if rel = "" then [] else String.split_on_char '/' rel in
              let rec strip d f =
                match (d, f) with
                | x :: d', y :: f' when x = y -> strip d' f'
                | _ -> (d, f)
              in
              let up, down = strip dir (String.split_on_char '/' in_root) in
              Some (String.concat "/" (List.map (fun _ -> "..") up @ down))
          else None)
        files

let compare_golden ?tolerance ?max_share ?metric ~golden actual =
  Compare.golden ?tolerance ?max_share ?metric ~update:(updating ())
    ~golden:(source_path golden) actual

let check ?tolerance ?max_share ?metric ?width ?height ?samples ?quality ?time ?frame
    ~scene ~golden () =
  match
    render_program ?width ?height ?samples ?quality ?time ?frame (source_path scene)
  with
  | Error m -> Alcotest.failf "%s: %s" scene m
  | Ok (prog, (sc, time, frame), img) -> (
      let golden_file = source_path golden in
      let read =
        Program.inputs prog
        @ if updating () || not (Sys.file_exists golden_file) then [] else [ golden_file ]
      in
      (match undeclared_inputs read with
      | [] -> ()
      | missing ->
          Alcotest.failf
            "%s: the test reads %s, which %s not among its dependencies, so dune would \
             not run it again when %s changes: add %s to the (deps …) of its test \
             stanza, for example %s"
            scene (String.concat ", " missing)
            (if List.length missing = 1 then "is" else "are")
            (if List.length missing = 1 then "it" else "one of them")
            (if List.length missing = 1 then "it" else "them")
            (String.concat " "
               (List.sort_uniq compare
                  (List.map
                     (fun p ->
                       match Filename.dirname p with
                       | "." -> Printf.sprintf "(glob_files *%s)" (Filename.extension p)
                       | d -> Printf.sprintf "(source_tree %s)" d)
                     missing))));
      match compare_golden ?tolerance ?max_share ?metric ~golden img with
      | Error m -> Alcotest.failf "%s: %s" golden m
      | Ok (Same _) | Ok (Updated _) -> ()
      | Ok (Missing { actual }) ->
          Alcotest.failf
            "no golden image %s yet; the render is in %s (accept it with \
             LANCER_UPDATE_GOLDEN=1)"
            golden_file actual
      | Ok (Different { figures; actual; diff }) ->
          let hint =
            Aov_run.golden_hint
              ~tolerance:(Option.value tolerance ~default:1)
              prog ~time ~frame sc ~golden:golden_file img
          in
          Alcotest.failf
            "%s differs from its golden %s: %a\n\
            \  actual image: %s\n\
            \  diff image:   %s\n\
             %s  (if the change is intended: LANCER_UPDATE_GOLDEN=1)"
            scene golden_file Compare.pp figures actual diff
            (match hint with Some h -> "  " ^ h ^ "\n" | None -> ""))

let test_case ?(speed = `Quick) ?tolerance ?max_share ?metric ?width ?height ?samples
    ?quality ?time ?frame name ~scene ~golden () =
  Alcotest.test_case name speed (fun () ->
      check ?tolerance ?max_share ?metric ?width ?height ?samples ?quality ?time ?frame
        ~scene ~golden ())
