(* A stream's primitives gathered in order (Gathered), spheres held as floats and made
   again, against the primitives as they were added: every field the same, the material
   and a shared colour the same record, in the same order, moved or not. *)

open Lancer_math
open Lancer_render

let seeded t = QCheck_alcotest.to_alcotest ~rand:(Random.State.make [| 20261205 |]) t

let materials =
  [|
    Material.default;
    { Material.default with specular = 0.5 };
    { Material.default with color = Color.v 0.2 0.4 0.6; reflection = 0.3 };
  |]

let shared_color = Color.v 0.9 0.1 0.1

(* One primitive from a few small numbers: a sphere with its material's colour, a shared
   colour record or one of its own, of one of two radii or its own; a sphere moved by a
   transform; a box; a difference of two spheres; a flipped sphere. *)
let primitive (kind, m, c, r, x) =
  let m = materials.(m mod Array.length materials) in
  let x = Float.of_int x /. 8. in
  let radius =
    match r mod 6 with
    | 0 | 1 -> 0.5
    | 2 -> 0.25
    | 3 -> -0.
    | 4 -> Float.nan
    | _ -> 0.1 +. (x /. 64.)
  in
  let center = Vec3.v x (-.x) (x *. 0.5) in
  let sphere = Shape.sphere ~center ~radius in
  match kind mod 8 with
  | 0 | 1 | 2 | 3 -> (
      match c mod 3 with
      | 0 -> Primitive.make m sphere
      | 1 -> Primitive.make ~color:shared_color m sphere
      | _ -> Primitive.make ~color:(Color.v (x /. 100.) 0.5 0.25) m sphere)
  | 4 -> Primitive.make ~transform:(Transform.translate (Vec3.v 1. 2. 3.)) m sphere
  | 5 -> Primitive.make m (Shape.box ~min:center ~max:(Vec3.add center (Vec3.v 1. 1. 1.)))
  | 6 ->
      Primitive.make m
        (Shape.csg Shape.Difference
           [
             (sphere, Transform.identity);
             (Shape.sphere ~center ~radius:(radius /. 2.), Transform.identity);
           ])
  | _ -> Primitive.make ~flip:true m sphere

(* Floats by their bits: a radius of −0 or NaN must come back as it was. *)
let bits x = Int64.bits_of_float x

let same_shape (a : Shape.t) (b : Shape.t) =
  match (a, b) with
  | Shape.Sphere s, Shape.Sphere t ->
      bits s.center.x = bits t.center.x
      && bits s.center.y = bits t.center.y
      && bits s.center.z = bits t.center.z
      && bits s.radius = bits t.radius
  | _ -> compare a b = 0

let same (a : Primitive.t) (b : Primitive.t) =
  same_shape a.shape b.shape && a.transform = b.transform && a.material == b.material
  && a.color = b.color
  && compare (Primitive.bounds a) (Primitive.bounds b) = 0
  && a.shift = b.shift
  && a.shift == Vec3.zero = (b.shift == Vec3.zero)
  && a.extra.flip = b.extra.flip
  && Array.length a.extra.leaves = Array.length b.extra.leaves

let gen =
  QCheck.(
    list_of_size (Gen.int_range 0 300)
      (quad (int_bound 9) (int_bound 5) (int_bound 5)
         (pair (int_bound 5) (int_bound 800))))

(* How a case is added: an untransformed sphere of kinds 0 and 1 by its parts
   ([add_sphere], as a compiled sphere is), anything else as its primitive. *)
let adder (kind, m, c, r, x) =
  let p = primitive (kind, m, c, r, x) in
  match (kind mod 8, p.shape) with
  | (0 | 1), Shape.Sphere { center; radius } ->
      (p, fun g -> Gathered.add_sphere g ~center ~radius ~color:p.color p.material)
  | _ -> (p, fun g -> Gathered.add g p)

let made_again =
  QCheck.Test.make ~count:300 ~name:"every primitive as it was added, in order" gen
    (fun cases ->
      let added = List.map (fun (k, m, c, (r, x)) -> adder (k, m, c, r, x)) cases in
      let ps = List.map fst added in
      List.for_all
        (fun move ->
          let g = Gathered.create ?move () in
          List.iter (fun (_, add) -> add g) added;
          let want = List.map (Option.value move ~default:Fun.id) ps in
          Gathered.total g = List.length ps
          &&
          let got = Gathered.take g in
          Gathered.total g = 0
          && Array.length got = List.length want
          && List.for_all2 same (Array.to_list got) want)
        [ None; Some (Primitive.mover (Vec3.v 4. (-8.) 16.)) ])

(* Spheres made in a loop, as a program makes them: those that share a material and a
   colour record keep sharing them, equal radii share one float, and the whole holds no
   more words than the primitives added. A mutation that gave each sphere made again a
   colour record of its own fails the count. *)
let shares () =
  let radius = 0.4 in
  let ps =
    List.init 2000 (fun i ->
        let center = Vec3.v (Float.of_int (i mod 40)) 0.4 (Float.of_int (i / 40)) in
        let sphere = Shape.sphere ~center ~radius in
        if i mod 2 = 0 then Primitive.make ~color:shared_color materials.(1) sphere
        else Primitive.make materials.(1) sphere)
  in
  let want = Array.of_list ps in
  Alcotest.(check bool) "spheres held" true (Array.for_all Gathered.holds want);
  (* Added as primitives, then by their parts as a compiled sphere is. *)
  List.iter
    (fun (how, add) ->
      let g = Gathered.create () in
      List.iter (add g) ps;
      Alcotest.(check int)
        (how ^ ": all but the first held as floats")
        1999 (Gathered.held g);
      let got = Gathered.take g in
      Alcotest.(check bool)
        (how ^ ": the same primitives")
        true
        (Array.for_all2 same got want);
      Alcotest.(check int)
        (how ^ ": as many words as the primitives added")
        (Obj.reachable_words (Obj.repr want))
        (Obj.reachable_words (Obj.repr got)))
    [
      ("add", Gathered.add);
      ( "add_sphere",
        fun g (p : Primitive.t) ->
          match p.shape with
          | Shape.Sphere { center; radius } ->
              Gathered.add_sphere g ~center ~radius ~color:p.color p.material
          | _ -> assert false );
    ]

(* Enough spheres, each of its own radius and colour (seven floats), to fill several of
   the largest blocks of floats outside the heap, each freed as take reads past it: every
   one made again as it was added. *)
let many () =
  let n = 40_000 in
  let ps =
    Array.init n (fun i ->
        let f = Float.of_int i in
        let sphere =
          Shape.sphere ~center:(Vec3.v f (-.f) (f /. 3.)) ~radius:(0.1 +. (f /. 1e6))
        in
        Primitive.make
          ~color:(Color.v (f /. 4e4) 0.5 (1. -. (f /. 4e4)))
          materials.(2) sphere)
  in
  let g = Gathered.create () in
  Array.iter (Gathered.add g) ps;
  Alcotest.(check int) "all but the first held" (n - 1) (Gathered.held g);
  let got = Gathered.take g in
  Alcotest.(check bool) "the same primitives" true (Array.for_all2 same got ps)

(* A stream discarded (a load that failed) is empty, and one made after it, or the same
   one filled again, gives what was added since. *)
let discards () =
  let ps =
    List.init 500 (fun i ->
        Primitive.make
          ~color:(Color.v (Float.of_int i /. 500.) 0. 0.)
          materials.(0)
          (Shape.sphere ~center:(Vec3.v (Float.of_int i) 0. 0.) ~radius:0.5))
  in
  let g = Gathered.create () in
  List.iter (Gathered.add g) ps;
  Gathered.discard g;
  Alcotest.(check int) "none left" 0 (Gathered.total g);
  Alcotest.(check int) "none held" 0 (Gathered.held g);
  Alcotest.(check int) "nothing to take" 0 (Array.length (Gathered.take g));
  List.iter (Gathered.add g) ps;
  let got = Gathered.take g in
  Alcotest.(check bool)
    "the same primitives, added again" true
    (List.for_all2 same (Array.to_list got) ps)

let overhead () = (Gc.get ()).space_overhead

(* [f ()] with the collector's overhead at 77, and the test's own set back after it. *)
let at_77 f =
  let before = overhead () in
  Gc.set { (Gc.get ()) with space_overhead = 77 };
  Fun.protect ~finally:(fun () -> Gc.set { (Gc.get ()) with space_overhead = before }) f

(* The all-live pace holds only while its work runs: the collector's overhead is set back
   when the work returns and when it raises, and a take or a build leaves it as it was. *)
let pace () =
  at_77 (fun () ->
      let inside = Pace.within Pace.all_live overhead in
      Alcotest.(check int) "the all-live pace while the work runs" Pace.all_live inside;
      Alcotest.(check int) "set back when it returns" 77 (overhead ());
      (match Pace.within Pace.all_live (fun () -> failwith "stop") with
      | () -> Alcotest.fail "the work raised"
      | exception Failure _ -> ());
      Alcotest.(check int) "set back when it raises" 77 (overhead ());
      let g = Gathered.create () in
      for i = 0 to 99 do
        Gathered.add g
          (Primitive.make Material.default
             (Shape.sphere ~center:(Vec3.v (Float.of_int i) 0. 0.) ~radius:0.5))
      done;
      let prims = Gathered.take g in
      Alcotest.(check int) "a take leaves it" 77 (overhead ());
      ignore (Accel.build prims);
      Alcotest.(check int) "a build leaves it" 77 (overhead ()))

(* Work at the all-live pace on two domains at once, the first to start returning first:
   the pace holds until the last one returns, and the overhead from before comes back.
   Each call setting back what it found would leave the second at 77 once the first
   returned, and the program at the all-live pace after both. *)
let pace_domains () =
  at_77 (fun () ->
      let first_in = Atomic.make false and second_in = Atomic.make false in
      let first =
        Domain.spawn (fun () ->
            Pace.within Pace.all_live (fun () ->
                Atomic.set first_in true;
                while not (Atomic.get second_in) do
                  Domain.cpu_relax ()
                done))
      in
      while not (Atomic.get first_in) do
        Domain.cpu_relax ()
      done;
      let after_first =
        Pace.within Pace.all_live (fun () ->
            Atomic.set second_in true;
            Domain.join first;
            overhead ())
      in
      Alcotest.(check int)
        "the second still at the all-live pace once the first returned" Pace.all_live
        after_first;
      Alcotest.(check int) "set back once both returned" 77 (overhead ()))

let () =
  Alcotest.run "gathered"
    [
      ( "gathered",
        [
          seeded made_again;
          Alcotest.test_case "what is shared stays shared" `Quick shares;
          Alcotest.test_case "blocks of floats filled and freed" `Quick many;
          Alcotest.test_case "a stream discarded" `Quick discards;
          Alcotest.test_case "the collector's pace set back" `Quick pace;
          Alcotest.test_case "the pace on two domains at once" `Quick pace_domains;
        ] );
    ]
