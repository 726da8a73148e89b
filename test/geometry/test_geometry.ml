(* Geometry: hand-computed intersections for every primitive (grazing, parallel,
   inside-origin and tangent rays, the doc/reference/numerics.md values), texture
   coordinates, the OBJ loader, watertightness of meshes and tiled parallelograms, the
   bounding volume hierarchy against brute force, and texture determinism. Random tests
   use fixed seeds. *)
open Lancer

let v = Vec3.v
let inf = Float.infinity
let close ?(eps = 1e-12) msg a b = Alcotest.(check (float eps)) msg a b

let rel msg ~tol expected got =
  if not (Float.abs (got -. expected) <= tol *. Float.abs expected) then
    Alcotest.failf "%s: expected %.17g, got %.17g (relative tolerance %g)" msg expected
      got tol

let check_vec ?(eps = 1e-12) msg (a : Vec3.t) (b : Vec3.t) =
  close ~eps (msg ^ " (x)") a.x b.x;
  close ~eps (msg ^ " (y)") a.y b.y;
  close ~eps (msg ^ " (z)") a.z b.z

let miss msg t =
  if t <> inf then Alcotest.failf "%s: expected a miss, got t = %.17g" msg t

let ray o d = Ray.make o d
let raw o d = Ray.make_raw o d
let hit s r = Walk.intersect s r 0. inf
let same_bits a b = Int64.equal (Int64.bits_of_float a) (Int64.bits_of_float b)
let case name f = Alcotest.test_case name `Quick f

let seeded ?(seed = 20240611) t =
  QCheck_alcotest.to_alcotest ~rand:(Random.State.make [| seed |]) t

(* ---- sphere and plane ---- *)

let sphere_tests =
  let unit_at c = Shape.sphere ~center:c ~radius:1. in
  [
    case "a unit sphere 1e8 away is hit at 99999999.00000001 and 100000001" (fun () ->
        let s = unit_at (v 0. 0. 1e8) and r = ray Vec3.zero Vec3.z_axis in
        close ~eps:1e-6 "near" 99999999.00000001 (hit s r);
        close ~eps:1e-6 "far" 100000001. (Shape.intersect s r 1e8 inf));
    case "a sphere of radius 1e-6 at distance 1 is hit at 1 ∓ 1e-6" (fun () ->
        let s = Shape.sphere ~center:(v 0. 0. 1.) ~radius:1e-6
        and r = ray Vec3.zero Vec3.z_axis in
        close ~eps:1e-15 "near" (1. -. 1e-6) (hit s r);
        close ~eps:1e-15 "far" (1. +. 1e-6) (Shape.intersect s r 1. inf));
    case
      "an unnormalised direction (0,0,1e-3) meets the sphere at z = 10 at t = 9000 and \
       11000" (fun () ->
        let s = unit_at (v 0. 0. 10.) and r = raw Vec3.zero (v 0. 0. 1e-3) in
        rel "near" ~tol:1e-12 9000. (hit s r);
        rel "far" ~tol:1e-12 11000. (Shape.intersect s r 9000. inf));
    case "a ray from inside a sphere hits it once, on the way out" (fun () ->
        let s = unit_at Vec3.zero and r = ray Vec3.zero Vec3.x_axis in
        close "t" 1. (hit s r);
        miss "second" (Shape.intersect s r 1. inf));
    case "a tangent ray touches the sphere at its single point" (fun () ->
        close "t" 5. (hit (unit_at Vec3.zero) (ray (v 1. 0. (-5.)) Vec3.z_axis)));
    case "a ray passing just outside the sphere misses" (fun () ->
        miss "t" (hit (unit_at Vec3.zero) (ray (v 1.000001 0. (-5.)) Vec3.z_axis)));
    case "a plane is missed by a parallel ray even with its origin on the plane"
      (fun () ->
        let p = Shape.plane ~normal:Vec3.y_axis ~offset:0. in
        miss "on" (hit p (ray Vec3.zero Vec3.x_axis));
        miss "above" (hit p (ray Vec3.y_axis Vec3.x_axis)));
    case "a grazing ray at 1e-12 rad hits the plane 1e12 away, finite" (fun () ->
        let p = Shape.plane ~normal:Vec3.y_axis ~offset:0. in
        rel "t" ~tol:1e-9 1e12 (hit p (raw (v 0. 1. 0.) (v 1. (-1e-12) 0.))));
  ]

(* ---- flat shapes ---- *)

let tri = Shape.triangle ~a:Vec3.zero ~b:Vec3.x_axis ~c:Vec3.y_axis

let flat_tests =
  [
    case "a triangle is hit inside, from both sides" (fun () ->
        close "front" 1. (hit tri (ray (v 0.25 0.25 (-1.)) Vec3.z_axis));
        close "back" 1. (hit tri (ray (v 0.25 0.25 1.) (v 0. 0. (-1.)))));
    case "a triangle is missed outside its edges" (fun () ->
        miss "outside" (hit tri (ray (v 0.6 0.6 (-1.)) Vec3.z_axis));
        miss "negative" (hit tri (ray (v (-0.01) 0.5 (-1.)) Vec3.z_axis)));
    case "a ray in the triangle's plane misses it" (fun () ->
        miss "in plane" (hit tri (ray (v (-1.) 0.25 0.) Vec3.x_axis)));
    case "a zero direction never hits anything" (fun () ->
        let r = raw (v 0.25 0.25 (-1.)) Vec3.zero in
        miss "triangle" (hit tri r);
        miss "paraboloid"
          (hit
             (Shape.paraboloid ~vertex:Vec3.zero ~axis:Vec3.y_axis ~radius:1. ~height:1.)
             r));
    case "a triangle's (u, v) are the weights of b and c, and its normal is (b−a)×(c−a)"
      (fun () ->
        let u, w = Shape.uv tri (v 0.25 0.5 0.) in
        close "u" 0.25 u;
        close "v" 0.5 w;
        check_vec "n" Vec3.z_axis (Shape.normal tri (v 0.2 0.2 0.)));
    case "a parallelogram is hit inside and has (a, b) as its uv" (fun () ->
        let p =
          Shape.parallelogram ~origin:Vec3.zero ~edge1:(v 2. 0. 0.) ~edge2:(v 0. 1. 0.)
        in
        close "t" 1. (hit p (ray (v 1.9 0.9 (-1.)) Vec3.z_axis));
        let a, b = Shape.uv p (v 1.9 0.9 0.) in
        close "a" 0.95 a;
        close "b" 0.9 b;
        miss "outside" (hit p (ray (v 2.1 0.5 (-1.)) Vec3.z_axis));
        miss "parallel" (hit p (ray (v (-1.) 0.5 0.) Vec3.x_axis)));
    case "a disk is hit within its radius and missed beyond or when parallel" (fun () ->
        let d = Shape.disk ~center:Vec3.zero ~normal:Vec3.y_axis ~radius:1. in
        close "t" 1. (hit d (ray (v 0.5 1. 0.) (v 0. (-1.) 0.)));
        miss "beyond" (hit d (ray (v 1.5 1. 0.) (v 0. (-1.) 0.)));
        miss "parallel" (hit d (ray Vec3.zero Vec3.x_axis));
        let u, w = Shape.uv d Vec3.zero in
        close "u centre" 0.5 u;
        close "v centre" 0.5 w);
  ]

(* ---- quadrics with a height range, and the box ---- *)

let cup = Shape.paraboloid ~vertex:Vec3.zero ~axis:Vec3.y_axis ~radius:1. ~height:1.

let can ?(caps = true) () =
  Shape.cylinder ~base:Vec3.zero ~top:(v 0. 2. 0.) ~radius:1. ~caps

let cube = Shape.box ~min:(v (-1.) (-1.) (-1.)) ~max:Vec3.one

let quadric_tests =
  [
    case "a ray nearly parallel to a paraboloid's axis (a = 1e-18) hits at 9.4999999905"
      (fun () ->
        rel "t" ~tol:1e-10 9.4999999905 (hit cup (raw (v 0.5 9.75 0.) (v 1e-9 (-1.) 0.))));
    case "a ray parallel to a paraboloid's axis (a = 0) is solved linearly" (fun () ->
        close "t" 4.75 (hit cup (ray (v 0.5 5. 0.) (v 0. (-1.) 0.))));
    case "a paraboloid is open: a ray down the axis reaches the vertex" (fun () ->
        close "t" 2. (hit cup (ray (v 0. 2. 0.) (v 0. (-1.) 0.)));
        check_vec "normal at the vertex" (v 0. (-1.) 0.) (Shape.normal cup Vec3.zero));
    case "a paraboloid is two-sided: hit from inside the cup and from outside" (fun () ->
        close "inside" (Float.sqrt 0.5) (hit cup (ray (v 0. 0.5 0.) Vec3.x_axis));
        close "outside" 4.5 (hit cup (ray (v (-5.) 0.25 0.) Vec3.x_axis)));
    case "a paraboloid ends at its height" (fun () ->
        miss "above the rim" (hit cup (ray (v (-5.) 1.5 0.) Vec3.x_axis)));
    case "a cylinder's side, caps and inside are hit where expected" (fun () ->
        close "side" 4. (hit (can ()) (ray (v (-5.) 1. 0.) Vec3.x_axis));
        close "top cap" 3. (hit (can ()) (ray (v 0. 5. 0.) (v 0. (-1.) 0.)));
        close "base cap" 1. (hit (can ()) (ray (v 0.5 (-1.) 0.) Vec3.y_axis));
        close "from inside" 1. (hit (can ()) (ray (v 0. 1. 0.) Vec3.x_axis));
        check_vec "cap normal" (v 0. (-1.) 0.) (Shape.normal (can ()) (v 0.5 0. 0.));
        check_vec "side normal" (v (-1.) 0. 0.) (Shape.normal (can ()) (v (-1.) 1. 0.)));
    case "an open cylinder lets a ray along its axis through" (fun () ->
        miss "open" (hit (can ~caps:false ()) (ray (v 0. 5. 0.) (v 0. (-1.) 0.))));
    case "a cylinder is missed above its top and beside it" (fun () ->
        miss "above" (hit (can ()) (ray (v (-5.) 2.5 0.) Vec3.x_axis));
        miss "beside" (hit (can ()) (ray (v (-5.) 1. 1.5) Vec3.x_axis)));
    case "a box is hit on its near face from outside and on its far face from inside"
      (fun () ->
        close "outside" 4. (hit cube (ray (v 0. 0. (-5.)) Vec3.z_axis));
        check_vec "normal" (v 0. 0. (-1.)) (Shape.normal cube (v 0.2 0.3 (-1.)));
        close "inside" 1. (hit cube (ray Vec3.zero Vec3.z_axis)));
    case "a ray along a box's face plane returns a number or a miss, never NaN" (fun () ->
        let t = hit cube (ray (v (-5.) 1. 0.) Vec3.x_axis) in
        Alcotest.(check bool) "not NaN" false (Float.is_nan t);
        miss "parallel outside" (hit cube (ray (v (-5.) 2. 0.) Vec3.x_axis)));
    case "uv stays in [0, 1] on every bounded primitive" (fun () ->
        let shapes_points =
          [
            (cup, v 0.5 0.25 0.);
            (can (), v 1. 1. 0.);
            (can (), v 0.3 2. 0.1);
            (cube, v 1. 0.3 (-0.2));
            (Shape.sphere ~center:Vec3.zero ~radius:1., v 0. 1. 0.);
          ]
        in
        List.iter
          (fun (s, p) ->
            let u, w = Shape.uv s p in
            if not (u >= 0. && u <= 1. && w >= 0. && w <= 1.) then
              Alcotest.failf "%s: uv (%g, %g)" (Shape.name s) u w)
          shapes_points);
    case "bounds enclose every primitive" (fun () ->
        let b = Option.get (Shape.bbox (can ())) in
        check_vec "min" (v (-1.) 0. (-1.)) b.min;
        check_vec "max" (v 1. 2. 1.) b.max;
        let b = Option.get (Shape.bbox cup) in
        check_vec "cup min" (v (-1.) 0. (-1.)) b.min;
        Alcotest.(check bool)
          "plane unbounded" true
          (Shape.bbox (Shape.plane ~normal:Vec3.y_axis ~offset:0.) = None));
  ]

(* ---- random directions and points ---- *)

let rand_dir st =
  let rec go () =
    let d =
      v
        (Random.State.float st 2. -. 1.)
        (Random.State.float st 2. -. 1.)
        (Random.State.float st 2. -. 1.)
    in
    let l = Vec3.length d in
    if l < 0.1 || l > 1. then go () else Vec3.smul (1. /. l) d
  in
  go ()

let rand_in st lo hi = lo +. Random.State.float st (hi -. lo)
let rand_point st lo hi = v (rand_in st lo hi) (rand_in st lo hi) (rand_in st lo hi)

(* A ray that leaves a convex shape outward, started off the surface by the renderer's
   scale-aware offset, never comes back to it. *)
let convex_prop =
  let shapes =
    [|
      Shape.sphere ~center:(v 0.3 (-0.2) 0.1) ~radius:1.3;
      cube;
      can ();
      Shape.box ~min:(v 1e3 1e3 1e3) ~max:(v 1001. 1002. 1003.);
      Shape.sphere ~center:(v 1e4 0. 0.) ~radius:1e-2;
    |]
  in
  QCheck.Test.make ~name:"a ray leaving a convex shape outward never re-hits it"
    ~count:3000
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let s = shapes.(seed mod Array.length shapes) in
      let b = Option.get (Shape.bbox s) in
      let c = Bbox.centroid b in
      let size = Vec3.max_abs (Vec3.sub b.max b.min) in
      let inside =
        Vec3.madd c (0.2 *. size) (Vec3.smul (Random.State.float st 1.) (rand_dir st))
      in
      let r = ray inside (rand_dir st) in
      let t = hit s r in
      if t = inf then QCheck.assume_fail ()
      else
        let p = Ray.at r t in
        let n = Shape.normal s p in
        let d = rand_dir st in
        let d = if Vec3.dot d n < 0. then Vec3.neg d else d in
        QCheck.assume (Vec3.dot d n > 1e-6);
        let o = Vec3.madd p (Shade.offset p p) n in
        hit s (ray o d) = inf)

(* ---- OBJ meshes ---- *)

(* A latitude–longitude sphere as OBJ text: poles shared by fans, quads in between. *)
let sphere_obj ?(nlat = 12) ?(nlon = 16) () =
  let b = Buffer.create 4096 in
  Buffer.add_string b "# generated sphere\nv 0 1 0\n";
  for i = 1 to nlat - 1 do
    let th = Float.pi *. Float.of_int i /. Float.of_int nlat in
    for j = 0 to nlon - 1 do
      let ph = 2. *. Float.pi *. Float.of_int j /. Float.of_int nlon in
      Printf.bprintf b "v %.17g %.17g %.17g\n"
        (Float.sin th *. Float.cos ph)
        (Float.cos th)
        (Float.sin th *. Float.sin ph)
    done
  done;
  Buffer.add_string b "v 0 -1 0\n";
  let ring i j = 2 + ((i - 1) * nlon) + (j mod nlon) in
  let south = 2 + ((nlat - 1) * nlon) in
  for j = 0 to nlon - 1 do
    Printf.bprintf b "f 1 %d %d\n" (ring 1 (j + 1)) (ring 1 j)
  done;
  for i = 1 to nlat - 2 do
    for j = 0 to nlon - 1 do
      Printf.bprintf b "f %d %d %d %d\n" (ring i j)
        (ring i (j + 1))
        (ring (i + 1) (j + 1))
        (ring (i + 1) j)
    done
  done;
  for j = 0 to nlon - 1 do
    Printf.bprintf b "f %d %d %d\n" south (ring (nlat - 1) j) (ring (nlat - 1) (j + 1))
  done;
  Buffer.contents b

let parse_ok ?smooth text =
  match Obj_file.parse ?smooth ~file:"t.obj" text with
  | Ok l -> l
  | Error e -> Alcotest.failf "unexpected error: %s" e

let parse_err text expected_prefix =
  match Obj_file.parse ~file:"t.obj" text with
  | Ok _ -> Alcotest.failf "expected an error starting %S" expected_prefix
  | Error e ->
      let n = String.length expected_prefix in
      if String.length e < n || String.sub e 0 n <> expected_prefix then
        Alcotest.failf "error %S does not start with %S" e expected_prefix

let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"

let mesh_tests =
  [
    case "a quad is fan-triangulated into two triangles" (fun () ->
        Alcotest.(check int) "count" 2 (List.length (parse_ok (quad ^ "f 1 2 3 4\n"))));
    case "negative indices count back from the last vertex" (fun () ->
        match parse_ok (quad ^ "f -4 -3 -2\n") with
        | [ Shape.Triangle { a; b; c; _ } ] ->
            check_vec "a" Vec3.zero a;
            check_vec "b" Vec3.x_axis b;
            check_vec "c" (v 1. 1. 0.) c
        | _ -> Alcotest.fail "one triangle expected");
    case "a/b, a/b/c and a//c corners read texture coordinates and normals" (fun () ->
        let text =
          quad
          ^ "vt 0 0\n\
             vt 1 0\n\
             vt 1 1\n\
             vn 0 0 1\n\
             vn 1 0 1\n\
             vn 0 1 1\n\
             f 1/1/1 2/2/2 3/3/3\n\
             f 1//1 3//3 4//1\n\
             f 1/1 3/3 4/2\n"
        in
        match parse_ok text with
        | [ t1; t2; t3 ] ->
            let u, w = Shape.uv t1 (v 1. 0.5 0.) in
            close "u" 1. u;
            close "v" 0.5 w;
            check_vec "smooth normal at a corner"
              (Vec3.normalize (v 1. 0. 1.))
              (Shape.normal t1 Vec3.x_axis);
            Alcotest.(check string) "kind" "mesh" (Shape.name t2);
            check_vec "flat without normals" (v 0. 0. 1.) (Shape.normal t3 (v 0.5 0.7 0.))
        | l -> Alcotest.failf "3 triangles expected, got %d" (List.length l));
    case "faces without normals or (u, v) before and after one with them" (fun () ->
        let text =
          quad ^ "vt 0.25 0.5\nvn 1 0 1\nf 1 2 3\nf 1 2 3\nf 1/1/1 2/1/1 3/1/1\nf 1 3 4\n"
        in
        match parse_ok text with
        | [ t1; t2; t3; t4 ] ->
            let p = v 0.9 0.1 0. in
            check_vec "first: flat" Vec3.z_axis (Shape.normal t1 p);
            check_vec "second: flat" Vec3.z_axis (Shape.normal t2 p);
            check_vec "third: its normals"
              (Vec3.normalize (v 1. 0. 1.))
              (Shape.normal t3 p);
            let u, w = Shape.uv t3 p in
            close "its u" 0.25 u;
            close "its v" 0.5 w;
            check_vec "fourth: flat" Vec3.z_axis (Shape.normal t4 (v 0.1 0.9 0.));
            let u, w = Shape.uv t1 p and u', w' = Shape.uv t4 (v 0.1 0.9 0.) in
            Alcotest.(check bool)
              "the others: no (u, v) of the file" true
              ((u, w) <> (0.25, 0.5) && (u', w') <> (0.25, 0.5))
        | l -> Alcotest.failf "4 triangles expected, got %d" (List.length l));
    case "smooth:false keeps the flat normal" (fun () ->
        match parse_ok ~smooth:false (quad ^ "vn 1 0 1\nf 1//1 2//1 3//1\n") with
        | [ t ] -> check_vec "flat" Vec3.z_axis (Shape.normal t (v 0.9 0.1 0.))
        | _ -> Alcotest.fail "one triangle expected");
    case "comments, groups and materials are ignored" (fun () ->
        Alcotest.(check int)
          "count" 1
          (List.length
             (parse_ok
                ("# hi\nmtllib m.mtl\no obj\ng grp\nusemtl red\ns off\n" ^ quad
               ^ "f 1 2 3 # tail\n"))));
    case "an index past the vertices read so far is an error with file and line"
      (fun () -> parse_err (quad ^ "f 1 2 5\n") "t.obj:5:");
    case "index 0 is an error" (fun () -> parse_err (quad ^ "f 0 1 2\n") "t.obj:5:");
    case "a face before any vertex is an error" (fun () ->
        parse_err "f 1 2 3\n" "t.obj:1:");
    case "a vertex with two coordinates is an error" (fun () ->
        parse_err "v 1 2\n" "t.obj:1:");
    case "a non-numeric coordinate is an error" (fun () ->
        parse_err "v 1 x 2\n" "t.obj:1:");
    case "a face with two corners is an error" (fun () ->
        parse_err (quad ^ "f 1 2\n") "t.obj:5:");
    case "a malformed corner is an error" (fun () ->
        parse_err (quad ^ "f 1/2/3/4 2 3\n") "t.obj:5:");
    case "a texture index out of range is an error" (fun () ->
        parse_err (quad ^ "f 1/1 2/1 3/1\n") "t.obj:5:");
    case "garbage is an error, not an exception" (fun () ->
        parse_err "hello world\n" "t.obj:1:";
        parse_err "\000\001\002binary" "t.obj:1:");
    case "a file without faces is an error" (fun () -> parse_err quad "t.obj:");
    case "a missing file is an error" (fun () ->
        match Obj_file.load "/nonexistent/x.obj" with
        | Ok _ -> Alcotest.fail "expected an error"
        | Error _ -> ());
    case "a mesh file on disk loads" (fun () ->
        let path = Filename.temp_file "lancer" ".obj" in
        Out_channel.with_open_bin path (fun oc -> output_string oc (sphere_obj ()));
        let r = Obj_file.load path in
        Sys.remove path;
        match r with
        | Ok l -> Alcotest.(check int) "triangles" (2 * 16 * 11) (List.length l)
        | Error e -> Alcotest.fail e);
  ]

(* Coordinates in every decimal form an exporter writes (signs, leading zeros, long
   fractions, exponents, underscores) are read to the same double as float_of_string. *)
let obj_number_prop =
  let gen =
    QCheck.Gen.(
      let digits n = string_size ~gen:(char_range '0' '9') (int_bound n) in
      let* sign = oneofl [ ""; "-"; "+" ] in
      let* int_part = digits 18 in
      let* frac = opt (digits 22) in
      let* exp = opt (pair (oneofl [ "e"; "E"; "e-"; "e+" ]) (int_bound 30)) in
      let* under = bool in
      let int_part = if int_part = "" && frac = None then "0" else int_part in
      let int_part =
        if under && String.length int_part > 1 then
          String.sub int_part 0 1 ^ "_"
          ^ String.sub int_part 1 (String.length int_part - 1)
        else int_part
      in
      let s =
        sign ^ int_part
        ^ (match frac with Some f -> "." ^ f | None -> "")
        ^ match exp with Some (e, k) -> e ^ string_of_int k | None -> ""
      in
      return s)
  in
  QCheck.Test.make ~name:"OBJ coordinates read as float_of_string reads them" ~count:3000
    (QCheck.make ~print:Fun.id gen) (fun s ->
      match float_of_string_opt s with
      | None -> QCheck.assume_fail ()
      | Some x -> (
          match parse_ok (Printf.sprintf "v %s 2 0\nv 0 0 0\nv 0 0 1\nf 1 2 3\n" s) with
          | [ Shape.Triangle { a; _ } ] ->
              Int64.equal (Int64.bits_of_float a.x) (Int64.bits_of_float x)
          | _ -> false))

(* ---- watertightness ---- *)

let mesh_prims () =
  parse_ok ~smooth:false (sphere_obj ())
  |> List.map (Primitive.make Material.default)
  |> Array.of_list

let vertices_of prims =
  Array.to_list prims
  |> List.concat_map (fun (p : Primitive.t) ->
         match p.shape with
         | Shape.Triangle { a; b; c; _ } -> [ (a, b); (b, c); (c, a) ]
         | _ -> [])

(* Rays from points inside the closed mesh aimed exactly at its vertices, and at points
   of its edges: every one must hit, through the hierarchy and through a plain scan. *)
let watertight_mesh =
  let prims = mesh_prims () in
  let accel = Accel.build prims in
  let edges = Array.of_list (vertices_of prims) in
  QCheck.Test.make ~name:"no ray escapes a closed OBJ sphere through a vertex or an edge"
    ~count:5000
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let a, b = edges.(Random.State.int st (Array.length edges)) in
      let target =
        match seed mod 3 with
        | 0 -> a
        | 1 -> Vec3.smul 0.5 (Vec3.add a b)
        | _ -> Vec3.madd a (Random.State.float st 1.) (Vec3.sub b a)
      in
      let origin =
        if seed mod 5 = 0 then Vec3.zero
        else Vec3.smul 0.5 (Vec3.smul (Random.State.float st 1.) (rand_dir st))
      in
      let r = Ray.make_raw origin (Vec3.sub target origin) in
      let _, i = Queries.nearest accel r 0. inf in
      let scan = Array.exists (fun p -> Queries.intersect p r 0. inf < inf) prims in
      i >= 0 && scan)

(* Tilted tiles with edges that are not representable exactly, so that shared edges are
   computed with rounding: exact [0, 1] bounds leak there. *)
let tile_o = v 0.1 (-0.3) 0.7
and tile_e1 = v 0.3 0.1 (-0.2)
and tile_e2 = v (-0.1) 0.7 0.3

let tile_point a b = Vec3.madd (Vec3.madd tile_o a tile_e1) b tile_e2

let tiles =
  Array.of_list
    (List.concat_map
       (fun i ->
         List.map
           (fun j ->
             Primitive.make Material.default
               (Shape.parallelogram
                  ~origin:(tile_point (Float.of_int i) (Float.of_int j))
                  ~edge1:tile_e1 ~edge2:tile_e2))
           [ 0; 1 ])
       [ 0; 1 ])

let watertight_tiles =
  let accel = Accel.build tiles in
  let n = Vec3.normalize (Vec3.cross tile_e1 tile_e2) in
  QCheck.Test.make
    ~name:
      "no ray passes between 2×2 tiled parallelograms at their shared edges and vertex"
    ~count:5000
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let target =
        match seed mod 3 with
        | 0 -> tile_point 1. (Random.State.float st 2.)
        | 1 -> tile_point (Random.State.float st 2.) 1.
        | _ -> tile_point 1. 1.
      in
      let side = if Random.State.bool st then 1. else -1. in
      let origin =
        Vec3.madd
          (Vec3.add (tile_point 1. 1.) (rand_point st (-2.) 2.))
          (side *. rand_in st 0.1 3.)
          n
      in
      let r = Ray.make_raw origin (Vec3.sub target origin) in
      QCheck.assume (Float.abs (Vec3.dot (Vec3.normalize (Ray.dir r)) n) > 1e-3);
      let _, i = Queries.nearest accel r 0. inf in
      i >= 0)

(* ---- indexed meshes ---- *)

let mesh_ok ?smooth text =
  match Obj_file.parse_mesh ?smooth ~file:"t.obj" text with
  | Ok m -> m
  | Error e -> Alcotest.failf "unexpected error: %s" e

(* A wavy grid of quads (shared edges and vertices, rays through them tie), every face
   given twice in places (exact ties between faces), some faces with normals and (u, v). *)
let wavy_obj st =
  let n = 3 + Random.State.int st 12 in
  let b = Buffer.create 4096 in
  for j = 0 to n do
    for i = 0 to n do
      Printf.bprintf b "v %d %.17g %d\n" i (rand_in st (-0.5) 0.5) j
    done
  done;
  Buffer.add_string b "vn 0 1 0\nvn 0.2 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n";
  let id i j = (j * (n + 1)) + i + 1 in
  for j = 0 to n - 1 do
    for i = 0 to n - 1 do
      let a = id i j
      and bb = id (i + 1) j
      and c = id (i + 1) (j + 1)
      and d = id i (j + 1) in
      (match Random.State.int st 3 with
      | 0 -> Printf.bprintf b "f %d %d %d %d\n" a bb c d
      | 1 -> Printf.bprintf b "f %d/1/1 %d/2/2 %d/3/1\nf %d %d %d\n" a bb c a c d
      | _ -> Printf.bprintf b "f %d %d %d\nf %d/3 %d/2 %d/1\n" a bb d bb c d);
      if Random.State.int st 8 = 0 then Printf.bprintf b "f %d %d %d\n" a bb c
    done
  done;
  (n, Buffer.contents b)

let same_face (x : Shape.t) (y : Shape.t) =
  match (x, y) with
  | Shape.Triangle a, Shape.Triangle b ->
      a.a = b.a && a.b = b.b && a.c = b.c && a.tn = b.tn && a.normals = b.normals
      && a.uvs = b.uvs
  | _ -> false

let mesh_nearest_prop =
  QCheck.Test.make
    ~name:
      "an indexed mesh's three queries are a scan of its faces': the nearest hit and its \
       face (ties to the lower), any crossing, every crossing once a t"
    ~count:40
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let n, text = wavy_obj st in
      let m = mesh_ok text in
      let faces = Array.of_list (Shape.faces m) in
      let shape = Shape.mesh m in
      let prim = Primitive.make Material.default shape in
      let accel = Accel.build [| prim |] in
      let ok = ref true in
      let fail fmt =
        ok := false;
        QCheck.Test.fail_reportf fmt
      in
      for _ = 1 to 300 do
        let o = v (rand_in st (-1.) (Float.of_int n +. 1.)) 3. (rand_in st (-1.) 5.) in
        (* At a vertex, along an edge, or anywhere over the grid. *)
        let target =
          match Random.State.int st 3 with
          | 0 ->
              v
                (Float.of_int (Random.State.int st (n + 1)))
                0.
                (Float.of_int (Random.State.int st (n + 1)))
          | 1 -> v (Float.of_int (Random.State.int st (n + 1))) 0. (rand_in st 0. 1.)
          | _ -> v (rand_in st 0. (Float.of_int n)) 0. (rand_in st 0. (Float.of_int n))
        in
        let target =
          (* Onto the surface's height there: aim at a vertex of the file. *)
          if Random.State.bool st then target else Vec3.add target (v 0. (-0.1) 0.)
        in
        let r = ray o (Vec3.sub target o) in
        let tmax = if Random.State.bool st then inf else rand_in st 1. 6. in
        (* Every face's roots, in order of (t, face). *)
        let roots =
          List.sort compare
            (List.filter_map
               (fun k ->
                 let t = Shape.intersect faces.(k) r 0. tmax in
                 if t < tmax then Some (t, k) else None)
               (List.init (Array.length faces) Fun.id))
        in
        let best_t, best = match roots with (t, k) :: _ -> (t, k) | [] -> (inf, -1) in
        let t = Walk.intersect shape r 0. tmax in
        if not (same_bits t best_t) then fail "mesh t %.17g vs scan %.17g" t best_t;
        let t, i, leaf, face = Queries.hit accel r 0. tmax in
        if not (same_bits t best_t) then fail "query t %.17g vs scan %.17g" t best_t;
        if best >= 0 && (i <> 0 || leaf <> -1 || face <> best) then
          fail "the face hit at %.17g is %d, the scan's %d" t face best;
        let s, _ = Queries.surface prim r 0. tmax in
        if best >= 0 && not (same_face s.shape faces.(best)) then
          fail "the surface at %.17g is not face %d" t best;
        if Queries.any accel r 0. tmax ~opaque:false <> (best >= 0) then
          fail "any crossing %b, scan %b" (not (best >= 0)) (best >= 0);
        (* Each t once, with the lowest face crossed there. *)
        let rec distinct = function
          | (t, k) :: ((t', _) :: _ as rest) when t = t' ->
              distinct ((t, k) :: List.tl rest)
          | x :: rest -> x :: distinct rest
          | [] -> []
        in
        let want = distinct roots
        and got =
          List.map
            (fun (t, _, _, face) -> (t, face))
            (Queries.crossings accel r 0. tmax ~transparent:false)
        in
        if got <> want then
          fail "%d crossings, the scan's %d distinct" (List.length got) (List.length want)
      done;
      !ok)

let indexed_tests =
  [
    case "an OBJ mesh is one object, its faces shared arrays" (fun () ->
        let m = mesh_ok (sphere_obj ()) in
        Alcotest.(check int) "faces" (2 * 16 * 11) (Trimesh.count m);
        let p = Primitive.make Material.default (Shape.mesh m) in
        Alcotest.(check int) "faces of the object" (2 * 16 * 11) (Primitive.faces p);
        Alcotest.(check bool) "shades through its faces" true (Primitive.is_composite p);
        (* Nothing per face beyond three 32-bit indices and its place in the tree: well
           under the 30-odd words a record per face took. *)
        let words = Obj.reachable_words (Obj.repr m) in
        if words > 16 * Trimesh.count m then
          Alcotest.failf "%d words for %d faces" words (Trimesh.count m));
    case "a mesh's faces are the triangles the list parse gives" (fun () ->
        let text =
          quad
          ^ "vt 0 0\nvt 1 0\nvn 0 0 1\nvn 1 0 1\nf 1/1/1 2/2/2 3/1/2 4/2/1\nf 1 3 4\n"
        in
        let a = Shape.faces (mesh_ok text) and b = parse_ok text in
        Alcotest.(check int) "count" (List.length b) (List.length a);
        List.iter2 (fun x y -> Alcotest.(check bool) "same face" true (same_face x y)) a b);
    case "a mesh's kinds count its faces" (fun () ->
        (* Faceted, so that only the face with (u, v) is more than a triangle. *)
        let m = mesh_ok ~smooth:false (quad ^ "vt 0 0\nf 1 2 3\nf 1/1 3/1 4/1\n") in
        Alcotest.(check (list string))
          "names" [ "triangle"; "mesh" ]
          (List.map Shape.name (Shape.faces m)));
    case "an untransformed sphere's object keeps no box of its own" (fun () ->
        let s i = Shape.sphere ~center:(v (Float.of_int i) 0. 0.) ~radius:0.4 in
        let prims = Array.init 1000 (fun i -> Primitive.make Material.default (s i)) in
        (* The array slot, the record (8), the shape (3) and its centre (4); a box per
           sphere would add 13. *)
        let per = Obj.reachable_words (Obj.repr prims) / 1000 in
        if per > 18 then Alcotest.failf "%d words per sphere" per;
        let b = Option.get (Primitive.bounds prims.(3)) in
        check_vec "min" (v 2.6 (-0.4) (-0.4)) b.min;
        check_vec "max" (v 3.4 0.4 0.4) b.max;
        let moved =
          Primitive.make
            ~transform:(Transform.translate (v 0. 1. 0.))
            Material.default (s 0)
        in
        let b = Option.get (Primitive.bounds moved) in
        check_vec "moved min" (v (-0.4) 0.6 (-0.4)) b.min);
    case "a scene of one mesh still builds a tree when it has eight faces or more"
      (fun () ->
        let m = mesh_ok (sphere_obj ()) in
        let a = Accel.build [| Primitive.make Material.default (Shape.mesh m) |] in
        Alcotest.(check bool) "bvh" true (Accel.uses_bvh a);
        let t, i = Queries.nearest a (ray (v 0. 0. (-5.)) Vec3.z_axis) 0. inf in
        Alcotest.(check int) "index" 0 i;
        if not (t > 3.9 && t < 4.1) then Alcotest.failf "t = %.17g" t);
  ]

(* ---- the hierarchy against brute force ---- *)

let brute_nearest prims r tmin tmax =
  let best_t = ref tmax and best_i = ref (-1) in
  Array.iteri
    (fun i p ->
      let t = Queries.intersect p r tmin !best_t in
      if t < !best_t then (
        best_t := t;
        best_i := i))
    prims;
  if !best_i < 0 then (inf, -1) else (!best_t, !best_i)

let brute_crossings prims r tmin tmax =
  let acc = ref [] in
  Array.iteri
    (fun i p ->
      let t = ref (Queries.intersect p r tmin tmax) in
      while !t < tmax do
        acc := (i, !t) :: !acc;
        t := Queries.intersect p r !t tmax
      done)
    prims;
  List.sort compare !acc

let index_of prims (p : Primitive.t) =
  let r = ref (-1) in
  Array.iteri (fun i q -> if !r < 0 && q == p then r := i) prims;
  !r

(* A random soup of spheres, triangles, boxes, cylinders and disks, some transformed,
   some duplicated (ties), sometimes with a plane. *)
let soup st =
  let n = 8 + Random.State.int st 150 in
  let m = Material.default in
  let one () =
    let c = rand_point st (-10.) 10. in
    let s =
      match Random.State.int st 5 with
      | 0 -> Shape.sphere ~center:c ~radius:(rand_in st 0.1 2.)
      | 1 ->
          Shape.triangle ~a:c
            ~b:(Vec3.add c (rand_point st (-2.) 2.))
            ~c:(Vec3.add c (rand_point st (-2.) 2.))
      | 2 -> Shape.box ~min:c ~max:(Vec3.add c (rand_point st 0.1 3.))
      | 3 ->
          Shape.cylinder ~base:c
            ~top:(Vec3.add c (rand_point st (-2.) 2.))
            ~radius:(rand_in st 0.1 1.) ~caps:true
      | _ -> Shape.disk ~center:c ~normal:(rand_dir st) ~radius:(rand_in st 0.1 2.)
    in
    let transform =
      if Random.State.int st 4 = 0 then
        Transform.then_
          (Transform.rotate (rand_point st 0. 90.))
          (Transform.scale (rand_point st 0.5 2.))
      else Transform.identity
    in
    Primitive.make ~transform m s
  in
  let l = List.init n (fun _ -> one ()) in
  let l =
    if Random.State.bool st then
      Primitive.make m (Shape.plane ~normal:(rand_dir st) ~offset:(rand_in st (-5.) 5.))
      :: l
    else l
  in
  let l = match l with a :: b :: rest -> (a :: b :: rest) @ [ a; b ] | l -> l in
  Array.of_list l

let rand_ray st =
  let o = rand_point st (-15.) 15. in
  let d =
    match Random.State.int st 4 with
    | 0 ->
        [| Vec3.x_axis; Vec3.y_axis; Vec3.z_axis; v 0. (-1.) 0. |].(Random.State.int st 4)
    | _ -> rand_dir st
  in
  ray o d

let bvh_nearest_prop =
  QCheck.Test.make ~name:"the BVH's nearest hit is the brute-force scan's, ties included"
    ~count:60
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let prims = soup st in
      let accel = Accel.build prims in
      if not (Accel.uses_bvh accel) then QCheck.Test.fail_report "no BVH built";
      let ok = ref true in
      for _ = 1 to 300 do
        let r = rand_ray st in
        let tmax = if Random.State.int st 4 = 0 then rand_in st 1. 30. else inf in
        let t1, i1 = Queries.nearest accel r 0. tmax
        and t2, i2 = brute_nearest prims r 0. tmax in
        if not (i1 = i2 && Int64.equal (Int64.bits_of_float t1) (Int64.bits_of_float t2))
        then (
          ok := false;
          QCheck.Test.fail_reportf "BVH (%.17g, %d) vs scan (%.17g, %d)" t1 i1 t2 i2)
      done;
      !ok)

let bvh_crossings_prop =
  QCheck.Test.make
    ~name:
      "the crossings query gives every crossing once, in order, as the brute-force scan"
    ~count:40
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let prims = soup st in
      let accel = Accel.build prims in
      let ok = ref true in
      for _ = 1 to 200 do
        let r = rand_ray st in
        let got = Queries.crossings accel r 0. 40. ~transparent:false in
        let ts = List.map (fun (t, _, _, _) -> t) got in
        if ts <> List.sort Float.compare ts then ok := false;
        (* Duplicated primitives are physically the same object twice: compare by index
           of first occurrence on both sides. *)
        let norm l =
          List.sort compare (List.map (fun (i, t) -> (index_of prims prims.(i), t)) l)
        in
        let seen = List.map (fun (t, i, _, _) -> (i, t)) got in
        if norm seen <> norm (brute_crossings prims r 0. 40.) then ok := false
      done;
      !ok)

(* ---- the shadow query ---- *)

(* A soup of every shape the occlusion query tests in scalars (and, with [quadrics], the
   one that builds a ray), some transformed, some transparent. *)
let shadow_soup ?(quadrics = true) st =
  let n = 1 + Random.State.int st 60 in
  let one () =
    let c = rand_point st (-10.) 10. in
    let e () = rand_point st (-2.) 2. in
    let s =
      match Random.State.int st (if quadrics then 8 else 7) with
      | 0 -> Shape.sphere ~center:c ~radius:(rand_in st 0.1 2.)
      | 1 -> Shape.triangle ~a:c ~b:(Vec3.add c (e ())) ~c:(Vec3.add c (e ()))
      | 2 -> Shape.box ~min:c ~max:(Vec3.add c (rand_point st 0.1 3.))
      | 3 -> Shape.disk ~center:c ~normal:(rand_dir st) ~radius:(rand_in st 0.1 2.)
      | 4 -> Shape.parallelogram ~origin:c ~edge1:(e ()) ~edge2:(e ())
      | 5 -> Shape.plane ~normal:(rand_dir st) ~offset:(rand_in st (-12.) 12.)
      | 6 ->
          Shape.paraboloid ~vertex:c ~axis:(rand_dir st) ~radius:(rand_in st 0.2 2.)
            ~height:(rand_in st 0.2 2.)
      | _ ->
          Shape.cylinder ~base:c
            ~top:(Vec3.add c (e ()))
            ~radius:(rand_in st 0.1 1.) ~caps:true
    in
    let transform =
      if Random.State.int st 3 = 0 then
        Transform.then_
          (Transform.then_
             (Transform.rotate (rand_point st 0. 90.))
             (Transform.scale (rand_point st 0.5 2.)))
          (Transform.translate (rand_point st (-3.) 3.))
      else Transform.identity
    in
    let m =
      if Random.State.int st 4 = 0 then { Material.default with transparency = 0.5 }
      else Material.default
    in
    Primitive.make ~transform m s
  in
  Array.init n (fun _ -> one ())

let brute_occluded prims r tmax =
  Array.exists
    (fun (p : Primitive.t) ->
      p.material.transparency = 0. && Queries.intersect p r 0. tmax < tmax)
    prims

let occluded_prop =
  QCheck.Test.make
    ~name:
      "the shadow query answers as a scan for an opaque crossing, whatever it tried first"
    ~count:60
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let prims = shadow_soup st in
      (* The same primitives through the tree and through the linear scan. *)
      let accels =
        [ Accel.build prims; Accel.build (Array.map Primitive.without_bounds prims) ]
      in
      let ok = ref true in
      for _ = 1 to 200 do
        let r = rand_ray st in
        let tmax = if Random.State.int st 4 = 0 then inf else rand_in st 0.5 30. in
        let expected = brute_occluded prims r tmax in
        List.iter
          (fun a ->
            let got =
              Queries.any a r 0. tmax ~opaque:true ~slot:(Random.State.int st 3)
            in
            if got <> expected then (
              ok := false;
              QCheck.Test.fail_reportf "occluded %b, scan %b" got expected))
          accels
      done;
      !ok)

let occluded_allocation =
  case "the shadow query allocates nothing" (fun () ->
      let st = Random.State.make [| 7 |] in
      let bounded =
        Array.concat (List.init 8 (fun _ -> shadow_soup ~quadrics:false st))
      in
      let bounded =
        List.filter
          (fun (p : Primitive.t) -> Option.is_some p.bounds)
          (Array.to_list bounded)
      in
      let floor =
        Primitive.make Material.default (Shape.plane ~normal:Vec3.y_axis ~offset:(-20.))
      in
      let prims = Array.of_list (floor :: bounded) in
      let n = 2000 in
      let rays = Array.init n (fun _ -> rand_ray st) in
      let data = Float.Array.make (6 * n) 0. in
      Array.iteri
        (fun k r ->
          let o = Ray.origin r and d = Ray.dir r in
          List.iteri
            (fun j x -> Float.Array.set data ((6 * k) + j) x)
            [ o.x; o.y; o.z; d.x; d.y; d.z ])
        rays;
      let q = Probe.create () and sc = Accel.domain_scratch () in
      List.iter
        (fun a ->
          let run () =
            let hits = ref 0 in
            for k = 0 to n - 1 do
              q.ox <- Float.Array.get data (6 * k);
              q.oy <- Float.Array.get data ((6 * k) + 1);
              q.oz <- Float.Array.get data ((6 * k) + 2);
              q.dx <- Float.Array.get data ((6 * k) + 3);
              q.dy <- Float.Array.get data ((6 * k) + 4);
              q.dz <- Float.Array.get data ((6 * k) + 5);
              q.p_tmin <- 0.;
              q.p_tmax <- 25.;
              if Accel.any sc a q ~opaque:true ~slot:(k land 1) ~mask:(-1) then incr hits
            done;
            !hits
          in
          ignore (run ());
          let w0 = Gc.minor_words () in
          let hits = run () in
          let words = Gc.minor_words () -. w0 in
          if hits = 0 || hits = n then
            Alcotest.failf "degenerate test: %d of %d rays blocked" hits n;
          if words > 64. then
            Alcotest.failf "%.0f minor words for %d shadow queries" words n)
        [ Accel.build prims; Accel.build (Array.map Primitive.without_bounds prims) ])

(* 24 shadow rays from [o] toward points at most [radius] from [c]: each answers the same
   under [mask] as with all objects, and as the nearest crossing of each object (a CSG
   object's from all its members' roots) says. *)
let rays_agree st sc a (q : Probe.t) prims o c radius mask =
  List.for_all
    (fun _ ->
      let off = Vec3.smul (rand_in st 0. radius) (rand_dir st) in
      let s = Vec3.add c off in
      let d = Vec3.sub s o in
      let dist = Vec3.length d in
      let d = Vec3.smul (1. /. dist) d in
      let ask mask =
        Probe.of_ray q (ray o d);
        q.p_tmin <- 0.;
        q.p_tmax <- dist;
        Accel.any sc a q ~opaque:true ~slot:(-1) ~mask
      in
      dist = 0.
      ||
      let masked = ask mask and all = ask (-1) in
      masked = all && all = brute_occluded prims (ray o d) dist)
    (List.init 24 Fun.id)

(* An area light's shadow rays from one point, with the objects Accel.shadow_mask allows
   and with all: the same answer for every ray toward a point within the light's radius,
   over a few objects (a scan, where the mask applies), CSG tubes among them. *)
let masked_culls = ref 0

let shadow_mask_prop =
  QCheck.Test.make
    ~name:
      "an area light's shadow rays answer the same under the mask, and as each object's \
       nearest crossing says"
    ~count:300
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let soup = shadow_soup st in
      let k = 1 + Random.State.int st (min 6 (Array.length soup)) in
      let tube () =
        let c = rand_point st (-8.) 8. and h = rand_in st 0.5 3. in
        let r = rand_in st 0.3 1.5 in
        let cyl top r =
          ( Shape.cylinder
              ~base:(Vec3.add c (v 0. (-0.1) 0.))
              ~top:(Vec3.add c (v 0. top 0.))
              ~radius:r ~caps:true,
            Transform.identity )
        in
        let turn () =
          Transform.then_
            (Transform.rotate (rand_point st 0. 90.))
            (Transform.translate (rand_point st (-0.3) 0.3))
        in
        let transform = if Random.State.bool st then turn () else Transform.identity in
        let shape =
          match Random.State.int st 3 with
          | 0 -> Shape.csg Difference [ cyl h r; cyl (h +. 0.2) (0.8 *. r) ]
          | 1 ->
              (* a member turned within the object *)
              let inner, _ = cyl (h +. 0.2) (0.8 *. r) in
              Shape.csg Difference [ cyl h r; (inner, turn ()) ]
          | _ ->
              (* a ball cut by a half-space: a plane member *)
              Shape.csg Intersection
                [
                  (Shape.sphere ~center:c ~radius:r, Transform.identity);
                  ( Shape.plane ~normal:(rand_dir st)
                      ~offset:(Vec3.dot c Vec3.y_axis *. rand_in st (-1.) 1.),
                    Transform.identity );
                ]
        in
        Primitive.make ~transform Material.default shape
      in
      let prims =
        Array.append (Array.sub soup 0 k)
          (Array.init (Random.State.int st 3) (fun _ -> tube ()))
      in
      let a = Accel.build prims in
      let sc = Accel.domain_scratch () and q = Probe.create () in
      let o = rand_point st (-12.) 12. and c = rand_point st (-12.) 12. in
      let radius = rand_in st 0. 3. in
      q.ox <- o.x;
      q.oy <- o.y;
      q.oz <- o.z;
      let mask = Accel.shadow_mask a q c radius in
      if mask <> -1 && mask <> (1 lsl Array.length prims) - 1 then incr masked_culls;
      rays_agree st sc a q prims o c radius mask)

(* Shadow rays from a point of a CSG object's own surface, lifted off it as shading lifts
   a point: where its first member (a sphere, a box, a capped cylinder) lies wholly below
   a plane touching it there, and the light above, the mask leaves the object out
   (Walk.csg_clear). The answers are those without the mask, and those of each object's
   nearest crossing, over differences and intersections placed by no transform, a turn,
   and a stretch. *)
let own_culls = ref 0

let csg_surface_prop =
  QCheck.Test.make
    ~name:
      "shadow rays from a CSG object's own surface answer the same when the mask leaves \
       the object out"
    ~count:400
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let c = rand_point st (-3.) 3. and r = rand_in st 0.4 1.5 in
      let cyl top r =
        Shape.cylinder
          ~base:(Vec3.add c (v 0. (-0.1) 0.))
          ~top:(Vec3.add c (v 0. top 0.))
          ~radius:r ~caps:true
      in
      let box h = Shape.box ~min:(Vec3.sub c (v h h h)) ~max:(Vec3.add c (v h h h)) in
      let slab =
        Shape.box
          ~min:(Vec3.sub c (v (0.3 *. r) (2. *. r) (2. *. r)))
          ~max:(Vec3.add c (v (0.3 *. r) (2. *. r) (2. *. r)))
      in
      let ball k = Shape.sphere ~center:c ~radius:(k *. r) in
      let id = Transform.identity in
      let shape =
        match Random.State.int st 4 with
        | 0 ->
            Shape.csg Difference
              [ (cyl (2. *. r) r, id); (cyl (2.2 *. r) (0.8 *. r), id) ]
        | 1 -> Shape.csg Difference [ (ball 1., id); (slab, id) ]
        | 2 -> Shape.csg Difference [ (box r, id); (ball 1.2, id) ]
        | _ -> Shape.csg Intersection [ (box r, id); (ball 1.3, id) ]
      in
      let transform =
        match Random.State.int st 3 with
        | 0 -> id
        | 1 ->
            Transform.then_
              (Transform.rotate (rand_point st 0. 90.))
              (Transform.translate (rand_point st (-1.) 1.))
        | _ ->
            Transform.then_
              (Transform.scale
                 (v (rand_in st 0.5 2.) (rand_in st 0.5 2.) (rand_in st 0.5 2.)))
              (Transform.rotate (rand_point st 0. 90.))
      in
      let p = Primitive.make ~transform Material.default shape in
      let floor =
        Primitive.make Material.default (Shape.plane ~normal:Vec3.y_axis ~offset:(-8.))
      in
      let prims = [| p; floor |] in
      let a = Accel.build prims in
      let centre = Transform.point transform c in
      let from = Vec3.add centre (Vec3.smul 12. (rand_dir st)) in
      let d =
        Vec3.normalize (Vec3.sub (Vec3.add centre (rand_point st (-0.5) 0.5)) from)
      in
      let surf, t = Queries.surface p (ray from d) 0. inf in
      t = inf
      ||
      let pt = Vec3.add from (Vec3.smul t d) in
      let n = Primitive.normal surf (Primitive.to_object surf pt) in
      let n = if Vec3.dot n d > 0. then Vec3.neg n else n in
      let big (u : Vec3.t) =
        Float.max (Float.abs u.x) (Float.max (Float.abs u.y) (Float.abs u.z))
      in
      let o = Vec3.add pt (Vec3.smul (1e-9 *. Float.max (big pt) (big from)) n) in
      (* a light mostly above the surface there *)
      let lc =
        Vec3.add o
          (Vec3.smul (rand_in st 1. 10.)
             (Vec3.normalize (Vec3.add n (Vec3.smul 0.9 (rand_dir st)))))
      in
      let radius = rand_in st 0. 1.5 in
      let sc = Accel.domain_scratch () and q = Probe.create () in
      Probe.set_origin q o.x o.y o.z;
      let mask = Accel.shadow_mask a q lc radius in
      if mask <> -1 && mask land 1 = 0 then incr own_culls;
      rays_agree st sc a q prims o lc radius mask)

(* The tree against the scan over the same primitives (kept out of the tree), bit for
   bit: the nearest hit and its part, the transparent crossings in order; and the scalar
   normal the renderer shades with against the vector form. *)
let scalar_forms_prop =
  QCheck.Test.make
    ~name:
      "the tree's nearest hit and transparent crossings are the scan's, and normal_into \
       is normal, bit for bit"
    ~count:40
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let prims = shadow_soup st in
      let tree = Accel.build prims
      and scan = Accel.build (Array.map Primitive.without_bounds prims) in
      let f = Frag.create () in
      for _ = 1 to 150 do
        let r = rand_ray st in
        let tmax = if Random.State.int st 4 = 0 then inf else rand_in st 0.5 30. in
        let t, i, leaf, face = Queries.hit tree r 0. tmax
        and t', i', leaf', face' = Queries.hit scan r 0. tmax in
        if i <> i' || leaf <> leaf' || face <> face' || not (same_bits t t') then
          QCheck.Test.fail_reportf "tree (%d, %.17g), scan (%d, %.17g)" i t i' t';
        if i >= 0 then (
          let o = prims.(i) in
          let p = Ray.at r t in
          let n = Primitive.normal o (Primitive.to_object o p) in
          Frag.set_point f p.x p.y p.z;
          Primitive.normal_into o f;
          if not (same_bits n.x f.nx && same_bits n.y f.ny && same_bits n.z f.nz) then
            QCheck.Test.fail_reportf
              "normal (%.17g, %.17g, %.17g), scalars (%.17g, %.17g, %.17g)" n.x n.y n.z
              f.nx f.ny f.nz);
        let a = Queries.crossings tree r 0. tmax ~transparent:true
        and b = Queries.crossings scan r 0. tmax ~transparent:true in
        let same (t, i, l, f) (u, j, m, g) = i = j && l = m && f = g && same_bits t u in
        if not (List.length a = List.length b && List.for_all2 same a b) then
          QCheck.Test.fail_reportf "tree %d crossings, scan %d" (List.length a)
            (List.length b);
        List.iter
          (fun (_, i, _, _) ->
            if prims.(i).Primitive.material.transparency = 0. then
              QCheck.Test.fail_report "an opaque crossing among the transparent ones")
          a
      done;
      true)

(* ---- shapes placed by a translation ---- *)

(* A shape whose transform only moves it is compiled as the shape moved, untransformed
   (the fast path); what a user sees of it must not change: the same roots, normals,
   texture points and (u, v) as the object-space primitive's, to rounding. Rays are aimed
   at a point inside each shape (never grazing); the translation is one move or two
   composed, near the origin or 1e6 away. *)
let placed_prop =
  QCheck.Test.make
    ~name:
      "a shape placed by a translation is untransformed, with the object-space \
       primitive's roots, normals, texture points and (u, v)"
    ~count:60
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let far = if Random.State.bool st then 1e6 else 1. in
      let rv k = v (rand_in st (-.k) k) (rand_in st (-.k) k) (rand_in st (-.k) k) in
      let d1 = Vec3.smul far (rv 5.) and d2 = rv 3. in
      let tr =
        if Random.State.bool st then Transform.translate d1
        else Transform.then_ (Transform.translate d1) (Transform.translate d2)
      in
      let c = rv 2. in
      (* The shape, in object space, and a point inside it to aim at. *)
      let shape, inside =
        match Random.State.int st 5 with
        | 0 -> (Shape.sphere ~center:c ~radius:(rand_in st 0.3 2.), c)
        | 1 ->
            ( Shape.box ~min:c ~max:(Vec3.add c (v 1. 0.7 1.3)),
              Vec3.add c (v 0.5 0.35 0.65) )
        | 2 ->
            let a = c
            and b = Vec3.add c (v 1.2 0.1 0.)
            and c' = Vec3.add c (v 0.2 1. 0.3) in
            (Shape.triangle ~a ~b ~c:c', Vec3.smul (1. /. 3.) (Vec3.add a (Vec3.add b c')))
        | 3 ->
            ( Shape.torus ~center:c ~axis:(v 0. 1. 0.) ~major:1. ~minor:0.3,
              Vec3.add c (v 1. 0. 0.) )
        | _ ->
            (Shape.plane ~normal:(Vec3.normalize (rv 1.)) ~offset:(rand_in st (-1.) 1.), c)
      in
      let m =
        {
          Material.default with
          texture =
            Some (Description.Checker { c1 = Color.white; c2 = Color.black; size = 0.3 });
        }
      in
      let o = Primitive.make ~transform:tr m shape in
      let b = Primitive.baked o in
      if not (Transform.is_identity b.transform) then
        QCheck.Test.fail_reportf "still transformed";
      let aim =
        match shape with
        | Shape.Plane _ -> Transform.point tr (rv 3.)
        | _ -> Transform.point tr inside
      in
      (* The arithmetic of either path rounds coordinates of the size of [far]: a
         millionth of a unit at 1e6, a billionth near the origin. *)
      let scale = far *. 10. and tol = if far > 1. then 1e-6 else 1e-9 in
      let near a b' = Float.abs (a -. b') <= tol *. Float.max 1. (Float.abs a) in
      let near_v (a : Vec3.t) (b' : Vec3.t) k =
        Float.abs (a.x -. b'.x) <= k
        && Float.abs (a.y -. b'.y) <= k
        && Float.abs (a.z -. b'.z) <= k
      in
      for _ = 1 to 20 do
        let origin =
          Vec3.add aim (Vec3.smul (rand_in st 4. 12.) (Vec3.normalize (rv 1.)))
        in
        let r = Ray.make origin (Vec3.sub aim origin) in
        let t = Queries.intersect o r 0. inf and t' = Queries.intersect b r 0. inf in
        if not ((t = inf && t' = inf) || near t t') then
          QCheck.Test.fail_reportf "root %.17g, baked %.17g" t t';
        if t < inf then (
          let p = Ray.at r t in
          let n = Primitive.normal o (Primitive.to_object o p)
          and n' = Primitive.normal b (Primitive.to_object b p) in
          if not (near_v n n' tol) then
            QCheck.Test.fail_reportf "normal (%g, %g, %g), baked (%g, %g, %g)" n.x n.y n.z
              n'.x n'.y n'.z;
          let tp = Primitive.texture_point o p and tp' = Primitive.texture_point b p in
          if not (near_v tp tp' (1e-12 *. scale)) then
            QCheck.Test.fail_reportf
              "texture point (%.17g, %.17g, %.17g), baked (%.17g, %.17g, %.17g)" tp.x tp.y
              tp.z tp'.x tp'.y tp'.z;
          let u, w = Primitive.uv o p and u', w' = Primitive.uv b p in
          let wrap a = Float.min (Float.abs a) (Float.abs (1. -. Float.abs a)) in
          if wrap (u -. u') > 1e3 *. tol || wrap (w -. w') > 1e3 *. tol then
            QCheck.Test.fail_reportf "uv (%.17g, %.17g), baked (%.17g, %.17g)" u w u' w')
      done;
      true)

(* An untextured shape that its transform turns, mirrors or scales alike on all axes is
   compiled as the shape it makes of it (a box only where nothing turns): the same roots
   and normals as the object-space primitive's. Rays are aimed near a point inside. *)
let similar_prop =
  QCheck.Test.make
    ~name:
      "an untextured shape turned, mirrored and scaled alike on every axis is that shape \
       in world space, with the object-space primitive's roots and normals"
    ~count:120
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let rv k = v (rand_in st (-.k) k) (rand_in st (-.k) k) (rand_in st (-.k) k) in
      let k = rand_in st 0.2 3. in
      let mirror = if Random.State.bool st then -1. else 1. in
      let kind = Random.State.int st 8 in
      let turn = if kind = 7 then Transform.identity else Transform.rotate (rv 180.) in
      let tr =
        Transform.then_
          (Transform.then_ turn (Transform.scale (v (mirror *. k) k k)))
          (Transform.translate (rv 5.))
      in
      let c = rv 1. and axis = Vec3.normalize (rv 1.) in
      let shape, inside =
        match kind with
        | 0 -> (Shape.sphere ~center:c ~radius:(rand_in st 0.3 2.), c)
        | 1 ->
            ( Shape.cylinder ~base:c ~top:(Vec3.madd c 1.5 axis) ~radius:0.4
                ~caps:(Random.State.bool st),
              Vec3.madd c 0.75 axis )
        | 2 ->
            ( Shape.cone ~base:c ~top:(Vec3.madd c 1.5 axis) ~base_radius:0.6
                ~top_radius:0.2 ~caps:(Random.State.bool st),
              Vec3.madd c 0.5 axis )
        | 3 -> (Shape.torus ~center:c ~axis ~major:1. ~minor:0.3, c)
        | 4 -> (Shape.disk ~center:c ~normal:axis ~radius:0.8, c)
        | 5 ->
            ( Shape.paraboloid ~vertex:c ~axis ~radius:0.8 ~height:1.2,
              Vec3.madd c 0.9 axis )
        | 6 -> (Shape.plane ~normal:axis ~offset:(rand_in st (-1.) 1.), c)
        | _ ->
            (Shape.box ~min:c ~max:(Vec3.add c (v 1. 0.6 1.4)), Vec3.add c (v 0.5 0.3 0.7))
      in
      let o = Primitive.make ~transform:tr Material.default shape in
      let b = Primitive.baked o in
      if not (Transform.is_identity b.transform) then
        QCheck.Test.fail_reportf "shape %d still transformed" kind;
      let aim = Transform.point tr inside in
      for _ = 1 to 20 do
        let origin =
          Vec3.add aim (Vec3.smul (rand_in st 8. 20.) (Vec3.normalize (rv 1.)))
        in
        let r = Ray.make origin (Vec3.add (Vec3.sub aim origin) (rv (0.3 *. k))) in
        let t = Queries.intersect o r 0. inf and t' = Queries.intersect b r 0. inf in
        let close a b' = Float.abs (a -. b') <= 1e-9 *. Float.max 1. (Float.abs a) in
        if not ((t = inf && t' = inf) || close t t') then
          QCheck.Test.fail_reportf "shape %d: root %.17g, baked %.17g" kind t t';
        if t < inf then
          let p = Ray.at r t in
          let n = Primitive.normal o (Primitive.to_object o p)
          and n' = Primitive.normal b (Primitive.to_object b p) in
          if Vec3.max_abs (Vec3.sub n n') > 1e-9 then
            QCheck.Test.fail_reportf "shape %d: normal (%g, %g, %g), baked (%g, %g, %g)"
              kind n.x n.y n.z n'.x n'.y n'.z
      done;
      true)

let placed_tests =
  [
    case "what a translation cannot carry is left as it is" (fun () ->
        let m = Material.default in
        let textured =
          {
            m with
            texture =
              Some (Description.Checker { c1 = Color.white; c2 = Color.black; size = 1. });
          }
        in
        let s = Shape.sphere ~center:Vec3.zero ~radius:1. in
        let same msg o = Alcotest.(check bool) msg true (Primitive.baked o == o) in
        same "a textured rotated sphere"
          (Primitive.make ~transform:(Transform.rotate (v 0. 30. 0.)) textured s);
        same "a textured scaled sphere"
          (Primitive.make ~transform:(Transform.scale (v 2. 2. 2.)) textured s);
        same "a sphere scaled unevenly"
          (Primitive.make ~transform:(Transform.scale (v 2. 1. 2.)) m s);
        same "a rotated box"
          (Primitive.make
             ~transform:(Transform.rotate (v 0. 30. 0.))
             m
             (Shape.box ~min:Vec3.zero ~max:(v 1. 1. 1.)));
        same "a rotated triangle"
          (Primitive.make
             ~transform:(Transform.rotate (v 0. 30. 0.))
             m
             (Shape.triangle ~a:Vec3.zero ~b:(v 1. 0. 0.) ~c:(v 0. 1. 0.)));
        same "a cylinder scaled unevenly"
          (Primitive.make
             ~transform:(Transform.scale (v 1. 2. 1.))
             m
             (Shape.cylinder ~base:Vec3.zero ~top:(v 0. 1. 0.) ~radius:0.5 ~caps:true));
        same "an untransformed sphere" (Primitive.make m s);
        same "a translated CSG object"
          (Primitive.make
             ~transform:(Transform.translate (v 1. 2. 3.))
             m
             (Shape.csg Union
                [ (s, Transform.identity); (s, Transform.translate (v 1. 0. 0.)) ])));
    case "a scene's translated spheres are untransformed, whatever the camera" (fun () ->
        let prims =
          List.init 20 (fun k ->
              Primitive.make
                ~transform:(Transform.translate (v (Float.of_int k) 0. 5.))
                Material.default
                (Shape.sphere ~center:Vec3.zero ~radius:0.4))
        in
        List.iter
          (fun position ->
            let camera = Camera.make ~position ~look_at:(v 0. 0. 5.) () in
            let sc = Scene.make_exn ~camera ~lights:[] prims in
            Array.iter
              (fun (o : Primitive.t) ->
                Alcotest.(check bool)
                  "untransformed" true
                  (Transform.is_identity o.transform))
              sc.objects)
          [ Vec3.zero; v 0. 1. (-4.); v 1e6 1e6 (-1e6) ]);
  ]

(* ---- sphere fields ---- *)

(* A grid of untransformed spheres (the flat leaves the hierarchy tests without reading
   a primitive), some duplicated or touching their neighbours (ties), a few of them
   transformed, boxes and transparent spheres among them, on an untransformed floor
   and sometimes a tilted, transformed plane: the leaves of flat spheres that are walked
   as one and the ones that are not, and the planes tested from flat scalars and the
   ones that are not. *)
let sphere_field st =
  let n = 4 + Random.State.int st 9 in
  let s = 1. in
  let r = if Random.State.bool st then 0.5 else rand_in st 0.2 0.5 in
  let m = Material.default and glass = { Material.default with transparency = 0.5 } in
  let l = ref [] in
  for i = 0 to n - 1 do
    for j = 0 to n - 1 do
      let c = v (Float.of_int i *. s) r (Float.of_int j *. s) in
      let k = Random.State.int st 20 in
      let p =
        if k = 0 then
          Primitive.make
            ~transform:(Transform.translate (v 0. 0.25 0.))
            m
            (Shape.sphere ~center:c ~radius:r)
        else if k = 1 then
          Primitive.make m
            (Shape.box ~min:(Vec3.sub c (v r r r)) ~max:(Vec3.add c (v r r r)))
        else
          Primitive.make (if k = 2 then glass else m) (Shape.sphere ~center:c ~radius:r)
      in
      l := p :: !l;
      if Random.State.int st 8 = 0 then l := p :: !l
    done
  done;
  l := Primitive.make m (Shape.plane ~normal:Vec3.y_axis ~offset:0.) :: !l;
  if Random.State.bool st then
    l :=
      Primitive.make
        ~transform:(Transform.rotate (v 10. 0. 20.))
        glass
        (Shape.plane ~normal:Vec3.y_axis ~offset:(-0.5))
      :: !l;
  Array.of_list (List.rev !l)

(* Rays over the field: from above at random, along the axes (reciprocals ±inf) at a
   sphere's height or through the centres' planes, and from points on the floor or on
   a sphere towards a light, as shadow rays start. *)
let field_ray st n =
  let extent = Float.of_int n in
  let grid () = Float.of_int (Random.State.int st n) in
  match Random.State.int st 4 with
  | 0 ->
      ray
        (v (rand_in st (-2.) (extent +. 2.)) (rand_in st 1. 6.) (rand_in st (-2.) extent))
        (rand_dir st)
  | 1 ->
      let axes = [| Vec3.x_axis; Vec3.z_axis; v (-1.) 0. 0.; v 0. 0. (-1.) |] in
      let y = if Random.State.bool st then 0.5 else rand_in st 0. 1. in
      ray (v (grid ()) y (grid ())) axes.(Random.State.int st 4)
  | 2 ->
      ray
        (v (rand_in st 0. extent) 0. (rand_in st 0. extent))
        (Vec3.normalize
           (v (rand_in st (-1.) 1.) (rand_in st 0.2 1.) (rand_in st (-1.) 1.)))
  | _ ->
      let c = v (grid ()) 0.5 (grid ()) in
      let d = rand_dir st in
      ray (Vec3.add c (Vec3.smul 0.5 d)) (Vec3.normalize (v (-0.4) 0.8 (-0.5)))

let brute_any prims r tmax =
  Array.exists (fun p -> Queries.intersect p r 0. tmax < tmax) prims

(* Every query of a sphere field against the scan over its primitives, through one
   structure over them all and through two parts (a moving one picked at random). *)
let sphere_field_prop =
  QCheck.Test.make
    ~name:
      "over a sphere field, one structure or two parts answer every query as the scan, \
       ties and axis-parallel rays included"
    ~count:40
    QCheck.(int_bound 1_000_000_000)
    (fun seed ->
      let st = Random.State.make [| seed |] in
      let prims = sphere_field st in
      let n = Array.length prims in
      let moving = Array.init n (fun _ -> Random.State.int st 5 = 0) in
      let part want =
        Array.of_list (List.filter (fun i -> moving.(i) = want) (List.init n Fun.id))
      in
      let fixed_idx = part false and moving_idx = part true in
      let sub idx = Array.map (fun i -> prims.(i)) idx in
      let layered =
        Accel.layered prims ~key:[||]
          ~fixed:(Accel.build (sub fixed_idx))
          ~fixed_idx
          ~moving:(Accel.build (sub moving_idx))
          ~moving_idx
      in
      let whole = Accel.build prims in
      if not (Accel.uses_bvh whole) then QCheck.Test.fail_report "no BVH built";
      let side = int_of_float (Float.sqrt (Float.of_int n)) in
      for _ = 1 to 300 do
        let r = field_ray st side in
        let tmax = if Random.State.int st 3 = 0 then rand_in st 0.5 8. else inf in
        let t0, i0 = brute_nearest prims r 0. tmax in
        let blocked = brute_occluded prims r tmax and any = brute_any prims r tmax in
        List.iter
          (fun (name, a) ->
            let t, i = Queries.nearest a r 0. tmax in
            if i <> i0 || not (same_bits t t0) then
              QCheck.Test.fail_reportf "%s: nearest (%.17g, %d), scan (%.17g, %d)" name t
                i t0 i0;
            let got =
              Queries.any a r 0. tmax ~opaque:true ~slot:(Random.State.int st 2)
            in
            if got <> blocked then
              QCheck.Test.fail_reportf "%s: occluded %b, scan %b" name got blocked;
            let hit = Queries.any a r 0. tmax ~opaque:false in
            if hit <> any then
              QCheck.Test.fail_reportf "%s: any hit %b, scan %b" name hit any;
            (* The transparent crossings are those of the scan, in order. *)
            let seen =
              List.map
                (fun (t, i, _, _) -> (i, t))
                (Queries.crossings a r 0. tmax ~transparent:true)
            in
            let ts = List.map snd seen in
            if ts <> List.sort Float.compare ts then
              QCheck.Test.fail_reportf "%s: crossings out of order" name;
            let expected =
              List.filter
                (fun (i, _) -> prims.(i).Primitive.material.transparency <> 0.)
                (brute_crossings prims r 0. tmax)
            in
            let norm l =
              List.sort compare (List.map (fun (i, t) -> (index_of prims prims.(i), t)) l)
            in
            if norm seen <> norm expected then
              QCheck.Test.fail_reportf "%s: %d transparent crossings, scan %d" name
                (List.length seen) (List.length expected))
          [ ("one structure", whole); ("two parts", layered) ]
      done;
      true)

let bvh_tests =
  [
    case "small scenes skip the hierarchy, larger ones build it" (fun () ->
        let s i =
          Primitive.make Material.default
            (Shape.sphere ~center:(v (Float.of_int i) 0. 0.) ~radius:0.4)
        in
        Alcotest.(check bool) "7" false (Accel.uses_bvh (Accel.build (Array.init 7 s)));
        Alcotest.(check bool) "100" true (Accel.uses_bvh (Accel.build (Array.init 100 s)));
        Alcotest.(check bool)
          "planes only" false
          (Accel.uses_bvh
             (Accel.build
                (Array.init 20 (fun i ->
                     Primitive.make Material.default
                       (Shape.plane ~normal:Vec3.y_axis ~offset:(Float.of_int i)))))));
    case
      "building over spheres allocates no box per sphere, and bounds_into writes bounds"
      (fun () ->
        let n = 20_000 in
        let prims =
          Array.init n (fun i ->
              Primitive.make Material.default
                (Shape.sphere
                   ~center:(v (Float.of_int (i mod 200)) 0.5 (Float.of_int (i / 200)))
                   ~radius:0.4))
        in
        Gc.full_major ();
        let w0 = Gc.minor_words () in
        let a = Accel.build prims in
        let words = (Gc.minor_words () -. w0) /. Float.of_int n in
        Alcotest.(check bool) "a tree" true (Accel.uses_bvh a);
        if words > 4. then Alcotest.failf "%.1f words allocated a sphere" words;
        let b = Float.Array.make 6 0. in
        let same p =
          Primitive.bounds_into p b 0;
          match Primitive.bounds p with
          | Some { Bbox.min; max } ->
              List.iteri
                (fun k x -> Alcotest.(check (float 0.)) "bound" x (Float.Array.get b k))
                [ min.x; min.y; min.z; max.x; max.y; max.z ]
          | None -> Alcotest.(check bool) "NaN" true (Float.is_nan (Float.Array.get b 0))
        in
        same prims.(7);
        same
          (Primitive.make
             ~transform:(Transform.scale (v 2. 3. 4.))
             Material.default
             (Shape.sphere ~center:(v 1. 2. 3.) ~radius:0.7));
        same
          (Primitive.make Material.default
             (Shape.box ~min:(v 0. 1. 2.) ~max:(v 3. 4. 5.)));
        same
          (Primitive.make Material.default (Shape.plane ~normal:Vec3.y_axis ~offset:1.)));
    case "a thousand identical spheres give the lowest index" (fun () ->
        let prims =
          Array.init 1000 (fun _ ->
              Primitive.make Material.default (Shape.sphere ~center:Vec3.zero ~radius:1.))
        in
        let accel = Accel.build prims in
        let t, i = Queries.nearest accel (ray (v 0. 0. (-5.)) Vec3.z_axis) 0. inf in
        close "t" 4. t;
        Alcotest.(check int) "index" 0 i);
    case "a BVH render is byte-identical to a brute-force render" (fun () ->
        let st = Random.State.make [| 7 |] in
        let mat c = { Material.default with color = c; specular = 0.3 } in
        let objs =
          Primitive.make
            (mat (Color.v 0.8 0.8 0.8))
            (Shape.plane ~normal:Vec3.y_axis ~offset:(-2.))
          :: List.init 60 (fun k ->
                 let c =
                   v (rand_in st (-4.) 4.) (rand_in st (-1.5) 3.) (rand_in st 0. 8.)
                 in
                 let color =
                   Color.v (Random.State.float st 1.) (Random.State.float st 1.)
                     (Random.State.float st 1.)
                 in
                 let m =
                   if k mod 7 = 0 then { (mat color) with reflection = 0.5 }
                   else mat color
                 in
                 let s =
                   match k mod 4 with
                   | 0 -> Shape.sphere ~center:c ~radius:(rand_in st 0.2 0.7)
                   | 1 -> Shape.box ~min:c ~max:(Vec3.add c (rand_point st 0.2 0.8))
                   | 2 ->
                       Shape.triangle ~a:c
                         ~b:(Vec3.add c (v 0.8 0. 0.))
                         ~c:(Vec3.add c (v 0. 0.8 0.3))
                   | _ ->
                       Shape.cylinder ~base:c
                         ~top:(Vec3.add c (v 0. 0.7 0.))
                         ~radius:0.3 ~caps:true
                 in
                 Primitive.make m s)
        in
        let settings = { Settings.default with width = 96; height = 72; depth = 3 } in
        let lights =
          [
            Light.Point
              {
                position = v 5. 8. (-6.);
                color = Color.white;
                intensity = 1.;
                attenuation = v 1. 0. 0.;
                radius = 0.;
                samples = 1;
                spot = None;
              };
          ]
        in
        let a = Scene.make_exn ~settings ~lights objs in
        let b =
          Scene.make_exn ~settings ~lights (List.map Primitive.without_bounds objs)
        in
        Alcotest.(check bool) "a uses the BVH" true (Accel.uses_bvh a.accel);
        Alcotest.(check bool) "b scans" false (Accel.uses_bvh b.accel);
        let fa, _ = Render.render a and fb, _ = Render.render b in
        Alcotest.(check bool)
          "identical framebuffers" true
          (let same = ref true in
           Float.Array.iteri
             (fun k x ->
               if
                 not
                   (Int64.equal (Int64.bits_of_float x)
                      (Int64.bits_of_float (Float.Array.get fb.data k)))
               then same := false)
             fa.data;
           !same));
  ]

(* ---- textures and bump maps ---- *)

let red = Color.v 1. 0. 0.
and blue = Color.v 0. 0. 1.

let ramp =
  (* 4×1 image, brightness growing to the right. *)
  let img = Framebuffer.create 4 1 in
  for i = 0 to 3 do
    let x = Float.of_int i /. 3. in
    Framebuffer.set img i 0 (Color.v x x x)
  done;
  img

let in_between (c : Color.t) =
  c.r >= 0. && c.r <= 1. && c.b >= 0. && c.b <= 1. && Float.abs (c.r +. c.b -. 1.) < 1e-12

let texture_tests =
  let procedural =
    [
      Description.Noise { c1 = red; c2 = blue; scale = 0.7 };
      Marble { c1 = red; c2 = blue; scale = 0.7 };
      Wood { c1 = red; c2 = blue; scale = 0.7 };
    ]
  in
  [
    case "noise, marble and wood are deterministic and mix between their two colours"
      (fun () ->
        let st = Random.State.make [| 3 |] in
        let pts = List.init 200 (fun _ -> rand_point st (-20.) 20.) in
        List.iter
          (fun tex ->
            let a = List.map (fun p -> Texture.eval tex p 0. 0.) pts
            and b = List.map (fun p -> Texture.eval tex p 0. 0.) pts in
            Alcotest.(check bool) (Texture.name tex ^ " deterministic") true (a = b);
            Alcotest.(check bool)
              (Texture.name tex ^ " in range")
              true (List.for_all in_between a);
            Alcotest.(check bool)
              (Texture.name tex ^ " varies")
              true
              (List.exists (fun c -> c <> List.hd a) a))
          procedural);
    case "procedural textures survive huge and non-finite points" (fun () ->
        List.iter
          (fun tex ->
            List.iter
              (fun p ->
                Alcotest.(check bool)
                  "finite" true
                  (Color.is_finite (Texture.eval tex p 0. 0.)))
              [ v 1e300 (-1e300) 0.; v Float.nan 0. 0.; v inf 0. 0. ])
          procedural);
    case "an image texture returns its pixels at their centres and wraps" (fun () ->
        let tex = Description.Image { image = ramp; scale = 1. } in
        close "second pixel" (1. /. 3.) (Texture.eval tex Vec3.zero 0.375 0.5).r;
        close "wrapped" (1. /. 3.) (Texture.eval tex Vec3.zero 1.375 (-2.5)).r;
        close "bilinear between pixels 1 and 2" 0.5 (Texture.eval tex Vec3.zero 0.5 0.5).g;
        close "scale tiles" (1. /. 3.)
          (Texture.eval
             (Description.Image { image = ramp; scale = 2. })
             Vec3.zero 0.1875 0.5)
            .r;
        Alcotest.(check bool) "needs uv" true (Texture.needs_uv tex);
        Alcotest.(check bool)
          "nan coordinates" true
          (Color.is_finite (Texture.eval tex Vec3.zero Float.nan inf)));
    case
      "an image bump map tilts the normal against the height's growth, a flat one leaves \
       it" (fun () ->
        let plane = Shape.plane ~normal:Vec3.y_axis ~offset:0. in
        let p = v 0.3 0. 0.2 in
        let uv d = Shape.uv plane (Vec3.add p d) in
        let n =
          Bump.perturb
            (Description.Image_bump { image = ramp; amount = 1. })
            ~uv p Vec3.y_axis
        in
        close "unit" 1. (Vec3.length n);
        Alcotest.(check bool) "tilted toward −x (u grows with x)" true (n.x < -0.01);
        let flat = Framebuffer.create 4 4 in
        let n =
          Bump.perturb
            (Description.Image_bump { image = flat; amount = 1. })
            ~uv p Vec3.y_axis
        in
        check_vec "flat" Vec3.y_axis n);
  ]

let () =
  Alcotest.run "geometry"
    [
      ("sphere and plane", sphere_tests);
      ("flat shapes", flat_tests);
      ("quadrics and box", quadric_tests);
      ("convexity", [ seeded convex_prop ]);
      ("obj", mesh_tests @ [ seeded obj_number_prop ]);
      ("indexed mesh", indexed_tests @ [ seeded mesh_nearest_prop ]);
      ("watertight", [ seeded watertight_mesh; seeded watertight_tiles ]);
      ("bvh", bvh_tests @ [ seeded bvh_nearest_prop; seeded bvh_crossings_prop ]);
      ("shadow query", [ seeded occluded_prop; occluded_allocation ]);
      ("scalar forms", [ seeded scalar_forms_prop ]);
      ( "shadow mask",
        [
          seeded shadow_mask_prop;
          case "a ball at the edge of the light's cone, at every distance, is tested"
            (fun () ->
              (* From (0, 0, 0) toward a light of radius 2 at (0, 10, 0): at s along the
                 way, a ray toward the disk's edge passes 2s from the axis. A small ball
                 there blocks that ray, and the mask must let it be tested. *)
              let o = v 0. 0. 0. and c = v 0. 10. 0. and radius = 2. in
              List.iter
                (fun s ->
                  let ball =
                    Primitive.make Material.default
                      (Shape.sphere
                         ~center:(v (0.98 *. 2. *. s) (10. *. s) 0.)
                         ~radius:0.01)
                  in
                  let a = Accel.build [| ball |] in
                  let sc = Accel.domain_scratch () and q = Probe.create () in
                  Probe.set_origin q o.x o.y o.z;
                  let mask = Accel.shadow_mask a q c radius in
                  let edge = Vec3.add c (v (0.98 *. radius) 0. 0.) in
                  let d = Vec3.sub edge o in
                  let dist = Vec3.length d in
                  let d = Vec3.smul (1. /. dist) d in
                  Probe.of_ray q (ray o d);
                  q.p_tmin <- 0.;
                  q.p_tmax <- dist;
                  if not (Accel.any sc a q ~opaque:true ~slot:(-1) ~mask) then
                    Alcotest.failf "the ball at s = %g is left out (mask %d)" s mask)
                [ 0.05; 0.1; 0.2; 0.3; 0.45; 0.6; 0.9 ]);
          case "the mask left some objects out in some of those cases" (fun () ->
              if !masked_culls = 0 then Alcotest.fail "the mask never culled an object");
          seeded csg_surface_prop;
          case "the mask left the object out for some of those points" (fun () ->
              if !own_culls < 40 then
                Alcotest.failf "the mask left a CSG object out for %d points of its own"
                  !own_culls);
          case
            "a tube is left out for a point of its own side under a light above it, not \
             for one inside it" (fun () ->
              let cyl top r =
                ( Shape.cylinder ~base:(v 0. 0. 0.) ~top:(v 0. top 0.) ~radius:r ~caps:true,
                  Transform.identity )
              in
              let tube =
                Primitive.make
                  ~transform:(Transform.translate (v (-0.1) 0. (-0.4)))
                  Material.default
                  (Shape.csg Difference [ cyl 1.4 0.5; cyl 1.5 0.4 ])
              in
              let a = Accel.build [| tube |] in
              let q = Probe.create () in
              let mask x =
                Probe.set_origin q (x -. 0.1) 0.7 (-0.4);
                Accel.shadow_mask a q (v 6. 6. (-0.4)) 0.5
              in
              Alcotest.(check int) "on its outer side" 0 (mask (0.5 +. 1e-9));
              Alcotest.(check int)
                "on its inner side, in the hole" 1
                (mask (-0.4 +. 1e-9)));
          case "the mask keeps a CSG object wherever a ray toward the light may meet it"
            (fun () ->
              let id = Transform.identity in
              (* The object, alone at slot 0, is kept for a light of radius r at c seen
                 from o, and the ray toward c is blocked. *)
              let kept what ?transform ?toward shape o c r =
                let p = Primitive.make ?transform Material.default shape in
                let a = Accel.build [| p |] in
                let sc = Accel.domain_scratch () and q = Probe.create () in
                Probe.set_origin q o.Vec3.x o.y o.z;
                let mask = Accel.shadow_mask a q c r in
                if mask land 1 = 0 then Alcotest.failf "%s: the object is left out" what;
                let d = Vec3.sub (Option.value toward ~default:c) o in
                let dist = Vec3.length d in
                Probe.of_ray q (ray o (Vec3.smul (1. /. dist) d));
                q.p_tmin <- 0.;
                q.p_tmax <- dist;
                if not (Accel.any sc a q ~opaque:true ~slot:(-1) ~mask:(-1)) then
                  Alcotest.failf "%s: the ray toward the light is not blocked" what
              in
              let cyl base top r = Shape.cylinder ~base ~top ~radius:r ~caps:true in
              let tube =
                Shape.csg Difference
                  [
                    (cyl (v 0. 0. 0.) (v 0. 1.4 0.) 0.5, id);
                    (cyl (v 0. (-0.1) 0.) (v 0. 1.5 0.) 0.4, id);
                  ]
              in
              (* a point of the hole's wall, the light beyond the wall behind it *)
              kept "the hole's wall" tube (v (-0.4 +. 1e-9) 0.7 0.) (v (-6.) 0.7 0.) 0.5;
              (* a point of a slab's face cut into a ball: inside the ball *)
              let ball_cut =
                Shape.csg Difference
                  [
                    (Shape.sphere ~center:Vec3.zero ~radius:1., id);
                    (Shape.box ~min:(v (-0.3) (-2.) (-2.)) ~max:(v 0.3 2. 2.), id);
                  ]
              in
              kept "a cut face" ball_cut (v (0.3 +. 1e-9) 0. 0.) (v 10. 0. 0.) 0.5;
              (* a first member moved within the object: its own transform *)
              let moved =
                Shape.csg Difference
                  [
                    ( Shape.sphere ~center:Vec3.zero ~radius:1.,
                      Transform.translate (v 0. 0. 3.) );
                    (Shape.sphere ~center:(v 9. 9. 9.) ~radius:0.1, id);
                  ]
              in
              kept "a moved member" moved (v 0. 0. 1.5) (v 0. 0. 6.) 0.1;
              (* a ball shrunk tenfold, the light's ball across its top's tangent plane:
                 the light's radius grows tenfold in the object's space *)
              let big =
                Shape.csg Difference
                  [
                    (Shape.sphere ~center:Vec3.zero ~radius:5., id);
                    (Shape.sphere ~center:(v 9. 9. 9.) ~radius:0.1, id);
                  ]
              in
              kept "a shrunk object" ~toward:(v 0.3 0.451 0.)
                ~transform:(Transform.scale (v 0.1 0.1 0.1))
                big
                (v 0. (0.5 +. 1e-9) 0.)
                (v 0.3 0.55 0.) 0.1;
              (* a point within rounding of a cylinder's cap, outside it by its own test,
                 where the cap's roots find a crossing *)
              let capped =
                Shape.csg Difference
                  [
                    ( cyl
                        (v 0x1.e5c5627ef66afp-1 0x1.e4b98ad0c5afcp-3 0x1.ca9b6af8f7d28p+0)
                        (v 0x1.4ba120700982cp+1 0x1.f3f9e009770d1p-1 0x1.9a1daa773be7p+0)
                        0x1.a8b07482cb69p-2,
                      id );
                    (Shape.sphere ~center:(v 90. 90. 90.) ~radius:0.1, id);
                  ]
              in
              let p = Primitive.make Material.default capped in
              let a = Accel.build [| p |] in
              let q = Probe.create () in
              let o = v 0x1.49bb7abe8cecbp+1 0x1.f1eb2da922191p-1 0x1.7534de01ac806p+0 in
              Probe.set_origin q o.x o.y o.z;
              let mask =
                Accel.shadow_mask a q
                  (v 0x1.a679560a4c7fap+2 0x1.090b31893dbfp-5 0x1.db2af09afa19dp+0)
                  0x1.30e02adac14e3p+0
              in
              Alcotest.(check int) "a point within rounding of a cap" 1 mask);
        ] );
      ("sphere fields", [ seeded sphere_field_prop ]);
      ( "placed by a translation",
        placed_tests @ [ seeded placed_prop; seeded similar_prop ] );
      ("textures", texture_tests);
    ]
