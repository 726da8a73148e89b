(* CSG: closed-form crossings, the boundary of the combined set against its inside
   function sampled along rays, the BVH against a brute-force scan, and a hollow glass
   sphere against the same picture made from its two surfaces. *)

open Lancer

let contains s sub =
  let n = String.length sub in
  let rec go i = i + n <= String.length s && (String.sub s i n = sub || go (i + 1)) in
  go 0

let seeded ?(seed = 20261201) t =
  QCheck_alcotest.to_alcotest ~rand:(Random.State.make [| seed |]) t

let close ?(eps = 1e-12) what want got =
  if Float.abs (want -. got) > eps then
    Alcotest.failf "%s: want %.17g, got %.17g" what want got

let sphere x y z r = Shape.sphere ~center:(Vec3.v x y z) ~radius:r
let id = Transform.identity
let ray o d = Ray.make o d

(* A shape's crossings after [tmin] with the leaf each lies on. *)
let crossings s r tmin =
  List.map (fun (t, l, _) -> (t, l)) (Walk.shape_crossings s r tmin)

(* The lens: two unit spheres whose centres are 1 apart. Along their common axis it spans
   z ∈ [−0.5, 0.5]: a ray from z = −5 enters at t = 4.5 (on the far sphere) and leaves at
   5.5 (on the near one). *)
let lens () =
  Shape.csg Intersection [ (sphere 0. 0. (-0.5) 1., id); (sphere 0. 0. 0.5 1., id) ]

let test_lens () =
  let r = ray (Vec3.v 0. 0. (-5.)) Vec3.z_axis in
  match crossings (lens ()) r 0. with
  | [ (t0, l0); (t1, l1) ] ->
      close "entry" 4.5 t0;
      close "exit" 5.5 t1;
      Alcotest.(check (pair int int))
        "entry on the sphere at +z, exit on the one at −z" (1, 0) (l0, l1);
      close "nearest hit" 4.5 (Walk.intersect (lens ()) r 0. Float.infinity)
  | l -> Alcotest.failf "want two crossings, got %d" (List.length l)

let test_lens_off_axis () =
  (* Off the axis by 0.5 along x: each sphere's surface at x = 0.5 is z = ±0.5 ∓ √0.75. *)
  let r = ray (Vec3.v 0.5 0. (-5.)) Vec3.z_axis in
  let h = Float.sqrt 0.75 in
  match crossings (lens ()) r 0. with
  | [ (t0, _); (t1, _) ] ->
      close ~eps:1e-12 "entry" (5. +. 0.5 -. h) t0;
      close ~eps:1e-12 "exit" (5. -. 0.5 +. h) t1
  | l -> Alcotest.failf "want two crossings, got %d" (List.length l)

(* A box minus a sphere that bites into its −x face: the ray along +x meets the cavity's
   wall at x = −0.5 first, and the normal there points into the cavity (−x). *)
let test_cavity_normal () =
  let red = { Material.default with color = Color.v 1. 0. 0. }
  and blue = { Material.default with color = Color.v 0. 0. 1. } in
  let shape =
    Shape.csg Difference
      [
        (Shape.box ~min:(Vec3.v (-1.) (-1.) (-1.)) ~max:Vec3.one, id);
        (sphere (-1.) 0. 0. 0.5, id);
      ]
  in
  let p = Primitive.make ~leaf_materials:[| None; Some blue |] red shape in
  let r = ray (Vec3.v (-5.) 0.1 0.) Vec3.x_axis in
  let s, t = Queries.surface p r 0. Float.infinity in
  let want = 5. -. 1. +. Float.sqrt ((0.5 *. 0.5) -. (0.1 *. 0.1)) in
  close "hit on the cavity wall" want t;
  let n = Primitive.normal s (Primitive.to_object s (Ray.at r t)) in
  if not (n.x < -0.9) then
    Alcotest.failf "the normal (%g, %g, %g) does not point into the cavity" n.x n.y n.z;
  Alcotest.(check bool)
    "the cavity wall shades with the sphere's material" true (s.material == blue);
  (* Through the middle of the solid part: the box's own face, with the CSG's material. *)
  let r = ray (Vec3.v (-5.) 0.9 0.9) Vec3.x_axis in
  let s, t = Queries.surface p r 0. Float.infinity in
  close "hit on the box face" 4. t;
  Alcotest.(check bool)
    "the box face shades with the CSG's material" true (s.material == red);
  let n = Primitive.normal s (Primitive.to_object s (Ray.at r t)) in
  if not (n.x < -0.9) then
    Alcotest.failf "the box face's normal (%g, %g, %g) is not −x" n.x n.y n.z

(* A plane member is the half-space below it: a box cut by the plane y = 0 keeps its lower
   half, and a ray from above meets the cut at y = 0. *)
let test_plane_half_space () =
  let shape =
    Shape.csg Intersection
      [
        (Shape.box ~min:(Vec3.v (-1.) (-1.) (-1.)) ~max:Vec3.one, id);
        (Shape.plane ~normal:Vec3.y_axis ~offset:0., id);
      ]
  in
  close "the cut" 5.
    (Walk.intersect shape
       (ray (Vec3.v 0.2 5. 0.3) (Vec3.v 0. (-1.) 0.))
       0. Float.infinity)

(* The hollow sphere's four walls: a shadow ray through it crosses the outer wall, the
   inner wall twice and the outer wall again. *)
let test_shadow_crosses_both_walls () =
  let shell =
    Shape.csg Difference [ (sphere 0. 0. 0. 1., id); (sphere 0. 0. 0. 0.8, id) ]
  in
  let glass = { Material.default with transparency = 0.9; ior = 1.5 } in
  let acc = Accel.build [| Primitive.make glass shell |] in
  let r = ray (Vec3.v 0. 0. (-5.)) Vec3.z_axis in
  Alcotest.(check int)
    "crossings" 4
    (List.length (Queries.crossings acc r 0. 10. ~transparent:false))

(* --- Random CSG trees ------------------------------------------------------------- *)

let rnd st lo hi = lo +. Random.State.float st (hi -. lo)

let rec random_tree st depth =
  if depth = 0 || Random.State.int st 3 = 0 then
    let c = Vec3.v (rnd st (-1.) 1.) (rnd st (-1.) 1.) (rnd st (-1.) 1.) in
    if Random.State.bool st then Shape.sphere ~center:c ~radius:(rnd st 0.3 1.2)
    else
      let h = Vec3.v (rnd st 0.2 1.) (rnd st 0.2 1.) (rnd st 0.2 1.) in
      Shape.box ~min:(Vec3.sub c h) ~max:(Vec3.add c h)
  else
    let op : Shape.csg_op =
      match Random.State.int st 4 with
      | 0 -> Union
      | 1 -> Merge
      | 2 -> Intersection
      | _ -> Difference
    in
    let n = 2 + Random.State.int st 2 in
    let member () =
      let tf =
        if Random.State.bool st then id
        else
          Transform.then_
            (Transform.rotate (Vec3.v (rnd st 0. 90.) (rnd st 0. 90.) (rnd st 0. 90.)))
            (Transform.translate
               (Vec3.v (rnd st (-0.5) 0.5) (rnd st (-0.5) 0.5) (rnd st (-0.5) 0.5)))
      in
      (random_tree st (depth - 1), tf)
    in
    Shape.csg op (List.init n (fun _ -> member ()))

let random_ray st =
  let o =
    Vec3.smul 5.
      (Vec3.normalize (Vec3.v (rnd st (-1.) 1.) (rnd st (-1.) 1.) (rnd st (-1.) 1.)))
  in
  let target = Vec3.v (rnd st (-1.) 1.) (rnd st (-1.) 1.) (rnd st (-1.) 1.) in
  ray o (Vec3.normalize (Vec3.sub target o))

(* The nearest hit is where the combined inside function first changes along the ray:
   sampled every 0.002 over [0, 12], the first change lies between two samples that
   bracket the hit. A union shows every member's surface, so its first crossing is where
   any member's inside first changes; for the other operations, the combined one. *)
let test_first_sign_change =
  QCheck.Test.make
    ~name:"the hit of a random CSG tree is the first change of its inside along the ray"
    ~count:400
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let s = random_tree st 3 in
      let r = random_ray st in
      let inside =
        match s with
        | Shape.Csg { op = Union; members; _ } ->
            (* Any member changing: compare the whole vector of members' insides. *)
            fun t ->
              List.map
                (fun (m : Shape.csg_member) ->
                  Walk.inside m.shape (Transform.inv_point m.transform (Ray.at r t)))
                (Array.to_list members)
        | _ -> fun t -> [ Walk.inside s (Ray.at r t) ]
      in
      let dt = 0.002 in
      let t_hit = Walk.intersect s r 0. Float.infinity in
      let s0 = inside 0. in
      let rec first k =
        if k > 6000 then None
        else if inside (Float.of_int k *. dt) <> s0 then Some k
        else first (k + 1)
      in
      match first 1 with
      | None ->
          (* No change seen: no hit, or one on a feature thinner than a sample step. *)
          QCheck.assume (t_hit = Float.infinity || t_hit > 12.);
          true
      | Some k ->
          let lo = Float.of_int (k - 1) *. dt and hi = Float.of_int k *. dt in
          if t_hit >= lo -. 1e-9 && t_hit <= hi +. 1e-9 then true
          else
            QCheck.Test.fail_reportf
              "hit at %.9g, first change of the inside in [%.9g, %.9g]" t_hit lo hi)

(* The BVH over CSG objects gives the brute-force scan's nearest hits. *)
let test_bvh_brute =
  QCheck.Test.make
    ~name:"the BVH's nearest hit among CSG objects is the brute-force scan's" ~count:40
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let prims =
        Array.init 24 (fun _ ->
            let tf =
              Transform.translate
                (Vec3.v (rnd st (-6.) 6.) (rnd st (-6.) 6.) (rnd st (-6.) 6.))
            in
            Primitive.make ~transform:tf Material.default (random_tree st 2))
      in
      let bvh = Accel.build prims
      and brute = Accel.build (Array.map Primitive.without_bounds prims) in
      assert (Accel.uses_bvh bvh);
      List.for_all
        (fun _ ->
          let o = Vec3.v (rnd st (-12.) 12.) (rnd st (-12.) 12.) (-20.) in
          let r =
            ray o
              (Vec3.normalize
                 (Vec3.sub
                    (Vec3.v (rnd st (-6.) 6.) (rnd st (-6.) 6.) (rnd st (-6.) 6.))
                    o))
          in
          let a = Queries.nearest bvh r 0. Float.infinity
          and b = Queries.nearest brute r 0. Float.infinity in
          if a = b then true
          else
            QCheck.Test.fail_reportf "BVH (%g, %d), brute force (%g, %d)" (fst a) (snd a)
              (fst b) (snd b))
        (List.init 200 Fun.id))

(* --- A hollow glass sphere -------------------------------------------------------- *)

let hollow_scene =
  {|settings { width: 64, height: 48, depth: 6 }
camera { position: (0, 1.5, -5), look_at: (0, 0.3, 0) }
light { position: (-4, 6, -5) }
plane { normal: (0, 1, 0), offset: -1, material: material { texture: checker((1, 1, 1), (0.1, 0.1, 0.1), 0.5) } }
difference {
  sphere { center: (0, 0.2, 0), radius: 1 }
  sphere { center: (0, 0.2, 0), radius: 0.8 }
  material: material { color: (0.9, 0.95, 1), transparency: 0.85, reflection: 0.05, ior: 1.5 }
}
|}

(* The same picture without CSG: the outer sphere, and the inner one with its normal
   reversed (pointing into the cavity), both of the glass. *)
let test_hollow_glass () =
  let prog =
    match Lancer.Program.load_string hollow_scene with
    | Ok p -> p
    | Error _ -> Alcotest.fail "the scene does not load"
  in
  let sc =
    match Lancer.Program.scene_at prog ~time:0. ~frame:0 with
    | Ok s -> s
    | Error _ -> Alcotest.fail "the scene does not evaluate"
  in
  let floor = sc.objects.(0) and shell = sc.objects.(1) in
  Alcotest.(check bool) "the shell is one CSG object" true (Primitive.is_csg shell);
  let glass = shell.extra.leaves.(0).material in
  let c = Vec3.v 0. 0.2 0. in
  let plain =
    Scene.make_exn ~settings:sc.settings ~camera:sc.camera
      ~lights:(Array.to_list sc.lights)
      [
        floor;
        Primitive.make glass (Shape.sphere ~center:c ~radius:1.);
        Primitive.make ~flip:true glass (Shape.sphere ~center:c ~radius:0.8);
      ]
  in
  let a, _ = Render.render sc and b, _ = Render.render plain in
  let bytes im = Image.to_bytes sc.settings.gamma im in
  Alcotest.(check bool) "pixel for pixel" true (Bytes.equal (bytes a) (bytes b));
  (* And the shell is not the solid ball (the test can tell them apart). *)
  let solid =
    Scene.make_exn ~settings:sc.settings ~camera:sc.camera
      ~lights:(Array.to_list sc.lights)
      [ floor; Primitive.make glass (Shape.sphere ~center:c ~radius:1.) ]
  in
  let d, _ = Render.render solid in
  Alcotest.(check bool)
    "differs from a solid glass ball" false
    (Bytes.equal (bytes a) (bytes d))

(* --- Cone ---------------------------------------------------------------------------- *)

(* A cone of radius 1 at y = 0 narrowing to a point at y = 1: at y = 0.5 its radius is
   0.5. From below, the base cap, or without caps the inside of the side where r = 0.2. *)
let test_cone () =
  let cone caps =
    Shape.cone ~base:Vec3.zero ~top:Vec3.y_axis ~base_radius:1. ~top_radius:0. ~caps
  in
  close "side" 4.5
    (Shape.intersect (cone true)
       (ray (Vec3.v (-5.) 0.5 0.) Vec3.x_axis)
       0. Float.infinity);
  let up = ray (Vec3.v 0.2 (-5.) 0.) Vec3.y_axis in
  close "base cap" 5. (Shape.intersect (cone true) up 0. Float.infinity);
  close ~eps:1e-12 "open: the side from inside" 5.8
    (Shape.intersect (cone false) up 0. Float.infinity);
  Alcotest.(check bool) "inside" true (Shape.inside (cone true) (Vec3.v 0.1 0.5 0.1));
  Alcotest.(check bool) "outside" false (Shape.inside (cone true) (Vec3.v 0.45 0.5 0.3));
  let n = Shape.normal (cone true) (Vec3.v (-0.5) 0.5 0.) in
  close ~eps:1e-12 "side normal x" (-.Float.sqrt 0.5) n.x;
  close ~eps:1e-12 "side normal y" (Float.sqrt 0.5) n.y

(* --- Torus --------------------------------------------------------------------------- *)

let torus_r = 1.
and torus_rr = 0.25

let torus = Shape.torus ~center:Vec3.zero ~axis:Vec3.y_axis ~major:torus_r ~minor:torus_rr

(* Every root of the torus along r, found by asking again past each one. *)
let all_roots s r =
  let rec go tmin acc k =
    let t = Shape.intersect s r tmin Float.infinity in
    if t = Float.infinity || k > 8 then List.rev acc else go t (t :: acc) (k + 1)
  in
  go 0. [] 0

let check_roots what ~eps want got =
  if List.length want <> List.length got then
    Alcotest.failf "%s: want %d roots (%s), got %d (%s)" what (List.length want)
      (String.concat ", " (List.map (Printf.sprintf "%.17g") want))
      (List.length got)
      (String.concat ", " (List.map (Printf.sprintf "%.17g") got));
  List.iter2 (fun w g -> close ~eps what w g) want got

(* The reference for a ray through the centre, computed independently of the renderer's
   solver: along p = s·u, with c = 1 − (u·axis)², the quartic is a quadratic in w = s²,
   w² + (2K − 4R²c)·w + K² = 0 with K = R² − r², solved by the stable formula. *)
let centre_roots ~dist (u : Vec3.t) =
  let k = (torus_r *. torus_r) -. (torus_rr *. torus_rr) and c = 1. -. (u.y *. u.y) in
  let b = (2. *. k) -. (4. *. torus_r *. torus_r *. c) and cc = k *. k in
  let disc = (b *. b) -. (4. *. cc) in
  if disc < 0. then []
  else
    let q = -0.5 *. (b +. (Float.of_int (compare b 0.) *. Float.sqrt disc)) in
    let ws = List.filter (fun w -> w >= 0.) [ q; cc /. q ] in
    let ss = List.concat_map (fun w -> [ -.Float.sqrt w; Float.sqrt w ]) ws in
    List.sort compare (List.map (fun s -> dist +. s) ss)

let test_torus_centre_rays () =
  let st = Random.State.make [| 7 |] in
  for _ = 1 to 200 do
    (* Directions a little off the plane of the ring, so that the ray meets the tube. *)
    let u =
      Vec3.normalize (Vec3.v (rnd st (-1.) 1.) (rnd st (-0.15) 0.15) (rnd st (-1.) 1.))
    in
    List.iter
      (fun (dist, eps) ->
        let o = Vec3.smul (-.dist) u in
        check_roots
          (Printf.sprintf "through the centre from %g" dist)
          ~eps (centre_roots ~dist u)
          (all_roots torus (ray o u)))
      [ (5., 1e-12); (1e6, 1e-8) ]
  done

let test_torus_axis_parallel () =
  (* At distance ρ from the axis, parallel to it: y = ±√(r² − (ρ − R)²). *)
  List.iter
    (fun (rho, dist) ->
      let h =
        Float.sqrt ((torus_rr *. torus_rr) -. ((rho -. torus_r) *. (rho -. torus_r)))
      in
      check_roots
        (Printf.sprintf "parallel to the axis at %g from %g" rho dist)
        ~eps:(if dist > 100. then 1e-8 else 1e-12)
        [ dist -. h; dist +. h ]
        (all_roots torus (ray (Vec3.v rho dist 0.) (Vec3.v 0. (-1.) 0.))))
    [ (1., 5.); (1.2, 5.); (0.8, 1e6); (1.1, 1e6) ]

let test_torus_tangent () =
  (* Along x in the plane y = r: the ray touches the top of the tube at x = ±R. *)
  List.iter
    (fun dist ->
      let eps = if dist > 100. then 1e-8 else 1e-12 in
      check_roots
        (Printf.sprintf "tangent to the top of the tube from %g" dist)
        ~eps
        [ dist -. torus_r; dist +. torus_r ]
        (all_roots torus (ray (Vec3.v (-.dist) torus_rr 0.) Vec3.x_axis));
      (* Along x at z = R + r: the ray grazes the outer equator at x = 0. *)
      check_roots
        (Printf.sprintf "grazing the outer equator from %g" dist)
        ~eps [ dist ]
        (all_roots torus (ray (Vec3.v (-.dist) 0. (torus_r +. torus_rr)) Vec3.x_axis)))
    [ 3.; 1e6 ];
  (* Just inside the top, four roots; just outside, none. *)
  Alcotest.(check int)
    "just inside the top" 4
    (List.length (all_roots torus (ray (Vec3.v (-3.) (torus_rr -. 1e-9) 0.) Vec3.x_axis)));
  Alcotest.(check int)
    "just above the top" 0
    (List.length (all_roots torus (ray (Vec3.v (-3.) (torus_rr +. 1e-6) 0.) Vec3.x_axis)))

(* Any ray: each root lies on the surface, and the roots are where the inside changes. *)
let test_torus_random =
  QCheck.Test.make ~name:"a torus's roots lie on it, and its inside changes exactly there"
    ~count:500
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let axis =
        Vec3.normalize (Vec3.v (rnd st (-1.) 1.) (rnd st (-1.) 1.) (rnd st (-1.) 1.))
      in
      let s = Shape.torus ~center:Vec3.zero ~axis ~major:1. ~minor:0.3 in
      let r = random_ray st in
      let roots = all_roots s r in
      let on_surface t =
        let p = Ray.at r t in
        let y = Vec3.dot p axis in
        let rho = Float.sqrt (Float.max 0. (Vec3.dot p p -. (y *. y))) in
        Float.abs (Float.sqrt (((rho -. 1.) *. (rho -. 1.)) +. (y *. y)) -. 0.3) < 1e-12
      in
      let changes = ref 0 in
      let prev = ref (Shape.inside s (Ray.at r 0.)) in
      for k = 1 to 10000 do
        let v = Shape.inside s (Ray.at r (Float.of_int k *. 0.001)) in
        if v <> !prev then incr changes;
        prev := v
      done;
      List.for_all on_surface roots
      && (List.length roots = !changes
         ||
         (QCheck.assume false;
          true)))

(* --- Height field ----------------------------------------------------------------- *)

(* A 3×2 image: W×H pixels give (W−1)×(H−1) cells of two triangles, vertex (i, j) at
   O + (sx·i/(W−1), sy·v(i, j), sz·j/(H−1)), v the pixel's luminance in [0, 1]. *)
let test_height_field () =
  let file = Filename.temp_file "lancer_hf" ".ppm" in
  let px =
    [
      0;
      0;
      0;
      255;
      255;
      255;
      51;
      51;
      51;
      (* row 0 *)
      102;
      102;
      102;
      0;
      0;
      0;
      255;
      0;
      0 (* row 1, last pixel red *);
    ]
  in
  let oc = open_out_bin file in
  output_string oc "P6\n3 2\n255\n";
  List.iter (fun b -> output_char oc (Char.chr b)) px;
  close_out oc;
  let scene =
    Printf.sprintf "height_field { file: %S, origin: (1, 2, 3), size: (4, 10, 2) }" file
  in
  let prog =
    match Lancer.Program.load_string scene with
    | Ok p -> p
    | Error _ -> Alcotest.fail "the scene does not load"
  in
  let sc =
    match Lancer.Program.scene_at prog ~time:0. ~frame:0 with
    | Ok s -> s
    | Error _ -> Alcotest.fail "the scene does not evaluate"
  in
  Sys.remove file;
  Alcotest.(check int) "two triangles per cell" 4 (Array.length sc.objects);
  let acc = Accel.build sc.objects in
  let down x z = Ray.make (Vec3.v x 100. z) (Vec3.v 0. (-1.) 0.) in
  let height x z =
    let t, i = Queries.nearest acc (down x z) 0. Float.infinity in
    if i < 0 then Float.nan else 100. -. t
  in
  (* Vertices: (i, j) = (1, 0) is white, (2, 0) grey 51, (0, 1) grey 102, (2, 1) red. *)
  close ~eps:1e-9 "white vertex" 12. (height 3. 3.);
  close ~eps:1e-9 "grey vertex" (2. +. (10. *. 51. /. 255.)) (height 5. 3.);
  close ~eps:1e-9 "grey vertex of row 1" (2. +. (10. *. 102. /. 255.)) (height 1. 5.);
  close ~eps:1e-9 "a red pixel is its luminance" (2. +. (10. *. 0.2126)) (height 5. 5.);
  (* Midway along the edge from (0, 0) (black) to (1, 0) (white). *)
  close ~eps:1e-9 "linear between vertices" 7. (height 2. 3.);
  Alcotest.(check bool) "outside the grid: no hit" true (Float.is_nan (height 5.5 4.))

(* --- Closed meshes ------------------------------------------------------------------ *)

let cube_obj ~faces =
  let file = Filename.temp_file "lancer_cube" ".obj" in
  let oc = open_out file in
  output_string oc
    "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n";
  List.iteri
    (fun i f -> if i < faces then output_string oc (f ^ "\n"))
    [ "f 1 4 3 2"; "f 5 6 7 8"; "f 1 2 6 5"; "f 4 8 7 3"; "f 1 5 8 4"; "f 2 3 7 6" ];
  close_out oc;
  file

let load_scene text =
  match Lancer.Program.load_string text with
  | Error es ->
      Error (String.concat "\n" (List.map (fun (e : Lancer_dsl.Error.t) -> e.message) es))
  | Ok p -> (
      match Lancer.Program.scene_at p ~time:0. ~frame:0 with
      | Ok s -> Ok s
      | Error es ->
          Error
            (String.concat "\n" (List.map (fun (e : Lancer_dsl.Error.t) -> e.message) es))
      )

(* A sphere minus a closed OBJ cube: along the axis, the ray meets the sphere, then the
   cube's face (the cavity's wall, facing the ray), then the far face and the sphere. *)
let test_closed_mesh () =
  let file = cube_obj ~faces:6 in
  let sc =
    load_scene
      (Printf.sprintf
         "difference { sphere { center: (0, 0, 0), radius: 2 } mesh { file: %S, scale: \
          0.5 } }"
         file)
  in
  Sys.remove file;
  match sc with
  | Error m -> Alcotest.fail m
  | Ok sc ->
      let o = sc.objects.(0) in
      let r = Ray.make (Vec3.v 0.1 0.2 (-5.)) Vec3.z_axis in
      let ts = List.map fst (crossings o.shape r 0.) in
      check_roots "crossings" ~eps:1e-9
        [ 5. -. Float.sqrt (4. -. 0.05); 4.5; 5.5; 5. +. Float.sqrt (4. -. 0.05) ]
        ts;
      let s, _ = Queries.surface o r 4.4 Float.infinity in
      let n = Primitive.normal s (Primitive.to_object s (Ray.at r 4.5)) in
      if not (n.z > 0.99) then
        Alcotest.failf "the cavity's wall faces (%g, %g, %g), not the ray" n.x n.y n.z

let test_open_mesh_refused () =
  let file = cube_obj ~faces:5 in
  let sc =
    load_scene
      (Printf.sprintf
         "intersection { sphere { center: (0, 0, 0), radius: 2 } mesh { file: %S } }" file)
  in
  Sys.remove file;
  match sc with
  | Ok _ -> Alcotest.fail "an open mesh was accepted"
  | Error m ->
      if not (contains m "4 edges are not shared by exactly two faces") then
        Alcotest.failf "unexpected message: %s" m

(* --- Physics ------------------------------------------------------------------------- *)

let test_physics_union_of_boxes () =
  let scene =
    "union { box { min: (-5, -1, -5), max: (5, 0, 5) } plane { normal: (1, 0, 0), \
     offset: 6 } translate: (0, -1, 0) }\n\
     body ball { sphere { center: (0, 2, 0), radius: 0.5 } }"
  in
  match Lancer.Program.load_string scene with
  | Error _ -> Alcotest.fail "the scene does not load"
  | Ok p -> (
      match Lancer.Program.colliders p with
      | [ Physics.Box { max; _ }; Physics.Plane _ ] ->
          close "the box's top, moved with the union" (-1.) max.y
      | l ->
          Alcotest.failf "want the union's box and plane as colliders, got %d colliders"
            (List.length l))

let test_physics_refuses_difference () =
  let scene =
    "difference { box { min: (-5, -1, -5), max: (5, 0, 5) } sphere { center: (0, 0, 0), \
     radius: 1 } }\n\
     body ball { sphere { center: (0, 2, 0), radius: 0.5 } }"
  in
  match load_scene scene with
  | Ok _ -> Alcotest.fail "a body over a difference was simulated"
  | Error m ->
      if not (contains m "bodies cannot collide with this difference") then
        Alcotest.failf "unexpected message: %s" m

(* --- check and --json ---------------------------------------------------------------- *)

let test_check_describes_trees () =
  let text =
    "difference { box { min: (-1, -1, -1), max: (1, 1, 1) } union { sphere { center: (1, \
     0, 0), radius: 0.5 } torus { center: (0, 0, 0), major: 1, minor: 0.2, material: \
     material { color: (1, 0, 0) } } } translate: (0, 1, 0) }"
  in
  let p =
    match Lancer.Program.load_string text with
    | Ok p -> p
    | Error _ -> Alcotest.fail "the scene does not load"
  in
  let sc =
    match Lancer.Program.scene_at p ~time:0. ~frame:0 with
    | Ok s -> s
    | Error _ -> Alcotest.fail "no scene"
  in
  let summary = Lancer.Program.summary p sc in
  if not (contains summary "csg: 1 object: difference(box, union(sphere, torus))") then
    Alcotest.failf "summary:\n%s" summary;
  let open Yojson.Safe.Util in
  let o = Lancer.Program.to_json p sc |> member "objects" |> index 0 in
  Alcotest.(check string) "kind" "difference" (o |> member "kind" |> to_string);
  let inner = o |> member "members" |> index 1 in
  Alcotest.(check string) "nested kind" "union" (inner |> member "kind" |> to_string);
  let torus = inner |> member "fields" |> member "members" |> index 1 in
  Alcotest.(check string) "leaf kind" "torus" (torus |> member "kind" |> to_string);
  Alcotest.(check (float 0.))
    "leaf field" 0.2
    (torus |> member "fields" |> member "minor" |> to_float);
  Alcotest.(check bool) "leaf material" true (torus |> member "material" <> `Null)

(* A 16-bit image keeps its precision: a sample of 1 of 65535 is not rounded to 0. *)
let test_height_field_16_bit () =
  let file = Filename.temp_file "lancer_hf16" ".ppm" in
  let oc = open_out_bin file in
  output_string oc "P6\n2 2\n65535\n";
  let sample v =
    output_char oc (Char.chr (v lsr 8));
    output_char oc (Char.chr (v land 255))
  in
  List.iter
    (fun v ->
      sample v;
      sample v;
      sample v)
    [ 1; 0; 0; 0 ];
  close_out oc;
  let scene = Printf.sprintf "height_field { file: %S, size: (1, 65535, 1) }" file in
  let r = load_scene scene in
  Sys.remove file;
  match r with
  | Error m -> Alcotest.fail m
  | Ok sc ->
      let acc = Accel.build sc.objects in
      let t, _ =
        Queries.nearest acc
          (Ray.make (Vec3.v 0. 100. 0.) (Vec3.v 0. (-1.) 0.))
          0. Float.infinity
      in
      close ~eps:1e-9 "the corner of sample 1 stands at 1" 1. (100. -. t)

(* --- Bounds and errors -------------------------------------------------------------- *)

(* One BVH leaf per CSG object: an intersection is bounded by the overlap of its
   members' boxes, a difference by its first member's. *)
let test_bounds () =
  let a = sphere 0. 0. 0. 1.
  and b = Shape.box ~min:(Vec3.v 0. (-3.) (-3.)) ~max:(Vec3.v 3. 3. 3.) in
  let check what (want_min, want_max) s =
    match Shape.bbox s with
    | None -> Alcotest.failf "%s: unbounded" what
    | Some (bb : Bbox.t) ->
        if not (Vec3.equal_f bb.min want_min && Vec3.equal_f bb.max want_max) then
          Alcotest.failf "%s: (%g, %g, %g)–(%g, %g, %g)" what bb.min.x bb.min.y bb.min.z
            bb.max.x bb.max.y bb.max.z
  in
  check "intersection"
    (Vec3.v 0. (-1.) (-1.), Vec3.v 1. 1. 1.)
    (Shape.csg Intersection [ (a, id); (b, id) ]);
  check "difference"
    (Vec3.v (-1.) (-1.) (-1.), Vec3.one)
    (Shape.csg Difference [ (a, id); (b, id) ]);
  check "merge"
    (Vec3.v (-1.) (-3.) (-3.), Vec3.v 3. 3. 3.)
    (Shape.csg Merge [ (a, id); (b, id) ]);
  let p =
    Primitive.make Material.default
      (Shape.csg Union [ (a, id); (Shape.plane ~normal:Vec3.y_axis ~offset:0., id) ])
  in
  Alcotest.(check bool) "a union with a plane is unbounded" true (p.bounds = None)

let located text =
  match Lancer.Program.load_string ~filename:"t.rts" text with
  | Ok _ -> Alcotest.failf "accepted: %s" text
  | Error es -> List.map (fun (e : Lancer_dsl.Error.t) -> (e.line, e.col, e.message)) es

let test_not_solid_located () =
  (match
     located
       "intersection {\n\
       \  sphere { center: (0, 0, 0), radius: 1 }\n\
       \  disk { center: (0, 0, 0), normal: (0, 1, 0), radius: 1 }\n\
        }"
   with
  | [ (3, 3, m) ] ->
      if not (contains m "a disk is not a solid") then Alcotest.failf "message: %s" m
  | l -> Alcotest.failf "want one error at 3:3, got %d" (List.length l));
  (match located "difference { sphere { center: (0, 0, 0), radius: 1 } }" with
  | [ (1, 1, m) ] ->
      if not (contains m "at least one to subtract") then Alcotest.failf "message: %s" m
  | l -> Alcotest.failf "want one error at 1:1, got %d" (List.length l));
  match located "merge { }" with
  | [ (1, 1, m) ] ->
      if not (contains m "needs at least one object") then Alcotest.failf "message: %s" m
  | l -> Alcotest.failf "want one error at 1:1, got %d" (List.length l)

(* Far from the world's origin the scene is rendered in coordinates centred near the
   camera: a CSG object moved there (by a power of two, an exact move) renders as it does
   at the origin, its leaves moved with it. *)
let test_far_from_origin () =
  let scene dx =
    Printf.sprintf
      {|settings { width: 48, height: 36 }
camera { position: (%.17g, 2, -5), look_at: (%.17g, 0, 0) }
light { position: (%.17g, 6, -5) }
difference {
  box { min: (-1, -1, -1), max: (1, 1, 1) }
  sphere { center: (-1, 0.3, -1), radius: 0.8, material: material { color: (0.2, 0.4, 1) } }
  material: material { color: (1, 0.3, 0.2), texture: checker((1, 0.3, 0.2), (1, 1, 1), 0.5) }
  translate: (%.17g, 0, 0)
}|}
      dx dx (dx -. 4.) dx
  in
  let render dx =
    match load_scene (scene dx) with
    | Error m -> Alcotest.fail m
    | Ok sc ->
        let im, _ = Render.render sc in
        Image.to_bytes sc.settings.gamma im
  in
  Alcotest.(check bool)
    "the same picture at 2^20" true
    (Bytes.equal (render 0.) (render 1048576.))

(* Shadow rays through a CSG object whose leaves differ: an opaque box with a glass
   sphere subtracted from it blocks the light where the ray crosses the box's solid part,
   and nowhere does the glass leaf make it see through the box. *)
let test_mixed_shadow () =
  let glass = { Material.default with transparency = 0.9; ior = 1.5 } in
  let shape =
    Shape.csg Difference
      [
        (Shape.box ~min:(Vec3.v (-1.) (-1.) (-1.)) ~max:Vec3.one, id);
        (sphere 0. 0. (-1.) 0.5, id);
      ]
  in
  let p = Primitive.make ~leaf_materials:[| None; Some glass |] Material.default shape in
  let sc = Scene.make_exn ~lights:[ Light.point (Vec3.v 0. 0. 10.) ] [ p ] in
  let st = Task.create () in
  let through_box = Shade.transmittance sc st (Vec3.v 0.5 0.5 (-5.)) Vec3.z_axis 20. in
  Alcotest.(check bool)
    "through the box's solid part: black" true
    (through_box.r = 0. && through_box.g = 0.);
  let through_pit = Shade.transmittance sc st (Vec3.v 0. 0. (-5.)) Vec3.z_axis 20. in
  Alcotest.(check bool)
    "through the glass pit and then the box: black" true (through_pit.r = 0.);
  let beside = Shade.transmittance sc st (Vec3.v 3. 0. (-5.)) Vec3.z_axis 20. in
  Alcotest.(check bool)
    "beside it: white" true
    (beside.r = 1. && beside.g = 1. && beside.b = 1.);
  (* And a glass difference with an opaque pit's wall: the wall blocks. *)
  let p = Primitive.make ~leaf_materials:[| None; Some Material.default |] glass shape in
  let sc = Scene.make_exn ~lights:[ Light.point (Vec3.v 0. 0. 10.) ] [ p ] in
  let through_wall = Shade.transmittance sc st (Vec3.v 0. 0. (-5.)) Vec3.z_axis 20. in
  Alcotest.(check bool)
    "through the opaque pit wall of a glass box: black" true (through_wall.r = 0.);
  let through_glass = Shade.transmittance sc st (Vec3.v 0.7 0.7 (-5.)) Vec3.z_axis 20. in
  close ~eps:1e-12 "through the glass box: two glass walls" (0.9 *. 0.9) through_glass.r;
  (* Glass members of a CSG object that has no material of its own: the light passes. *)
  let shell =
    Shape.csg Difference [ (sphere 0. 0. 0. 1., id); (sphere 0. 0. 0. 0.8, id) ]
  in
  let p =
    Primitive.make ~leaf_materials:[| Some glass; Some glass |] Material.default shell
  in
  let sc = Scene.make_exn ~lights:[ Light.point (Vec3.v 0. 0. 10.) ] [ p ] in
  let through_shell = Shade.transmittance sc st (Vec3.v 0. 0. (-5.)) Vec3.z_axis 20. in
  close ~eps:1e-12 "through a shell of glass members: four walls" (0.9 ** 4.)
    through_shell.r

(* --- Nested CSG objects --------------------------------------------------------- *)

(* The crossings by their definition: every member's roots (a nested object's own
   crossings), merged in order of (t, leaf); the object's whole inside tested at the
   middle of each gap and past the last root; a root where it changes is a crossing (a
   union keeps them all). [Walk.shape_crossings] follows a nested object's inside from its
   crossings instead of testing it at every gap, and must give the same list, bit for
   bit. Members are simple shapes or CSG objects (no meshes); a simple shape itself has
   its roots. *)
let rec reference_crossings (s : Shape.t) r tmin =
  match s with
  | Shape.Csg { op; members; _ } -> (
      let member (m : Shape.csg_member) =
        let r' =
          if Transform.is_identity m.transform then r
          else
            Ray.make_raw
              (Transform.inv_point m.transform (Ray.origin r))
              (Transform.inv_vector m.transform (Ray.dir r))
        in
        match m.shape with
        | Shape.Csg _ ->
            List.map
              (fun (t, l) -> (t, m.first_leaf + l))
              (reference_crossings m.shape r' tmin)
        | sh ->
            let rec go tmin k =
              let t = Shape.intersect sh r' tmin Float.infinity in
              if t < Float.infinity && k < 64 then (t, m.first_leaf) :: go t (k + 1)
              else []
            in
            go tmin 0
      in
      let roots =
        List.stable_sort
          (fun ((a : float), (i : int)) (b, j) ->
            if a < b then -1 else if a > b then 1 else Int.compare i j)
          (List.concat_map member (Array.to_list members))
      in
      let state t = Walk.inside s (Ray.at r t) in
      let rec skip t = function (t', _) :: rest when t' = t -> skip t rest | l -> l in
      let rec walk before = function
        | [] -> []
        | (t, leaf) :: rest ->
            let rest = skip t rest in
            let probe =
              match rest with
              | (t', _) :: _ -> 0.5 *. (t +. t')
              | [] -> t +. Float.max 1. (Float.abs t)
            in
            let after = state probe in
            if after <> before then (t, leaf) :: walk after rest else walk before rest
      in
      match roots with
      | [] -> []
      | _ when op = Union -> roots
      | (t0, _) :: _ -> walk (state (0.5 *. (tmin +. t0))) roots)
  | _ ->
      (* A simple shape: its roots, on leaf 0. *)
      let rec go tmin =
        let t = Shape.intersect s r tmin Float.infinity in
        if t < Float.infinity then (t, 0) :: go t else []
      in
      go tmin

let same_bits (a : float) b = Int64.equal (Int64.bits_of_float a) (Int64.bits_of_float b)

let same_crossings want got =
  List.length want = List.length got
  && List.for_all2 (fun (t, l) (t', l') -> same_bits t t' && l = l') want got

let show_crossings l =
  String.concat ", " (List.map (fun (t, l) -> Printf.sprintf "%.17g@%d" t l) l)

let check_crossings what s r tmin =
  let want = reference_crossings s r tmin and got = crossings s r tmin in
  same_crossings want got
  || QCheck.Test.fail_reportf "%s: by definition [%s], got [%s]" what
       (show_crossings want) (show_crossings got)

let test_crossings_by_definition =
  QCheck.Test.make ~name:"a random CSG tree's crossings are its definition's, bit for bit"
    ~count:500
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let s = random_tree st 4 in
      List.for_all
        (fun tmin -> check_crossings "random tree" s (random_ray st) tmin)
        [ 0.; rnd st 2. 6. ])

(* A tree [n] deep in which each level combines the one below with a random sphere or
   box, by [op] or, without it, a random operation; some levels placed by a turn and a
   move. *)
let chain ?op st n =
  let leaf () =
    let c = Vec3.v (rnd st (-1.) 1.) (rnd st (-1.) 1.) (rnd st (-1.) 1.) in
    if Random.State.bool st then Shape.sphere ~center:c ~radius:(rnd st 0.1 0.6)
    else
      let h = Vec3.v (rnd st 0.1 0.5) (rnd st 0.1 0.5) (rnd st 0.1 0.5) in
      Shape.box ~min:(Vec3.sub c h) ~max:(Vec3.add c h)
  in
  let rec go k below =
    if k = 0 then below
    else
      let op : Shape.csg_op =
        match op with
        | Some op -> op
        | None -> (
            match Random.State.int st 4 with
            | 0 -> Union
            | 1 -> Merge
            | 2 -> Intersection
            | _ -> Difference)
      in
      let tf =
        if Random.State.int st 4 > 0 then id
        else
          Transform.then_
            (Transform.rotate (Vec3.v (rnd st 0. 10.) (rnd st 0. 10.) (rnd st 0. 10.)))
            (Transform.translate
               (Vec3.v (rnd st (-0.1) 0.1) (rnd st (-0.1) 0.1) (rnd st (-0.1) 0.1)))
      in
      go (k - 1) (Shape.csg op [ (below, tf); (leaf (), id) ])
  in
  go n (Shape.sphere ~center:Vec3.zero ~radius:1.5)

let test_deep_chains () =
  let st = Random.State.make [| 20270101 |] in
  List.iter
    (fun (what, op) ->
      let s = chain ?op st 150 in
      for _ = 1 to 300 do
        ignore (check_crossings what s (random_ray st) 0.)
      done)
    [
      ("a difference nested 150 deep", Some Shape.Difference);
      ("an intersection nested 150 deep", Some Shape.Intersection);
      ("a merge nested 150 deep", Some Shape.Merge);
      ("operations nested 150 deep at random", None);
    ]

(* The leaves as the levels would list them one at a time: each member's own (a nested
   object's composed with the member's transform, and flipped where this level subtracts
   it), as (surface, transform, flipped). *)
let rec reference_leaves (s : Shape.t) =
  match s with
  | Shape.Csg { op; members; _ } ->
      List.concat
        (List.mapi
           (fun i (m : Shape.csg_member) ->
             let subtracted = op = Difference && i > 0 in
             match m.shape with
             | Shape.Csg _ ->
                 List.map
                   (fun (sh, tr, flipped) ->
                     (sh, Transform.then_ tr m.transform, flipped <> subtracted))
                   (reference_leaves m.shape)
             | sh -> [ (sh, m.transform, subtracted) ])
           (Array.to_list members))
  | _ -> []

(* Two transforms that move three points, and back, to the same bits. *)
let same_transform a b =
  List.for_all
    (fun p ->
      let same (u : Vec3.t) (v : Vec3.t) =
        same_bits u.x v.x && same_bits u.y v.y && same_bits u.z v.z
      in
      same (Transform.point a p) (Transform.point b p)
      && same (Transform.inv_point a p) (Transform.inv_point b p))
    [ Vec3.v 0.3 (-1.7) 2.9; Vec3.v (-5.) 0.1 0.7; Vec3.v 1e3 2e-3 (-7.) ]

let same_leaves s =
  let want = reference_leaves s and got = Array.to_list (Shape.csg_leaves s) in
  List.length want = List.length got
  && List.for_all2
       (fun (sh, tr, flipped) (l : Shape.csg_leaf) ->
         sh == l.leaf_shape && flipped = l.flipped && same_transform tr l.leaf_transform)
       want got

let test_leaves_by_level =
  QCheck.Test.make
    ~name:"a random CSG tree's leaves are placed as its levels compose them, bit for bit"
    ~count:300
    QCheck.(int_bound 1_000_000_000)
    (fun seed -> same_leaves (random_tree (Random.State.make [| seed |]) 4))

let test_deep_leaves () =
  let st = Random.State.make [| 20270102 |] in
  let s = chain st 150 in
  Alcotest.(check int)
    "one leaf per level and the base" 151
    (Array.length (Shape.csg_leaves s));
  Alcotest.(check bool) "placed as the levels compose them" true (same_leaves s)

(* A sphere with [n] small red and blue ones taken out of its front one level at a time
   on a spiral, each level turned a little: a difference nested [n] deep whose leaves are
   placed through up to [n] transforms. *)
let nested_difference n =
  let b = Buffer.create (n * 96) in
  Buffer.add_string b
    "settings { width: 64, height: 48 }\n\
     camera { position: (0, 0, -3.4), look_at: (0, 0, 0) }\n\
     light { position: (-3, 5, -5) }\n\
     let red = material { color: (0.9, 0.2, 0.1) }\n\
     let blue = material { color: (0.1, 0.3, 0.9) }\n";
  for _ = 1 to n do
    Buffer.add_string b "difference {\n"
  done;
  Buffer.add_string b "sphere { center: (0, 0, 0), radius: 1.5 }\n";
  for k = 1 to n do
    let a = 2.399963 *. Float.of_int k
    and r = 1.4 *. Float.sqrt (Float.of_int k /. Float.of_int n) in
    Printf.bprintf b
      "sphere { center: (%.6f, %.6f, -1.3), radius: 0.09, material: %s }\n\
       rotate: (0, 0, 0.7)\n\
       }\n"
      (r *. Float.cos a)
      (r *. Float.sin a)
      (if k mod 2 = 1 then "red" else "blue")
  done;
  Buffer.contents b

(* The picture of a difference nested 300 deep is the one rendered (and stored) when each
   level tested the inside of everything below it at every gap. *)
let test_nested_picture () =
  let file = Filename.temp_file "lancer_nested" ".rts" in
  Out_channel.with_open_bin file (fun oc -> output_string oc (nested_difference 300));
  let img = Lancer_alcotest.render_scene file in
  Sys.remove file;
  match img with
  | Error m -> Alcotest.fail m
  | Ok img -> (
      match
        Lancer_alcotest.compare_golden ~tolerance:0 ~golden:"nested_difference.png" img
      with
      | Error m -> Alcotest.fail m
      | Ok (Same _ | Updated _) -> ()
      | Ok (Missing { actual }) ->
          Alcotest.failf "no golden image; the render is in %s" actual
      | Ok (Different { actual; diff; _ }) ->
          Alcotest.failf "the picture changed: %s (differences in %s)" actual diff)

(* --- The walk against linear scans ----------------------------------------------- *)

(* A closed mesh: a torus of [nu]·[nv] quads (two triangles each) whose vertices are moved
   in and out at random, turned at random; a few vertices on round coordinates. *)
let random_closed_mesh st =
  let nu = 3 + Random.State.int st 12 and nv = 3 + Random.State.int st 8 in
  let b = Buffer.create 4096 in
  let turn = Transform.rotate (Vec3.v (rnd st 0. 90.) (rnd st 0. 90.) (rnd st 0. 90.)) in
  let pi = Float.pi in
  for i = 0 to nu - 1 do
    for j = 0 to nv - 1 do
      let u = 2. *. pi *. Float.of_int i /. Float.of_int nu
      and w = 2. *. pi *. Float.of_int j /. Float.of_int nv in
      let r = 0.4 *. rnd st 0.7 1.3 and big = rnd st 0.9 1.1 in
      let p =
        Vec3.v
          ((big +. (r *. Float.cos w)) *. Float.cos u)
          (r *. Float.sin w)
          ((big +. (r *. Float.cos w)) *. Float.sin u)
      in
      let p = Transform.point turn p in
      let p =
        if Random.State.int st 8 = 0 then
          Vec3.v (Float.round (p.x *. 4.) /. 4.) p.y (Float.round (p.z *. 4.) /. 4.)
        else p
      in
      Printf.bprintf b "v %.17g %.17g %.17g\n" p.x p.y p.z
    done
  done;
  for i = 0 to nu - 1 do
    for j = 0 to nv - 1 do
      let id i j = (i mod nu * nv) + (j mod nv) + 1 in
      let a = id i j
      and b' = id (i + 1) j
      and c = id (i + 1) (j + 1)
      and d = id i (j + 1) in
      Printf.bprintf b "f %d %d %d\nf %d %d %d\n" a b' c a c d
    done
  done;
  match Obj_file.parse_mesh ~file:"random" (Buffer.contents b) with
  | Ok m -> m
  | Error e -> failwith e

(* The parity of the faces crossed along [Walk.parity_direction] from [p]: every face in
   turn. *)
let linear_parity faces p =
  let r = Ray.make_raw p Walk.parity_direction in
  List.fold_left
    (fun n f ->
      if Shape.intersect f r 0. Float.infinity < Float.infinity then n + 1 else n)
    0 faces
  land 1
  = 1

(* The inside of [s] at [p] with each solid mesh's parity counted over all its faces. *)
let rec linear_inside (s : Shape.t) p =
  match s with
  | Shape.Mesh { mesh; solid = true } -> linear_parity (Shape.faces mesh) p
  | Shape.Csg { op; members; _ } -> (
      let at (m : Shape.csg_member) =
        linear_inside m.shape (Transform.inv_point m.transform p)
      in
      let l = Array.to_list members in
      match op with
      | Union | Merge -> List.exists at l
      | Intersection -> List.for_all at l
      | Difference -> at (List.hd l) && not (List.exists at (List.tl l)))
  | s -> Shape.inside s p

(* [s]'s crossings after [tmin] as (t, leaf, face), by their definition and with every
   face of a mesh tried in turn: a mesh's roots are each face's, each t once with its
   lowest face; a CSG object's are its members' merged in order of (t, leaf, face), kept
   where the whole object's inside ([linear_inside], tested at the middle of each gap and
   past the last root) changes, or all of them for a union. *)
let rec linear_crossings (s : Shape.t) r tmin =
  match s with
  | Shape.Mesh { mesh; _ } ->
      let faces = Shape.faces mesh in
      let all =
        List.sort compare
          (List.concat
             (List.mapi
                (fun k f ->
                  let t = Shape.intersect f r tmin Float.infinity in
                  if t < Float.infinity then [ (t, 0, k) ] else [])
                faces))
      in
      let rec once = function
        | ((t, _, _) as a) :: ((t', _, _) :: _ as rest) when t = t' ->
            once (a :: List.tl rest)
        | a :: rest -> a :: once rest
        | [] -> []
      in
      once all
  | Shape.Csg { op; members; _ } -> (
      let member (m : Shape.csg_member) =
        let r' =
          if Transform.is_identity m.transform then r
          else
            Ray.make_raw
              (Transform.inv_point m.transform (Ray.origin r))
              (Transform.inv_vector m.transform (Ray.dir r))
        in
        match m.shape with
        | Shape.Mesh { mesh; _ } ->
            (* Every face crossed, as many as cross at one t. *)
            List.concat
              (List.mapi
                 (fun k f ->
                   let t = Shape.intersect f r' tmin Float.infinity in
                   if t < Float.infinity then [ (t, m.first_leaf, k) ] else [])
                 (Shape.faces mesh))
        | Shape.Csg _ ->
            List.map
              (fun (t, l, f) -> (t, m.first_leaf + l, f))
              (linear_crossings m.shape r' tmin)
        | sh ->
            List.map
              (fun (t, _, _) -> (t, m.first_leaf, -1))
              (linear_crossings sh r' tmin)
      in
      let roots = List.sort compare (List.concat_map member (Array.to_list members)) in
      let state t = linear_inside s (Ray.at r t) in
      let rec skip t = function
        | (t', _, _) :: rest when t' = t -> skip t rest
        | l -> l
      in
      let rec walk before = function
        | [] -> []
        | ((t, _, _) as c) :: rest ->
            let rest = skip t rest in
            let probe =
              match rest with
              | (t', _, _) :: _ -> 0.5 *. (t +. t')
              | [] -> t +. Float.max 1. (Float.abs t)
            in
            let after = state probe in
            if after <> before then c :: walk after rest else walk before rest
      in
      match roots with
      | [] -> []
      | _ when op = Union -> roots
      | (t0, _, _) :: _ -> walk (state (0.5 *. (tmin +. t0))) roots)
  | _ ->
      let rec go tmin =
        let t = Shape.intersect s r tmin Float.infinity in
        if t < Float.infinity then (t, 0, -1) :: go t else []
      in
      go tmin

let show3 l =
  String.concat ", " (List.map (fun (t, l, f) -> Printf.sprintf "%.17g@%d/%d" t l f) l)

let same3 want got =
  List.length want = List.length got
  && List.for_all2
       (fun (t, l, f) (t', l', f') -> same_bits t t' && l = l' && f = f')
       want got

(* A solid made of closed mesh [m]: alone, or combined with a box, a sphere or a random
   tree, possibly twice over. *)
let rec mesh_solid st m depth =
  let mesh = Shape.solid_mesh m in
  if depth = 0 || Random.State.int st 4 = 0 then mesh
  else
    let other =
      if Random.State.bool st then random_tree st 1
      else
        let c = Vec3.v (rnd st (-1.) 1.) (rnd st (-0.5) 0.5) (rnd st (-1.) 1.) in
        Shape.box
          ~min:(Vec3.sub c (Vec3.v 0.6 0.6 0.6))
          ~max:(Vec3.add c (Vec3.v 0.6 0.6 0.6))
    in
    let op : Shape.csg_op =
      match Random.State.int st 4 with
      | 0 -> Union
      | 1 -> Merge
      | 2 -> Intersection
      | _ -> Difference
    in
    let inner = mesh_solid st m (depth - 1) in
    let members = if Random.State.bool st then [ inner; other ] else [ other; inner ] in
    let place s =
      if Random.State.bool st then (s, id)
      else (s, Transform.rotate (Vec3.v (rnd st 0. 90.) (rnd st 0. 90.) 0.))
    in
    Shape.csg op (List.map place members)

(* A ray from a sphere of radius 4 at a point of the mesh's region, a vertex of it now and
   then. *)
let mesh_ray st m =
  let o =
    Vec3.smul 4.
      (Vec3.normalize (Vec3.v (rnd st (-1.) 1.) (rnd st (-1.) 1.) (rnd st (-1.) 1.)))
  in
  let target =
    if Random.State.int st 4 = 0 then
      Trimesh.vertex m (Random.State.int st (Trimesh.count m)) (Random.State.int st 3)
    else Vec3.v (rnd st (-1.3) 1.3) (rnd st (-0.5) 0.5) (rnd st (-1.3) 1.3)
  in
  Ray.make o (Vec3.sub target o)

let test_closed_mesh_linear =
  QCheck.Test.make
    ~name:
      "a closed mesh's inside and crossings through its hierarchy are a scan of its \
       faces', alone and in CSG objects, bit for bit"
    ~count:60
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let m = random_closed_mesh st in
      if Float.Array.length (Trimesh.nodes m) = 0 then
        QCheck.Test.fail_report "the mesh has no hierarchy";
      if Obj_file.open_edges_mesh m <> 0 then QCheck.Test.fail_report "the mesh is open";
      let s = mesh_solid st m 3 in
      for _ = 1 to 60 do
        let p =
          if Random.State.int st 4 = 0 then
            Trimesh.vertex m
              (Random.State.int st (Trimesh.count m))
              (Random.State.int st 3)
          else Vec3.v (rnd st (-1.5) 1.5) (rnd st (-0.6) 0.6) (rnd st (-1.5) 1.5)
        in
        let mesh = Shape.solid_mesh m in
        if Walk.inside mesh p <> linear_parity (Shape.faces m) p then
          QCheck.Test.fail_reportf "the mesh's inside at (%.17g, %.17g, %.17g)" p.x p.y
            p.z;
        if Walk.inside s p <> linear_inside s p then
          QCheck.Test.fail_reportf "the solid's inside at (%.17g, %.17g, %.17g)" p.x p.y
            p.z;
        let r = mesh_ray st m
        and tmin = if Random.State.bool st then 0. else rnd st 1. 4. in
        List.iter
          (fun (what, s) ->
            let want = linear_crossings s r tmin
            and got = Walk.shape_crossings s r tmin in
            if not (same3 want got) then
              QCheck.Test.fail_reportf "%s: by a scan [%s], got [%s]" what (show3 want)
                (show3 got))
          [ ("the mesh", mesh); ("the solid", s) ]
      done;
      true)

(* Open edges by their definition: each triangle's three edges as pairs of corner
   positions (lower first, as [compare] orders them), sorted; a run of equal ones is one
   edge, open where it is not two long. *)
let naive_open_edges tris =
  let k (v : Vec3.t) = (v.x, v.y, v.z) in
  let key a b = if compare (k a) (k b) <= 0 then (k a, k b) else (k b, k a) in
  let edges =
    List.sort compare
      (List.concat_map
         (function
           | Shape.Triangle { a; b; c; _ } -> [ key a b; key b c; key c a ] | _ -> [])
         tris)
  in
  let rec runs n = function
    | x :: (y :: _ as rest) when compare x y = 0 -> runs (n + 1) rest
    | _ :: rest -> (if n <> 2 then 1 else 0) + runs 1 rest
    | [] -> 0
  in
  runs 1 edges

let test_open_edges =
  QCheck.Test.make
    ~name:
      "open edges are counted as a sort of the edges by position does, 0 and -0 one, \
       NaNs one"
    ~count:300
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let coord () =
        match Random.State.int st 8 with
        | 0 -> 0.
        | 1 -> -0.
        | 2 -> Float.nan
        | _ -> Float.of_int (Random.State.int st 3) -. 1.
      in
      let pool =
        Array.init
          (2 + Random.State.int st 8)
          (fun _ -> Vec3.v (coord ()) (coord ()) (coord ()))
      in
      let pick () = pool.(Random.State.int st (Array.length pool)) in
      let tris =
        List.init (Random.State.int st 30) (fun _ ->
            Shape.triangle ~a:(pick ()) ~b:(pick ()) ~c:(pick ()))
      in
      let want = naive_open_edges tris and got = Obj_file.open_edges tris in
      (want = got || QCheck.Test.fail_reportf "open edges %d, by a sort %d" got want)
      &&
      let m = random_closed_mesh st in
      let faces =
        List.filteri (fun i _ -> i mod 7 <> 0 || Random.State.bool st) (Shape.faces m)
      in
      Obj_file.open_edges_mesh m = 0
      && Obj_file.open_edges faces = naive_open_edges faces
      || QCheck.Test.fail_reportf "a torus with %d of %d faces" (List.length faces)
           (Trimesh.count m))

(* Random scenes of spheres, boxes, meshes (open or closed), CSG trees and CSG objects of
   closed meshes, some turned and moved, some transparent, a plane now and then. *)
let mixed_scene st =
  let m = random_closed_mesh st in
  let n = 1 + Random.State.int st 30 in
  let one () =
    let s =
      match Random.State.int st 6 with
      | 0 -> sphere (rnd st (-1.) 1.) (rnd st (-1.) 1.) (rnd st (-1.) 1.) (rnd st 0.2 1.)
      | 1 ->
          let c = Vec3.v (rnd st (-1.) 1.) (rnd st (-1.) 1.) (rnd st (-1.) 1.) in
          Shape.box ~min:c ~max:(Vec3.add c (Vec3.v (rnd st 0.1 1.) (rnd st 0.1 1.) 0.5))
      | 2 -> Shape.mesh m
      | 3 -> random_tree st 2
      | 4 -> mesh_solid st m 2
      | _ -> Shape.plane ~normal:Vec3.y_axis ~offset:(rnd st (-8.) (-4.))
    in
    let transform =
      Transform.then_
        (if Random.State.bool st then id
         else Transform.rotate (Vec3.v (rnd st 0. 90.) (rnd st 0. 90.) 0.))
        (Transform.translate
           (Vec3.v (rnd st (-5.) 5.) (rnd st (-3.) 3.) (rnd st (-5.) 5.)))
    in
    let material =
      if Random.State.int st 4 = 0 then { Material.default with transparency = 0.5 }
      else Material.default
    in
    Primitive.make ~transform material s
  in
  Array.init n (fun _ -> one ())

(* Every crossing of each object by itself in (tmin, tmax), as the crossings query gives
   them: (t, index, leaf, face), the leaf −1 but in a CSG object, the face −1 but on a
   mesh. *)
let object_crossings prims r tmin tmax ~transparent =
  List.sort compare
    (List.concat
       (List.mapi
          (fun i (p : Primitive.t) ->
            if transparent && p.material.transparency = 0. then []
            else
              let csg = match p.shape with Shape.Csg _ -> true | _ -> false in
              List.filter_map
                (fun (t, leaf, face) ->
                  if t < tmax then Some (t, i, (if csg then leaf else -1), face) else None)
                (Walk.shape_crossings p.shape (Queries.object_ray p r) tmin))
          (Array.to_list prims)))

let test_walk_brute =
  QCheck.Test.make
    ~name:
      "the walk's three queries over meshes, CSG objects and simple shapes are a scan's, \
       through a tree, without one and in two parts"
    ~count:80
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let prims = mixed_scene st in
      let n = Array.length prims in
      let moving = Array.init n (fun _ -> Random.State.int st 3 = 0) in
      let part want =
        Array.of_list (List.filter (fun i -> moving.(i) = want) (List.init n Fun.id))
      in
      let fixed_idx = part false and moving_idx = part true in
      let sub idx = Array.map (fun i -> prims.(i)) idx in
      let accels =
        [
          ("tree", Accel.build prims);
          ("scan", Accel.build (Array.map Primitive.without_bounds prims));
          ( "two parts",
            Accel.layered prims ~key:[||]
              ~fixed:(Accel.build (sub fixed_idx))
              ~fixed_idx
              ~moving:(Accel.build (sub moving_idx))
              ~moving_idx );
        ]
      in
      for _ = 1 to 60 do
        let o = Vec3.v (rnd st (-9.) 9.) (rnd st (-5.) 5.) (-12.) in
        (* At random, or at a vertex of a mesh's (an edge or a corner of its faces). *)
        let target =
          let p = prims.(Random.State.int st n) in
          match p.shape with
          | Shape.Mesh { mesh; _ } when Random.State.bool st ->
              Transform.point p.transform
                (Trimesh.vertex mesh
                   (Random.State.int st (Trimesh.count mesh))
                   (Random.State.int st 3))
          | _ -> Vec3.v (rnd st (-6.) 6.) (rnd st (-3.) 3.) (rnd st (-6.) 6.)
        in
        let r = Ray.make o (Vec3.sub target o) in
        let tmin = if Random.State.bool st then 0. else rnd st 0. 8.
        and tmax = if Random.State.bool st then Float.infinity else rnd st 8. 30. in
        let every = object_crossings prims r tmin tmax ~transparent:false in
        let want_hit =
          match every with
          | (t, i, leaf, face) :: _ -> (t, i, leaf, face)
          | [] -> (Float.infinity, -1, -1, -1)
        in
        let blocked =
          List.exists
            (fun (_, i, _, _) -> prims.(i).Primitive.material.transparency = 0.)
            every
        in
        let see_through = object_crossings prims r tmin tmax ~transparent:true in
        List.iter
          (fun (name, a) ->
            let t, i, leaf, face = Queries.hit a r tmin tmax in
            let wt, wi, wl, wf = want_hit in
            if not (same_bits t wt && i = wi && leaf = wl && face = wf) then
              QCheck.Test.fail_reportf "%s: nearest %.17g@%d:%d/%d, scan %.17g@%d:%d/%d"
                name t i leaf face wt wi wl wf;
            if Queries.any a r tmin tmax ~opaque:false <> (every <> []) then
              QCheck.Test.fail_reportf "%s: any crossing, scan %b" name (every <> []);
            if
              Queries.any a r tmin tmax ~opaque:true ~slot:(Random.State.int st 2)
              <> blocked
            then QCheck.Test.fail_reportf "%s: an opaque crossing, scan %b" name blocked;
            let same l l' =
              List.length l = List.length l'
              && List.for_all2
                   (fun (t, i, l, f) (t', i', l', f') ->
                     same_bits t t' && i = i' && l = l' && f = f')
                   l l'
            in
            let show l =
              String.concat ", "
                (List.map (fun (t, i, l, f) -> Printf.sprintf "%.17g@%d:%d/%d" t i l f) l)
            in
            let got = Queries.crossings a r tmin tmax ~transparent:false in
            if not (same got every) then
              QCheck.Test.fail_reportf "%s: crossings [%s], scan [%s]" name (show got)
                (show every);
            let got = Queries.crossings a r tmin tmax ~transparent:true in
            if not (same got see_through) then
              QCheck.Test.fail_reportf "%s: transparent crossings [%s], scan [%s]" name
                (show got) (show see_through))
          accels
      done;
      true)

let () =
  Alcotest.run "csg"
    [
      ( "bounds and errors",
        [
          Alcotest.test_case
            "an intersection is bounded by the overlap, a difference by its first member"
            `Quick test_bounds;
          Alcotest.test_case "a member that is not a solid is refused where it is written"
            `Quick test_not_solid_located;
        ] );
      ( "closed form",
        [
          Alcotest.test_case "a ray along the lens's axis enters at 4.5 and leaves at 5.5"
            `Quick test_lens;
          Alcotest.test_case "a ray off the lens's axis crosses where the spheres say"
            `Quick test_lens_off_axis;
          Alcotest.test_case
            "a box minus a sphere: the cavity's wall faces into the cavity" `Quick
            test_cavity_normal;
          Alcotest.test_case "a plane member is the half-space below it" `Quick
            test_plane_half_space;
          Alcotest.test_case "a shadow ray crosses both walls of a hollow sphere" `Quick
            test_shadow_crosses_both_walls;
        ] );
      ( "solids",
        [
          Alcotest.test_case "a cone's side, cap and open inside where the radius says"
            `Quick test_cone;
          Alcotest.test_case
            "torus rays through the centre, near and from 1e6, match the closed form"
            `Quick test_torus_centre_rays;
          Alcotest.test_case "torus rays parallel to its axis, near and from 1e6" `Quick
            test_torus_axis_parallel;
          Alcotest.test_case
            "torus rays tangent to the tube keep their double root, near and from 1e6"
            `Quick test_torus_tangent;
          seeded test_torus_random;
          Alcotest.test_case "a height field's vertices stand at the image's luminance"
            `Quick test_height_field;
          Alcotest.test_case "a 16-bit height field keeps its precision" `Quick
            test_height_field_16_bit;
        ] );
      ( "meshes",
        [
          Alcotest.test_case
            "a closed OBJ cube subtracted from a sphere leaves a cubic cavity" `Quick
            test_closed_mesh;
          Alcotest.test_case "an open mesh is refused with the count of its open edges"
            `Quick test_open_mesh_refused;
          seeded test_open_edges;
        ] );
      ( "physics",
        [
          Alcotest.test_case "a union of a box and a plane collides as its members" `Quick
            test_physics_union_of_boxes;
          Alcotest.test_case "a body over a difference is refused at the difference"
            `Quick test_physics_refuses_difference;
        ] );
      ( "check",
        [
          Alcotest.test_case "check and --json describe a CSG tree, members and materials"
            `Quick test_check_describes_trees;
        ] );
      ( "properties",
        [
          seeded test_first_sign_change;
          seeded test_bvh_brute;
          seeded test_closed_mesh_linear;
          seeded test_walk_brute;
        ] );
      ( "nesting",
        [
          seeded test_crossings_by_definition;
          seeded test_leaves_by_level;
          Alcotest.test_case
            "the leaves of operations nested 150 deep are placed through every level"
            `Quick test_deep_leaves;
          Alcotest.test_case
            "differences, intersections, merges nested 150 deep cross by their definition"
            `Quick test_deep_chains;
          Alcotest.test_case
            "a difference nested 300 deep renders the picture it always has, byte for \
             byte"
            `Quick test_nested_picture;
        ] );
      ( "rendering",
        [
          Alcotest.test_case "a hollow glass sphere is its two surfaces, pixel for pixel"
            `Quick test_hollow_glass;
          Alcotest.test_case "shadows through a CSG object of opaque and glass leaves"
            `Quick test_mixed_shadow;
          Alcotest.test_case
            "a CSG object far from the origin renders as it does at the origin" `Quick
            test_far_from_origin;
        ] );
    ]
