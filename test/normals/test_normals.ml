(* Normals computed for a mesh that has none (and for a smooth height field): the
   angle-weighted average of the faces around each vertex, split where two faces meet at
   more than 60°, against normals worked out here from the same definition. *)
open Lancer

let v = Vec3.v
let case name f = Alcotest.test_case name `Quick f

let check_vec msg (a : Vec3.t) (b : Vec3.t) =
  let eps = 1e-12 in
  Alcotest.(check (float eps)) (msg ^ " (x)") a.x b.x;
  Alcotest.(check (float eps)) (msg ^ " (y)") a.y b.y;
  Alcotest.(check (float eps)) (msg ^ " (z)") a.z b.z

let mesh ?smooth text =
  match Obj_file.parse_mesh ?smooth ~file:"t.obj" text with
  | Ok m -> m
  | Error e -> Alcotest.failf "unexpected error: %s" e

(* ---- The definition, written out independently ---- *)

let face_normal a b c = Vec3.normalize (Vec3.cross (Vec3.sub b a) (Vec3.sub c a))

(* The angle between two vectors, by its cosine. *)
let angle u w =
  Float.acos
    (Float.max (-1.) (Float.min 1. (Vec3.dot (Vec3.normalize u) (Vec3.normalize w))))

(* The normal at each corner of [faces] (triples of indices into [pos]): the faces at the
   corner's vertex reached from the corner's own face through edges from that vertex
   where the two faces' normals are at most [crease] degrees apart, each face's normal
   weighted by its angle at the vertex, summed in the order of the faces. *)
let corner_normals ?(crease = 60.) pos faces =
  let n k =
    let a, b, c = faces.(k) in
    face_normal pos.(a) pos.(b) pos.(c)
  in
  let corners k =
    let a, b, c = faces.(k) in
    [ a; b; c ]
  in
  let angle_at k vtx =
    match List.filter (fun i -> i <> vtx) (corners k) with
    | [ x; y ] -> angle (Vec3.sub pos.(x) pos.(vtx)) (Vec3.sub pos.(y) pos.(vtx))
    | _ -> Alcotest.fail "a face with a repeated vertex"
  in
  let cos_crease = Float.cos (crease *. Float.pi /. 180.) in
  let around vtx =
    List.filter
      (fun k -> List.mem vtx (corners k))
      (List.init (Array.length faces) Fun.id)
  in
  (* Faces k and k' share an edge from vtx: another vertex in common. *)
  let share_edge vtx k k' =
    List.exists (fun x -> x <> vtx && List.mem x (corners k')) (corners k)
  in
  let group vtx k =
    let rec grow seen = function
      | [] -> seen
      | g :: rest ->
          let next =
            List.filter
              (fun k' ->
                (not (List.mem k' seen))
                && share_edge vtx g k'
                && Vec3.dot (n g) (n k') >= cos_crease)
              (around vtx)
          in
          grow (seen @ next) (rest @ next)
    in
    grow [ k ] [ k ]
  in
  Array.mapi
    (fun k (a, b, c) ->
      let at vtx =
        let members = group vtx k in
        Vec3.normalize
          (List.fold_left
             (fun sum k' ->
               if List.mem k' members then
                 Vec3.add sum (Vec3.smul (angle_at k' vtx) (n k'))
               else sum)
             Vec3.zero (around vtx))
      in
      (at a, at b, at c))
    faces

let obj_text ?normals pos faces =
  let b = Buffer.create 4096 in
  Array.iter
    (fun (p : Vec3.t) -> Printf.bprintf b "v %.17g %.17g %.17g\n" p.x p.y p.z)
    pos;
  (match normals with
  | None ->
      Array.iter
        (fun (a, c, d) -> Printf.bprintf b "f %d %d %d\n" (a + 1) (c + 1) (d + 1))
        faces
  | Some ns ->
      Array.iteri
        (fun k ((na : Vec3.t), (nb : Vec3.t), (nc : Vec3.t)) ->
          List.iter
            (fun (n : Vec3.t) -> Printf.bprintf b "vn %.17g %.17g %.17g\n" n.x n.y n.z)
            [ na; nb; nc ];
          let a, c, d = faces.(k) in
          Printf.bprintf b "f %d//%d %d//%d %d//%d\n" (a + 1)
            ((3 * k) + 1)
            (c + 1)
            ((3 * k) + 2)
            (d + 1)
            ((3 * k) + 3))
        ns);
  Buffer.contents b

(* Two faces sharing the edge from (0, 0, 0) to (1, 0, 0), one in the plane y = 0, the
   other folded up by [fold] degrees. *)
let tent fold =
  let r = fold *. Float.pi /. 180. in
  let pos =
    [| v 0. 0. 0.; v 1. 0. 0.; v 0.3 0. 1.; v 0.6 (Float.sin r) (-.Float.cos r) |]
  in
  (pos, [| (0, 1, 2); (1, 0, 3) |])

(* A lumpy sphere: a latitude–longitude grid, radii varied so that faces differ. *)
let lumpy ?(nlat = 10) ?(nlon = 14) () =
  let pos = ref [ v 0. 1. 0. ] in
  for i = 1 to nlat - 1 do
    let th = Float.pi *. Float.of_int i /. Float.of_int nlat in
    for j = 0 to nlon - 1 do
      let ph = 2. *. Float.pi *. Float.of_int j /. Float.of_int nlon in
      let r = 1. +. (0.08 *. Float.sin (3. *. ph) *. Float.sin (2. *. th)) in
      pos :=
        v
          (r *. Float.sin th *. Float.cos ph)
          (r *. Float.cos th)
          (r *. Float.sin th *. Float.sin ph)
        :: !pos
    done
  done;
  pos := v 0. (-1.) 0. :: !pos;
  let pos = Array.of_list (List.rev !pos) in
  let ring i j = 1 + ((i - 1) * nlon) + (j mod nlon) and south = Array.length pos - 1 in
  let faces = ref [] in
  for j = 0 to nlon - 1 do
    faces := (0, ring 1 (j + 1), ring 1 j) :: !faces
  done;
  for i = 1 to nlat - 2 do
    for j = 0 to nlon - 1 do
      faces :=
        (ring i j, ring (i + 1) (j + 1), ring (i + 1) j)
        :: (ring i j, ring i (j + 1), ring (i + 1) (j + 1))
        :: !faces
    done
  done;
  for j = 0 to nlon - 1 do
    faces := (south, ring (nlat - 1) j, ring (nlat - 1) (j + 1)) :: !faces
  done;
  (pos, Array.of_list (List.rev !faces))

let stored_normals m k = (Trimesh.normal m k 0, Trimesh.normal m k 1, Trimesh.normal m k 2)

let same_normals what m expected =
  Array.iteri
    (fun k (na, nb, nc) ->
      let a, b, c = stored_normals m k in
      let at j = Printf.sprintf "%s, face %d, corner %d" what k j in
      check_vec (at 0) na a;
      check_vec (at 1) nb b;
      check_vec (at 2) nc c)
    expected

let unit_tests =
  [
    case "faces meeting at 40° smooth into each other, angle-weighted" (fun () ->
        let pos, faces = tent 40. in
        let m = mesh (obj_text pos faces) in
        Alcotest.(check int) "every face computed" 2 (Trimesh.computed m);
        same_normals "tent" m (corner_normals pos faces);
        (* On the shared edge the normal is between the two faces', not either. *)
        let n0, _, _ = stored_normals m 0 in
        let f0 = face_normal pos.(0) pos.(1) pos.(2) in
        Alcotest.(check bool)
          "not the flat normal" true
          (Vec3.dot n0 f0 < 0.999 && Vec3.dot n0 f0 > 0.9));
    case "faces meeting at 70° keep their own normals: the edge is a crease" (fun () ->
        let pos, faces = tent 70. in
        let m = mesh (obj_text pos faces) in
        let f0 = face_normal pos.(0) pos.(1) pos.(2)
        and f1 = face_normal pos.(1) pos.(0) pos.(3) in
        same_normals "creased tent" m [| (f0, f0, f0); (f1, f1, f1) |];
        same_normals "the definition" m (corner_normals pos faces));
    case
      "faces 35° apart in turn smooth into one group, though the first and last are 105° \
       apart" (fun () ->
        (* A fan around the apex of a steep cone, each blade turned 35° about y from the
           one before, bent down, the blades sharing their edges from the origin. *)
        let blade i =
          let r = Float.of_int i *. 35. *. Float.pi /. 180. in
          v (Float.cos r) (-2.) (Float.sin r)
        in
        let pos = Array.append [| v 0. 0. 0. |] (Array.init 5 blade) in
        let faces = Array.init 4 (fun i -> (0, i + 2, i + 1)) in
        let m = mesh (obj_text pos faces) in
        same_normals "fan" m (corner_normals pos faces);
        let n0, _, _ = stored_normals m 0 and n3, _, _ = stored_normals m 3 in
        check_vec "one normal at the centre" n0 n3;
        Alcotest.(check bool)
          "the first and last faces are more than 60° apart" true
          (Vec3.dot
             (face_normal pos.(0) pos.(2) pos.(1))
             (face_normal pos.(0) pos.(5) pos.(4))
          < 0.5));
    case "a polygon of 200 000 corners, fanned from one vertex, is quick" (fun () ->
        let b = Buffer.create (1 lsl 22) in
        Buffer.add_string b "v 0 0 0\n";
        let n = 200_000 in
        for i = 0 to n - 1 do
          let r = 2. *. Float.pi *. Float.of_int i /. Float.of_int n in
          Printf.bprintf b "v %.17g 0 %.17g\n" (Float.cos r) (Float.sin r)
        done;
        Buffer.add_string b "f 1";
        for i = n downto 1 do
          Printf.bprintf b " %d" (i + 1)
        done;
        Buffer.add_char b '\n';
        let t0 = Sys.time () in
        let m = mesh (Buffer.contents b) in
        let dt = Sys.time () -. t0 in
        Alcotest.(check int) "every face computed" (n - 1) (Trimesh.computed m);
        check_vec "the centre's normal" (v 0. 1. 0.) (Trimesh.normal m 0 0);
        if dt > 10. then Alcotest.failf "%.1f s of CPU" dt);
    case "a cube's corners stay sharp, a lumpy sphere is smooth everywhere" (fun () ->
        let cube =
          [|
            v 0. 0. 0.;
            v 1. 0. 0.;
            v 1. 1. 0.;
            v 0. 1. 0.;
            v 0. 0. 1.;
            v 1. 0. 1.;
            v 1. 1. 1.;
            v 0. 1. 1.;
          |]
        and quads =
          [
            (0, 3, 2, 1);
            (4, 5, 6, 7);
            (0, 1, 5, 4);
            (2, 3, 7, 6);
            (1, 2, 6, 5);
            (0, 4, 7, 3);
          ]
        in
        let faces =
          Array.of_list
            (List.concat_map (fun (a, b, c, d) -> [ (a, b, c); (a, c, d) ]) quads)
        in
        let m = mesh (obj_text cube faces) in
        Array.iteri
          (fun k (a, b, c) ->
            let f = face_normal cube.(a) cube.(b) cube.(c) in
            same_normals "cube" (mesh (obj_text cube [| faces.(k) |])) [| (f, f, f) |];
            let na, nb, nc = stored_normals m k in
            List.iter (check_vec (Printf.sprintf "cube face %d" k) f) [ na; nb; nc ])
          faces;
        let pos, faces = lumpy () in
        same_normals "lumpy sphere" (mesh (obj_text pos faces)) (corner_normals pos faces));
    case "normals read from the file are kept; smooth: false computes none" (fun () ->
        let pos, faces = tent 40. in
        let given =
          [| (v 0. 1. 0., v 0. 1. 0., v 0. 1. 0.); (v 1. 0. 0., v 1. 0. 0., v 1. 0. 0.) |]
        in
        let m = mesh (obj_text ~normals:given pos faces) in
        Alcotest.(check int) "none computed" 0 (Trimesh.computed m);
        same_normals "the file's" m given;
        let flat = mesh ~smooth:false (obj_text pos faces) in
        Alcotest.(check int) "none computed, flat" 0 (Trimesh.computed flat);
        Alcotest.(check bool) "no normals" false (Trimesh.has_normals flat 0));
  ]

(* ---- Rendered ---- *)

let temp_dir () =
  let d = Filename.temp_file "lancer-normals" "" in
  Sys.remove d;
  Sys.mkdir d 0o755;
  d

let write path text = Out_channel.with_open_bin path (fun oc -> output_string oc text)

let render text =
  match Program.load_string ~filename:"normals.rts" text with
  | Error _ -> Alcotest.failf "the scene does not load:\n%s" text
  | Ok p -> (
      match Program.scene_at p ~time:0. ~frame:0 with
      | Error _ -> Alcotest.failf "the scene does not evaluate:\n%s" text
      | Ok sc ->
          let fb, _ = Render.render sc in
          Image.to_bytes sc.settings.gamma fb)

let scene object_ =
  Printf.sprintf
    "settings { width: 80, height: 60 }\n\
     camera { position: (0.4, 1.6, -3.5), look_at: (0, 0, 0), fov: 45 }\n\
     light { position: (-3, 5, -4) }\n\
     light { position: (4, 1, -2), intensity: 0.4 }\n\
     %s\n"
    object_

let material =
  "material: material { color: (0.9, 0.6, 0.3), specular: 0.6, shininess: 30 }"

let render_tests =
  [
    case "a mesh without vn renders as the same mesh with those normals written out"
      (fun () ->
        let d = temp_dir () in
        let pos, faces = lumpy () in
        let bare = Filename.concat d "bare.obj"
        and written = Filename.concat d "vn.obj" in
        write bare (obj_text pos faces);
        write written (obj_text ~normals:(corner_normals pos faces) pos faces);
        let img file smooth =
          render
            (scene
               (Printf.sprintf "mesh { file: %S, smooth: %b, %s }" file smooth material))
        in
        let computed = img bare true in
        Alcotest.(check bool)
          "the same bytes" true
          (Bytes.equal computed (img written true));
        Alcotest.(check bool)
          "not the faceted image" false
          (Bytes.equal computed (img bare false)));
    case "a smooth height field renders as its grid written as a mesh without vn"
      (fun () ->
        let d = temp_dir () in
        let w = 9 and h = 7 in
        let grey i j = ((37 * i * i) + (91 * j) + (13 * i * j)) mod 256 in
        let ppm = Buffer.create 512 in
        Printf.bprintf ppm "P6\n%d %d\n255\n" w h;
        for j = 0 to h - 1 do
          for i = 0 to w - 1 do
            let g = Char.chr (grey i j) in
            Buffer.add_char ppm g;
            Buffer.add_char ppm g;
            Buffer.add_char ppm g
          done
        done;
        let image = Filename.concat d "h.ppm" in
        write image (Buffer.contents ppm);
        let origin = v (-1.5) (-0.5) (-1.) and size = v 3. 0.6 2. in
        (* Vertex (i, j) at origin + (sx·i/(W−1), sy·value, sz·j/(H−1)); cell (i, j) is
           the triangles (i, j), (i, j+1), (i+1, j) and (i+1, j), (i, j+1), (i+1, j+1). *)
        let pos =
          Array.init (w * h) (fun k ->
              let i = k mod w and j = k / w in
              v
                (origin.x +. (size.x *. Float.of_int i /. Float.of_int (w - 1)))
                (origin.y +. (size.y *. (Float.of_int (grey i j) /. 255.)))
                (origin.z +. (size.z *. Float.of_int j /. Float.of_int (h - 1))))
        in
        let faces =
          Array.of_list
            (List.concat
               (List.init (h - 1) (fun j ->
                    List.concat
                      (List.init (w - 1) (fun i ->
                           let a = (j * w) + i in
                           [ (a, a + w, a + 1); (a + 1, a + w, a + w + 1) ])))))
        in
        let grid = Filename.concat d "grid.obj" in
        write grid (obj_text pos faces);
        let field smooth =
          Printf.sprintf
            "height_field { file: %S, origin: (-1.5, -0.5, -1), size: (3, 0.6, 2), \
             smooth: %b, %s }"
            image smooth material
        in
        let smooth = render (scene (field true)) in
        Alcotest.(check bool)
          "the mesh's bytes" true
          (Bytes.equal smooth
             (render (scene (Printf.sprintf "mesh { file: %S, %s }" grid material))));
        Alcotest.(check bool)
          "not the flat field" false
          (Bytes.equal smooth (render (scene (field false))));
        Alcotest.(check bool)
          "flat by default" true
          (Bytes.equal
             (render (scene (field false)))
             (render
                (scene
                   (Printf.sprintf
                      "height_field { file: %S, origin: (-1.5, -0.5, -1), size: (3, 0.6, \
                       2), %s }"
                      image material)))));
  ]

let () = Alcotest.run "normals" [ ("computed", unit_tests); ("rendered", render_tests) ]
