(* A leaf's spheres tested two at a time (Walk.sphere_candidates, in C) against the sphere
   test in OCaml (Shape.sphere_sc): a sphere is left out only where that test takes its
   early miss, which it reports as no root whatever the interval; every sphere the ray's
   line crosses stays in, grazing ones included. *)

open Lancer_math
open Lancer_render

let seeded t = QCheck_alcotest.to_alcotest ~rand:(Random.State.make [| 20261205 |]) t

(* Shape.sphere_gen's early miss, as its comment and the C both state it: the line's
   distance from the centre, squared, beyond the radius's (with a relative slack of
   1e-9) and not so large that it must be taken again by a scaled length. *)
let early_miss cx cy cz r (q : Probe.t) =
  let fx = q.ox -. cx and fy = q.oy -. cy and fz = q.oz -. cz in
  let a = (q.dx *. q.dx) +. (q.dy *. q.dy) +. (q.dz *. q.dz) in
  let b = (fx *. q.dx) +. (fy *. q.dy) +. (fz *. q.dz) in
  let k = -.b /. a in
  let px = fx +. (k *. q.dx) and py = fy +. (k *. q.dy) and pz = fz +. (k *. q.dz) in
  let l2 = (px *. px) +. (py *. py) +. (pz *. pz) in
  l2 > r *. r *. (1. +. 1e-9) && l2 < 1e280

let probe (ox, oy, oz) (dx, dy, dz) =
  let q = Probe.create () in
  Probe.set_origin q ox oy oz;
  q.dx <- dx;
  q.dy <- dy;
  q.dz <- dz;
  q

(* A case: [lo] slots before the leaf, then its [n] spheres; some are aimed at (the ray
   passes at [r·(1 + e)] from the centre, e within ±3e-9 for a grazing one), some hold
   NaN, the others lie anywhere. Scales from 1e-3 to 1e3, and now and then 1e150, whose
   squares need the scaled length. *)
let case =
  let open QCheck.Gen in
  let coord s = map (fun x -> s *. x) (float_range (-1.) 1.) in
  let* scale = oneof [ return 1e-3; return 1.; return 1e3; return 1e150 ] in
  let* lo = int_range 0 3 and* n = int_range 1 (Sys.int_size - 1) in
  let* o = triple (coord scale) (coord scale) (coord scale) in
  let* d = triple (coord 1.) (coord 1.) (coord 1.) in
  let d = match d with 0., 0., 0. -> (0., 0., 1.) | d -> d in
  let* spheres =
    list_repeat (lo + n)
      (let* kind = int_range 0 9 and* r = float_range 0.01 0.5 in
       let r = r *. scale in
       match kind with
       | 0 -> return (Float.nan, Float.nan, Float.nan, Float.nan)
       | 1 | 2 | 3 | 4 ->
           (* Centre at t along the ray, moved off it by r·(1 + e) across it. *)
           let* t = float_range (-2.) 2.
           and* e =
             if kind = 1 then float_range (-3e-9) 3e-9 else float_range (-0.5) 0.5
           in
           let ox, oy, oz = o and dx, dy, dz = d in
           (* A unit vector across d: d × (1, 0, 0) or d × (0, 1, 0). *)
           let ux, uy, uz =
             if Float.abs dx < Float.abs dy then (0., dz, -.dy) else (-.dz, 0., dx)
           in
           let u = Float.sqrt ((ux *. ux) +. (uy *. uy) +. (uz *. uz)) in
           let off = r *. (1. +. e) /. u in
           let t = t *. scale in
           return
             ( ox +. (t *. dx) +. (off *. ux),
               oy +. (t *. dy) +. (off *. uy),
               oz +. (t *. dz) +. (off *. uz),
               r )
       | _ ->
           let* x = coord scale and* y = coord scale and* z = coord scale in
           return (x, y, z, r))
  in
  return (lo, n, o, d, spheres)

let flat_of spheres =
  let f = Float.Array.make (4 * List.length spheres) 0. in
  List.iteri
    (fun j (x, y, z, r) ->
      Float.Array.set f (4 * j) x;
      Float.Array.set f ((4 * j) + 1) y;
      Float.Array.set f ((4 * j) + 2) z;
      Float.Array.set f ((4 * j) + 3) r)
    spheres;
  f

let print (lo, n, o, d, spheres) =
  let p3 (x, y, z) = Printf.sprintf "(%h, %h, %h)" x y z in
  Printf.sprintf "lo %d n %d origin %s direction %s spheres [%s]" lo n (p3 o) (p3 d)
    (String.concat "; "
       (List.map (fun (x, y, z, r) -> Printf.sprintf "%s r %h" (p3 (x, y, z)) r) spheres))

let sphere_of flat j =
  let g k = Float.Array.get flat ((4 * j) + k) in
  (g 0, g 1, g 2, g 3)

(* The mask is the early miss, slot by slot, and no bit is set past the leaf. *)
let exact =
  QCheck.Test.make ~name:"the mask is the sphere test's early miss, slot by slot"
    ~count:3000 (QCheck.make ~print case) (fun (lo, n, o, d, spheres) ->
      let flat = flat_of spheres and q = probe o d in
      let m = Walk.sphere_candidates flat lo n q in
      m lsr n = 0
      && List.for_all
           (fun k ->
             let x, y, z, r = sphere_of flat (lo + k) in
             let set = (m lsr k) land 1 = 1 in
             set = not (early_miss x y z r q))
           (List.init n Fun.id))

(* A sphere left out has no root in any interval; one with a root stays in. *)
let sound =
  QCheck.Test.make ~name:"a sphere left out has no root" ~count:3000
    (QCheck.make ~print case) (fun (lo, n, o, d, spheres) ->
      let flat = flat_of spheres and q = probe o d in
      let m = Walk.sphere_candidates flat lo n q in
      List.for_all
        (fun k ->
          let x, y, z, r = sphere_of flat (lo + k) in
          let root =
            Shape.sphere_sc x y z r q.ox q.oy q.oz q.dx q.dy q.dz Float.neg_infinity
              Float.infinity
          in
          (m lsr k) land 1 = 1 || root = Float.infinity)
        (List.init n Fun.id))

(* Eight spheres in a row across the z axis, a ray down it through the fourth: only that
   one and the NaN slot stay. *)
let row () =
  let spheres =
    List.init 8 (fun k ->
        if k = 6 then (Float.nan, Float.nan, Float.nan, Float.nan)
        else (Float.of_int (k - 3), 0., 5., 0.4))
  in
  let flat = flat_of spheres in
  let q = probe (0., 0., 0.) (0., 0., 1.) in
  Alcotest.(check int)
    "the fourth and the NaN slot"
    ((1 lsl 3) lor (1 lsl 6))
    (Walk.sphere_candidates flat 0 8 q);
  Alcotest.(check int)
    "from slot 2, five slots: the fourth and the NaN slot, bits 1 and 4"
    ((1 lsl 1) lor (1 lsl 4))
    (Walk.sphere_candidates flat 2 5 q)

let () =
  Alcotest.run "spheres"
    [
      ("candidates", [ seeded exact; seeded sound; Alcotest.test_case "a row" `Quick row ]);
    ]
