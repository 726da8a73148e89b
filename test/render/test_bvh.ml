(* Bvh.build against Bvh_ref.build, the same binned-SAH build written plainly: the same
   node array (every reachable node's 8 floats, bit for bit), the same leaf order and the
   same depth, over random item sets of many sizes and shapes. Random inputs use fixed
   seeds. *)
module Bvh = Lancer_render.Bvh

(* The nodes of a tree over [m] items: those up to its last in preorder, found by following
   right children from the root (a tree over none is one empty leaf). *)
let reachable m nodes =
  let rec walk k = if Bvh.count nodes k > 0 then k + 1 else walk (Bvh.link nodes k) in
  if m = 0 then 1 else walk 0

let same_tree ?cheap ?large what pbox =
  let a = Bvh.build ?cheap ?large (Float.Array.copy pbox) in
  let b = Bvh_ref.build ?cheap ?large (Float.Array.copy pbox) in
  if a.depth <> b.depth then
    Alcotest.failf "%s: depth %d, reference %d" what a.depth b.depth;
  if a.order <> b.order then Alcotest.failf "%s: the leaf order differs" what;
  let m = Float.Array.length pbox / 6 in
  let n = reachable m b.nodes in
  if reachable m a.nodes <> n then Alcotest.failf "%s: the node count differs" what;
  for i = 0 to (8 * n) - 1 do
    let x = Float.Array.get a.nodes i and y = Float.Array.get b.nodes i in
    if Int64.bits_of_float x <> Int64.bits_of_float y then
      Alcotest.failf "%s: node %d float %d is %h, reference %h" what (i / 8) (i mod 8) x y
  done

(* [m] items from [gen], which gives a box's min and extent. *)
let items m gen =
  let pb = Float.Array.create (6 * m) in
  for k = 0 to m - 1 do
    let x, y, z, dx, dy, dz = gen k in
    Bvh.pad_into pb k x y z (x +. dx) (y +. dy) (z +. dz)
  done;
  pb

let shapes rs =
  let f s = Random.State.float rs s in
  let i n = Float.of_int (Random.State.int rs n) in
  [
    ("uniform", fun _ -> (f 100., f 100., f 100., f 3., f 3., f 3.));
    ("points", fun _ -> (f 10., f 10., f 10., 0., 0., 0.));
    ("flat", fun _ -> (f 50., 2., f 50., f 1., 0., f 1.));
    ("a line", fun _ -> (f 1000., 0., 0., f 2., 0., 0.));
    ("grid ties", fun _ -> (i 8, i 8, i 8, 1., 1., 1.));
    ("few distinct", fun _ -> (i 3, 0., i 2, 0.5, 0.5, 0.5));
    ("all equal", fun _ -> (1., 2., 3., 1., 1., 1.));
    ("mixed sizes", fun _ -> (f 100., f 100., f 100., f 50. ** 2., f 0.1, f 5.));
    ( "clusters",
      fun k -> (Float.of_int (k mod 4 * 1000) +. f 1., f 1., f 1., f 0.1, f 0.1, f 0.1) );
    ( "large magnitudes",
      fun _ -> (1e12 +. f 1e6, -1e9 -. f 1e3, f 1e-6, f 1e3, f 1e3, f 1e-9) );
    ("sorted", fun k -> (Float.of_int k, 0., 0., 1., 1., 1.));
    ("reversed", fun k -> (Float.of_int (-k), Float.of_int (k mod 7), 0., 1., 1., 1.));
    (* Split off a few at a time: trees deeper (73) than the scratch first made (64). *)
    ("exponential", fun k -> (1.5 ** Float.of_int (k mod 400), f 1., 0., 1., 1., 1.));
  ]

let sizes =
  [ 0; 1; 2; 3; 5; 8; 9; 16; 31; 32; 33; 34; 40; 63; 64; 65; 100; 257; 1000; 4099 ]

let random_sets () =
  let rs = Random.State.make [| 20261202 |] in
  List.iter
    (fun (name, gen) ->
      List.iter
        (fun m -> same_tree (Printf.sprintf "%s, %d items" name m) (items m gen))
        sizes)
    (shapes rs)

(* Duplicates among distinct boxes, in random order: ties at every level. *)
let duplicates () =
  let rs = Random.State.make [| 7 |] in
  for round = 1 to 20 do
    let m = 50 + Random.State.int rs 3000 in
    let distinct = 1 + Random.State.int rs 40 in
    let base =
      Array.init distinct (fun _ ->
          let f s = Random.State.float rs s in
          (f 20., f 20., f 20., f 2., f 2., f 2.))
    in
    let pb = items m (fun _ -> base.(Random.State.int rs distinct)) in
    same_tree (Printf.sprintf "duplicates, round %d, %d items" round m) pb
  done

let large () =
  let rs = Random.State.make [| 99 |] in
  let f s = Random.State.float rs s in
  same_tree "50000 uniform"
    (items 50000 (fun _ -> (f 1000., f 1000., f 1000., f 4., f 4., f 4.)));
  same_tree "a 200 × 200 grid"
    (items 40000 (fun k ->
         ( Float.of_int (k / 200) -. 0.4,
           0.,
           Float.of_int (k mod 200) -. 0.4,
           0.8,
           0.8,
           0.8 )))

(* Items flagged cheap: a node of at most four of them is a leaf, with no split searched,
   as in the reference; where some are not flagged the node is searched as before. *)
let cheap_leaves () =
  let rs = Random.State.make [| 4 |] in
  let count_leaves nodes m =
    (* Leaves of 3 or 4 items, reached from the root. *)
    let rec go k acc =
      let c = Bvh.count nodes k in
      if c > 0 then if c >= 3 then acc + 1 else acc
      else go (Bvh.link nodes k) (go (k + 1) acc)
    in
    if m = 0 then 0 else go 0 0
  in
  List.iter
    (fun (name, gen) ->
      List.iter
        (fun m ->
          let pb = items m gen in
          let all = Bytes.make m '\001' in
          let some =
            Bytes.init m (fun _ -> if Random.State.int rs 4 = 0 then '\000' else '\001')
          in
          same_tree ~cheap:(all, 4) (Printf.sprintf "%s, %d items, all cheap" name m) pb;
          same_tree ~cheap:(some, 4) (Printf.sprintf "%s, %d items, some cheap" name m) pb;
          same_tree
            ~cheap:(Bytes.make m '\000', 4)
            (Printf.sprintf "%s, %d items, none cheap" name m)
            pb)
        sizes)
    (shapes rs);
  (* Over a grid of separate boxes, the search alone splits down to one or two items a
     leaf; cheap items stop at four. *)
  let grid =
    items 4096 (fun k ->
        (Float.of_int (k / 64), 0., Float.of_int (k mod 64), 0.8, 0.8, 0.8))
  in
  let plain = Bvh.build (Float.Array.copy grid) in
  let cheap = Bvh.build ~cheap:(Bytes.make 4096 '\001', 4) (Float.Array.copy grid) in
  Alcotest.(check int) "no leaf of 3 or 4 without flags" 0 (count_leaves plain.nodes 4096);
  if count_leaves cheap.nodes 4096 < 512 then
    Alcotest.failf "cheap items: %d leaves of 3 or 4, expected at least 512"
      (count_leaves cheap.nodes 4096)

(* From [large] items the tree's large nodes are cut in Morton order. Every shape and
   size of [random_sets], with and without cheap items, built that way from 17 items on
   (every node above the small subtrees cut) and from 300: the same trees as the plain
   reference, where wide items (the mixed sizes, a floor under small boxes) are set apart
   under the root. *)
let morton () =
  let rs = Random.State.make [| 18 |] in
  let with_floor =
    ( "a floor under small boxes",
      fun k ->
        if k = 5 then (-10., -1., -10., 120., 1., 120.)
        else
          let f s = Random.State.float rs s in
          (f 100., f 100., f 100., f 0.5, f 0.5, f 0.5) )
  in
  List.iter
    (fun (name, gen) ->
      List.iter
        (fun m ->
          let pb = items m gen in
          List.iter
            (fun large ->
              let what = Printf.sprintf "%s, %d items, Morton from %d" name m large in
              same_tree ~large what pb;
              same_tree ~large ~cheap:(Bytes.make m '\001', 8) (what ^ ", all cheap") pb)
            [ 17; 300 ])
        sizes)
    (with_floor :: shapes rs);
  let f s = Random.State.float rs s in
  same_tree ~large:17 "50000 uniform, Morton"
    (items 50000 (fun _ -> (f 1000., f 1000., f 1000., f 4., f 4., f 4.)))

(* Over a grid with a floor, the tree in Morton order keeps the floor out of the grid's
   boxes: only the root and the floor's own leaf are wider than the grid, rather than every
   node on the floor's way down. *)
let morton_floor () =
  let n = 64 in
  let pb =
    items
      ((n * n) + 1)
      (fun k ->
        if k = n * n then (-100., -1., -100., 200., 1., 200.)
        else (Float.of_int (k / n), 0., Float.of_int (k mod n), 0.8, 0.8, 0.8))
  in
  let t = Bvh.build ~large:17 pb in
  let rec wide k =
    let w = Float.Array.get t.nodes ((8 * k) + 3) -. Float.Array.get t.nodes (8 * k) in
    let here = if w > 65. then 1 else 0 in
    if Bvh.count t.nodes k > 0 then here
    else here + wide (k + 1) + wide (Bvh.link t.nodes k)
  in
  Alcotest.(check int) "nodes wider than the grid" 2 (wide 0)

(* The descent (in C) against Descent_ref, step by step: the same leaf and the same
   stack, entry t by entry t in bits, after every step, over random trees and rays. Some
   origins lie on a node's slab plane with the ray along it (0·inf, NaN), some
   directions have a signed zero, some intervals are unbounded; between two steps the
   best t sometimes falls, as a nearest walk's does. *)
let descent () =
  let rs = Random.State.make [| 20261205 |] in
  let f s = Random.State.float rs s in
  let one_in n = Random.State.int rs n = 0 in
  let same what (a : Bvh.walk) (b : Bvh.walk) la lb =
    if la <> lb then Alcotest.failf "%s: leaf %d, reference %d" what la lb;
    if a.sp <> b.sp then Alcotest.failf "%s: %d on the stack, reference %d" what a.sp b.sp;
    for i = 0 to a.sp - 1 do
      let ta = Float.Array.get a.ts i and tb = Float.Array.get b.ts i in
      if a.ids.(i) <> b.ids.(i) || Int64.bits_of_float ta <> Int64.bits_of_float tb then
        Alcotest.failf "%s: stack entry %d is (%d, %h), reference (%d, %h)" what i
          a.ids.(i) ta b.ids.(i) tb
    done
  in
  let steps = ref 0 in
  List.iter
    (fun (name, gen) ->
      List.iter
        (fun m ->
          let t = Bvh.build (items m gen) in
          let nodes = t.nodes and n = Float.Array.length t.nodes / 8 in
          let lo = Array.init 3 (fun a -> Float.Array.get nodes a)
          and hi = Array.init 3 (fun a -> Float.Array.get nodes (3 + a)) in
          let coord a =
            if one_in 4 then
              Float.Array.get nodes
                ((8 * Random.State.int rs n) + a + if one_in 2 then 0 else 3)
            else
              let w = hi.(a) -. lo.(a) in
              let w = if Float.is_finite w && w > 0. then w else 1. in
              lo.(a) -. w +. f (3. *. w)
          in
          for ray = 1 to 100 do
            let q = Lancer_math.Probe.create () in
            Lancer_math.Probe.set_origin q (coord 0) (coord 1) (coord 2);
            let d () = if one_in 5 then if one_in 2 then 0. else -0. else f 2. -. 1. in
            q.dx <- d ();
            q.dy <- d ();
            q.dz <- d ();
            Lancer_math.Probe.set_inv_dir q;
            let tmin = if one_in 2 then 0. else f 10. in
            let tmax = if one_in 2 then Float.infinity else tmin +. f 300. in
            let a = Bvh.new_walk () and b = Bvh.new_walk () in
            Bvh.ready a t.depth;
            Bvh.ready b t.depth;
            let what k = Printf.sprintf "%s, %d items, ray %d, step %d" name m ray k in
            let la = ref (Bvh.start nodes q a tmin tmax)
            and lb = ref (Descent_ref.start nodes q b tmin tmax)
            and k = ref 0 in
            same (what 0) a b !la !lb;
            while !la >= 0 do
              if one_in 3 then (
                let best = Float.Array.get a.span 1 in
                let best' =
                  if Float.is_finite best then tmin +. f (best -. tmin)
                  else tmin +. f 100.
                in
                Float.Array.set a.span 1 best';
                Float.Array.set b.span 1 best');
              incr k;
              incr steps;
              la := Bvh.next_leaf nodes q a;
              lb := Descent_ref.next_leaf nodes q b;
              same (what !k) a b !la !lb
            done
          done)
        sizes)
    (shapes rs);
  if !steps < 5_000 then Alcotest.failf "only %d steps taken" !steps

let () =
  Alcotest.run "bvh"
    [
      ( "build",
        [
          Alcotest.test_case "random sets of every shape and size" `Quick random_sets;
          Alcotest.test_case "duplicate boxes" `Quick duplicates;
          Alcotest.test_case "large sets" `Quick large;
          Alcotest.test_case "leaves of cheap items" `Quick cheap_leaves;
          Alcotest.test_case "large builds in Morton order" `Quick morton;
          Alcotest.test_case "a floor set apart from a grid" `Quick morton_floor;
        ] );
      ("walk", [ Alcotest.test_case "the descent against a plain one" `Quick descent ]);
    ]
