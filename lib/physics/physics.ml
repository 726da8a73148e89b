(* Newtonian motion of spheres: an event-driven exact integrator and two fixed-step ones.
   See physics.mli for the model, the resting rule and the fixed-step collision handling. *)

module V = Vec3

type body = Description.body = {
  name : string;
  center : V.t;
  radius : float;
  velocity : V.t;
  mass : float;
  restitution : float;
  loc : Loc.t;
}

let body ?(velocity = V.zero) ?(mass = 1.) ?(restitution = 1.) ?loc ~name ~center ~radius
    () =
  let loc = match loc with Some l -> l | None -> Loc.whole_file name in
  { name; center; radius; velocity; mass; restitution; loc }

type collider =
  | Plane of { normal : V.t; offset : float }
  | Parallelogram of { origin : V.t; edge1 : V.t; edge2 : V.t }
  | Box of { min : V.t; max : V.t }

type method_ = Description.physics_method = Exact | Verlet | Euler
type world = Description.physics = { gravity : V.t; method_ : method_; step : float }

let default_world = Description.default_physics

(* ---------------------------------------------------------------------------------- *)
(* Obstacles from a scene's description *)

module D = Description

let is_axis_aligned tr =
  let count (v : Vec3.t) =
    Bool.to_int (v.x <> 0.) + Bool.to_int (v.y <> 0.) + Bool.to_int (v.z <> 0.)
  in
  List.for_all
    (fun v -> count (Transform.vector tr v) = 1)
    [ Vec3.v 1. 0. 0.; Vec3.v 0. 1. 0.; Vec3.v 0. 0. 1. ]

(* A shape of the description placed in the world by [tr], as an obstacle. *)
let collider_of tr (shape : D.shape) =
  match shape with
  | D.Plane { normal; offset } ->
      let normal = Vec3.normalize normal in
      let n = Transform.normal tr normal
      and p = Transform.point tr (Vec3.smul offset normal) in
      [ Plane { normal = n; offset = Vec3.dot n p } ]
  | D.Parallelogram { origin; edge1; edge2 } ->
      [
        Parallelogram
          {
            origin = Transform.point tr origin;
            edge1 = Transform.vector tr edge1;
            edge2 = Transform.vector tr edge2;
          };
      ]
  | D.Box { min = a; max = b } when is_axis_aligned tr ->
      let p = Transform.point tr a and q = Transform.point tr b in
      [ Box { min = Vec3.min p q; max = Vec3.max p q } ]
  | D.Box { min = a; max = b } ->
      (* A rotated box: its six faces. *)
      let pt x y z = Transform.point tr (Vec3.v x y z) in
      let face o u v =
        Parallelogram { origin = o; edge1 = Vec3.sub u o; edge2 = Vec3.sub v o }
      in
      let c000 = pt a.x a.y a.z
      and c100 = pt b.x a.y a.z
      and c010 = pt a.x b.y a.z
      and c001 = pt a.x a.y b.z in
      let c111 = pt b.x b.y b.z
      and c011 = pt a.x b.y b.z
      and c101 = pt b.x a.y b.z
      and c110 = pt b.x b.y a.z in
      [
        face c000 c100 c010;
        face c000 c010 c001;
        face c000 c001 c100;
        face c111 c011 c101;
        face c111 c101 c110;
        face c111 c110 c011;
      ]
  | _ -> []

(* A CSG object collides exactly as its members only when its surface is every member's
   surface (a union, or a merge, whose faces a body outside meets first anyway) and each
   member is a collider (plane, parallelogram, box). *)
let rec exact_csg (s : D.shape) =
  match s with
  | D.Csg { op = Union | Merge; members; _ } ->
      List.for_all (fun (m : D.obj) -> exact_csg m.shape) members
  | D.Csg _ -> false
  | D.Plane _ | D.Parallelogram _ | D.Box _ -> true
  | _ -> false

(* The simple surfaces of a CSG object's members, each with the transform that places it
   in the object's space (composed as the renderer composes its leaves). *)
let rec leaves (s : D.shape) =
  match s with
  | D.Csg { members; _ } ->
      List.concat_map
        (fun (m : D.obj) ->
          match m.shape with
          | D.Csg _ ->
              List.map
                (fun (sh, tr) -> (sh, Transform.then_ tr m.transform))
                (leaves m.shape)
          | sh -> [ (sh, m.transform) ])
        members
  | sh -> [ (sh, Transform.identity) ]

exception Not_exact of D.obj

let colliders objects =
  match
    List.concat_map
      (fun (o : D.obj) ->
        match o.shape with
        | _ when o.body <> None -> []
        | D.Csg _ when exact_csg o.shape ->
            List.concat_map
              (fun (sh, tr) -> collider_of (Transform.then_ tr o.transform) sh)
              (leaves o.shape)
        | D.Csg _ -> raise (Not_exact o)
        | sh -> collider_of o.transform sh)
      objects
  with
  | cs -> Ok cs
  | exception Not_exact o -> Error o

type target = Collider of int | Body of string
type kind = Bounce | Rest | Leave
type event = { time : float; body : string; target : target; kind : kind; speed : float }

(* One piece of closed-form motion: p(τ) = p0 + v0·τ + ½·acc·τ², τ = t − t0. *)
type seg = { t0 : float; p0 : V.t; v0 : V.t; acc : V.t }

type track =
  | Segments of seg array (* Exact: sorted by t0, the first at t0 = 0 *)
  | Steps of { dt : float; ps : V.t array; vs : V.t array; gravity : V.t }
(* fixed step: the state at k·dt *)

type trajectory = {
  names : string array;
  tracks : track array;
  events : event list;
  until : float;
  truncated : bool;
}

let rest_fraction = 1e-4
let max_events = 100_000
let names tr = Array.to_list tr.names
let events tr = tr.events
let until tr = tr.until
let truncated tr = tr.truncated

(* ---------- Polynomials: c.(k) is the coefficient of τ^k ---------- *)

let eval c x =
  let r = ref 0. in
  for k = Array.length c - 1 downto 0 do
    r := (!r *. x) +. c.(k)
  done;
  !r

let deriv c =
  Array.init (Int.max 0 (Array.length c - 1)) (fun k -> float (k + 1) *. c.(k + 1))

let degree c =
  let d = ref (Array.length c - 1) in
  while !d >= 0 && c.(!d) = 0. do
    decr d
  done;
  !d

(* Real roots of a·x² + b·x + c, stable form: q = −½(b + sign(b)·√Δ), roots q/a and c/q. *)
let quadratic_roots a b c =
  if a = 0. then if b = 0. then [] else [ -.c /. b ]
  else
    let disc = (b *. b) -. (4. *. a *. c) in
    if disc < 0. then []
    else
      let q = -0.5 *. (b +. Float.copy_sign (Float.sqrt disc) b) in
      if q = 0. then [ 0. ]
      else
        let r0 = q /. a and r1 = c /. q in
        if r0 <= r1 then [ r0; r1 ] else [ r1; r0 ]

(* Bisection on a bracketed sign change; stops when the midpoint is no longer strictly
   inside, so the result is as good as doubles allow and depends only on the bracket. *)
let bisect c lo hi =
  let flo = eval c lo in
  let rec go lo hi flo n =
    let mid = 0.5 *. (lo +. hi) in
    if n = 0 || mid <= lo || mid >= hi then mid
    else
      let fm = eval c mid in
      if fm = 0. then mid
      else if fm < 0. = (flo < 0.) then go mid hi fm (n - 1)
      else go lo mid flo (n - 1)
  in
  go lo hi flo 200

(* Sorted real roots of the polynomial in [lo, hi]. Degree ≤ 2 in closed form; higher
   degrees split [lo, hi] at the roots of the derivative (where the polynomial is
   monotone) and bisect each interval that changes sign. *)
let rec roots_in c lo hi =
  let inside x = x >= lo && x <= hi in
  match degree c with
  | d when d <= 0 -> []
  | 1 -> List.filter inside [ -.c.(0) /. c.(1) ]
  | 2 -> List.filter inside (quadratic_roots c.(2) c.(1) c.(0))
  | _ ->
      let pts = (lo :: roots_in (deriv c) lo hi) @ [ hi ] in
      let rec scan acc = function
        | x0 :: (x1 :: _ as rest) ->
            let f0 = eval c x0 and f1 = eval c x1 in
            let acc = if f0 = 0. then x0 :: acc else acc in
            let acc =
              if f0 <> 0. && f1 <> 0. && f0 < 0. <> (f1 < 0.) then bisect c x0 x1 :: acc
              else acc
            in
            scan acc rest
        | [ x ] -> if eval c x = 0. then x :: acc else acc
        | [] -> acc
      in
      List.sort_uniq Float.compare (scan [] pts)

(* |D + W·τ + ½·A·τ²|² − R², as coefficients. *)
let dist2_poly d w a r =
  [|
    V.dot d d -. (r *. r);
    2. *. V.dot d w;
    V.dot w w +. V.dot d a;
    V.dot w a;
    0.25 *. V.dot a a;
  |]

(* ---------- Features of the static colliders ---------- *)

type feature =
  | Face of {
      n : V.t; (* unit normal *)
      d : float; (* n·P = d *)
      finite : bool;
      origin : V.t;
      alpha : V.t; (* u = alpha·(P − origin) *)
      beta : V.t; (* v = beta·(P − origin) *)
      owner : int;
    }
  | Edge of { a : V.t; u : V.t; len : float; owner : int } (* capsule around a segment *)
  | Corner of { c : V.t; owner : int }

let owner = function Face f -> f.owner | Edge e -> e.owner | Corner c -> c.owner

let face_of owner origin e1 e2 =
  let nn = V.cross e1 e2 in
  let nn2 = V.dot nn nn in
  let n = V.normalize nn in
  Face
    {
      n;
      d = V.dot n origin;
      finite = true;
      origin;
      alpha = V.smul (1. /. nn2) (V.cross e2 nn);
      beta = V.smul (1. /. nn2) (V.cross nn e1);
      owner;
    }

let edge_of owner a b =
  let e = V.sub b a in
  Edge { a; u = V.normalize e; len = V.length e; owner }

let features_of i = function
  | Plane { normal; offset } ->
      let n = V.normalize normal in
      [
        Face
          {
            n;
            d = offset;
            finite = false;
            origin = V.zero;
            alpha = V.zero;
            beta = V.zero;
            owner = i;
          };
      ]
  | Parallelogram { origin; edge1; edge2 } ->
      let p1 = V.add origin edge1 and p2 = V.add origin edge2 in
      let p12 = V.add p1 edge2 in
      [
        face_of i origin edge1 edge2;
        edge_of i origin p1;
        edge_of i origin p2;
        edge_of i p1 p12;
        edge_of i p2 p12;
        Corner { c = origin; owner = i };
        Corner { c = p1; owner = i };
        Corner { c = p2; owner = i };
        Corner { c = p12; owner = i };
      ]
  | Box { min = lo; max = hi } ->
      let ex = V.v (hi.x -. lo.x) 0. 0.
      and ey = V.v 0. (hi.y -. lo.y) 0.
      and ez = V.v 0. 0. (hi.z -. lo.z) in
      let corner bx by bz =
        V.v
          (if bx then hi.x else lo.x)
          (if by then hi.y else lo.y)
          (if bz then hi.z else lo.z)
      in
      let faces =
        [
          face_of i lo ey ez;
          face_of i (V.add lo ex) ey ez;
          face_of i lo ex ez;
          face_of i (V.add lo ey) ex ez;
          face_of i lo ex ey;
          face_of i (V.add lo ez) ex ey;
        ]
      in
      let bools = [ false; true ] in
      let edges =
        List.concat_map
          (fun b1 ->
            List.concat_map
              (fun b2 ->
                [
                  edge_of i (corner false b1 b2) (corner true b1 b2);
                  edge_of i (corner b1 false b2) (corner b1 true b2);
                  edge_of i (corner b1 b2 false) (corner b1 b2 true);
                ])
              bools)
          bools
      in
      let corners =
        List.concat_map
          (fun bx ->
            List.concat_map
              (fun by ->
                List.map (fun bz -> Corner { c = corner bx by bz; owner = i }) bools)
              bools)
          bools
      in
      faces @ edges @ corners

let in_face alpha beta origin p =
  let q = V.sub p origin in
  let u = V.dot alpha q and v = V.dot beta q in
  u >= 0. && u <= 1. && v >= 0. && v <= 1.

(* ---------- Exact, event-driven ---------- *)

let pos s tau = V.add s.p0 (V.add (V.smul tau s.v0) (V.smul (0.5 *. tau *. tau) s.acc))
let vel s tau = V.madd s.v0 tau s.acc

(* A resting body's constraints: the features it rests on with their outward normals
   (none: flying; one: sliding on a surface; two: sliding along their crease; three: stuck). *)
type constraints = (int * V.t) list

(* [project cons x] is the part of x free under the constraints. *)
let project (cons : constraints) x =
  match cons with
  | [] -> x
  | [ (_, n) ] -> V.madd x (-.V.dot x n) n
  | [ (_, n1); (_, n2) ] ->
      let c = V.cross n1 n2 in
      let l = V.length c in
      if l < 1e-9 then V.madd x (-.V.dot x n1) n1
      else
        let d = V.smul (1. /. l) c in
        V.smul (V.dot x d) d
  | _ -> V.zero

type action =
  | Hit of { feature : int; side : float } (* side: ±1 for faces, unused otherwise *)
  | Leave_face of int
  | Hit_body of int

type cand = { at : float; tau : float; action : action }

(* The earliest τ in [0, horizon] at which the gap polynomial [c] enters contact (a root
   where the gap decreases faster than [min_slope], so grazing touches are not impacts)
   and [valid] holds. τ = 0 when the body already overlaps and approaches, or, with
   [settle] (faces), when it touches with no speed but accelerates into the surface: a
   body placed at rest on a floor. *)
let first_contact ?(settle = false) c ~overlapping ~min_slope ~horizon valid =
  let dc = deriv c in
  let slope0 = eval dc 0. in
  if
    overlapping && valid 0.
    && (slope0 < -.min_slope || (settle && slope0 <= min_slope && eval (deriv dc) 0. < 0.))
  then Some 0.
  else
    List.find_opt
      (fun tau -> tau > 0. && eval dc tau < -.min_slope && valid tau)
      (roots_in c 0. horizon)

(* Approach speeds below this (m/s) are grazing touches, not impacts. *)
let min_speed = 1e-9
let perp u x = V.madd x (-.V.dot x u) u

let static_contact feats (b : body) seg (cons : constraints) horizon =
  let best = ref None in
  let consider tau action =
    match !best with Some (t, _) when t <= tau -> () | _ -> best := Some (tau, action)
  in
  Array.iteri
    (fun fi f ->
      if not (List.mem_assoc fi cons) then
        match f with
        | Face { n; d; finite; origin; alpha; beta; _ } ->
            let s0 = V.dot n seg.p0 -. d
            and sv = V.dot n seg.v0
            and sa = V.dot n seg.acc in
            let valid tau = (not finite) || in_face alpha beta origin (pos seg tau) in
            List.iter
              (fun side ->
                let c = [| (side *. s0) -. b.radius; side *. sv; 0.5 *. side *. sa |] in
                let overlapping = side *. s0 >= 0. && side *. s0 <= b.radius in
                match
                  first_contact ~settle:true c ~overlapping ~min_slope:min_speed ~horizon
                    valid
                with
                | Some tau -> consider tau (Hit { feature = fi; side })
                | None -> ())
              [ 1.; -1. ]
        | Edge { a; u; len; _ } ->
            let d = V.sub seg.p0 a in
            let c = dist2_poly (perp u d) (perp u seg.v0) (perp u seg.acc) b.radius in
            let valid tau =
              let t = V.dot (V.sub (pos seg tau) a) u in
              t >= 0. && t <= len
            in
            Option.iter
              (fun tau -> consider tau (Hit { feature = fi; side = 1. }))
              (first_contact c
                 ~overlapping:(c.(0) <= 0.)
                 ~min_slope:(2. *. b.radius *. min_speed)
                 ~horizon valid)
        | Corner { c = p; _ } ->
            let c = dist2_poly (V.sub seg.p0 p) seg.v0 seg.acc b.radius in
            Option.iter
              (fun tau -> consider tau (Hit { feature = fi; side = 1. }))
              (first_contact c
                 ~overlapping:(c.(0) <= 0.)
                 ~min_slope:(2. *. b.radius *. min_speed)
                 ~horizon
                 (fun _ -> true)))
    feats;
  (* A body resting on a finite face leaves it when its centre crosses the border. *)
  List.iter
    (fun (feature, _) ->
      match feats.(feature) with
      | Face { finite = true; origin; alpha; beta; _ } ->
          let q0 = V.sub seg.p0 origin in
          List.iter
            (fun (w, bound, dir) ->
              let c = [| V.dot w q0 -. bound; V.dot w seg.v0; 0.5 *. V.dot w seg.acc |] in
              let dc = deriv c in
              match
                List.find_opt
                  (fun tau -> tau > 0. && dir *. eval dc tau > 0.)
                  (roots_in c 0. horizon)
              with
              | Some tau -> consider tau (Leave_face feature)
              | None -> ())
            [ (alpha, 0., -1.); (alpha, 1., 1.); (beta, 0., -1.); (beta, 1., 1.) ]
      | _ -> ())
    cons;
  Option.map (fun (tau, action) -> { at = seg.t0 +. tau; tau; action }) !best

let pair_contact (bi : body) (bj : body) si sj j horizon_end =
  let tb = Float.max si.t0 sj.t0 in
  let ti = tb -. si.t0 and tj = tb -. sj.t0 in
  let d = V.sub (pos sj tj) (pos si ti) and w = V.sub (vel sj tj) (vel si ti) in
  let a = V.sub sj.acc si.acc in
  let c = dist2_poly d w a (bi.radius +. bj.radius) in
  let min_slope = 2. *. (bi.radius +. bj.radius) *. min_speed in
  match
    first_contact c
      ~overlapping:(c.(0) <= 0.)
      ~min_slope ~horizon:(horizon_end -. tb)
      (fun _ -> true)
  with
  | Some tau -> Some { at = tb +. tau; tau; action = Hit_body j }
  | None -> None

let validate world bodies =
  if not (world.step > 0.) then invalid_arg "Physics.simulate: step must be > 0";
  List.iteri
    (fun i (b : body) ->
      if not (b.radius > 0.) then
        invalid_arg ("Physics.simulate: radius of " ^ b.name ^ " must be > 0");
      if not (b.mass > 0.) then
        invalid_arg ("Physics.simulate: mass of " ^ b.name ^ " must be > 0");
      if not (b.restitution >= 0. && b.restitution <= 1.) then
        invalid_arg ("Physics.simulate: restitution of " ^ b.name ^ " must be in [0, 1]");
      List.iteri
        (fun j (c : body) ->
          if j < i && String.equal c.name b.name then
            invalid_arg ("Physics.simulate: two bodies are named " ^ b.name))
        bodies)
    bodies

(* Whether a rebound of normal speed [vout] off a surface with outward normal [n] rises
   less than rest_fraction·r under the acceleration [a] (which must point into it). *)
let below_rest a (b : body) n vout =
  let an = V.dot a n in
  an < 0. && vout *. vout < 2. *. -.an *. rest_fraction *. b.radius

(* Whether a normal speed is too small to lift off or bounce off a support: the same
   threshold with the full gravity as the scale. *)
let slow g (b : body) vn = vn *. vn < 2. *. V.length g *. rest_fraction *. b.radius

let simulate_exact world feats (bodies : body array) ~until =
  let g = world.gravity in
  let nb = Array.length bodies in
  let segs =
    Array.map
      (fun (b : body) -> [ { t0 = 0.; p0 = b.center; v0 = b.velocity; acc = g } ])
      bodies
  in
  let cur i = List.hd segs.(i) in
  let cons = Array.make nb ([] : constraints) in
  let static_c = Array.make nb None and static_dirty = Array.make nb true in
  let pair_c = Array.make_matrix nb nb None
  and pair_dirty = Array.make_matrix nb nb true in
  let evs = ref [] and count = ref 0 in
  let set_state i t p v =
    let acc = project cons.(i) g in
    segs.(i) <- { t0 = t; p0 = p; v0 = v; acc } :: segs.(i);
    static_dirty.(i) <- true;
    for j = 0 to nb - 1 do
      pair_dirty.(i).(j) <- true;
      pair_dirty.(j).(i) <- true
    done
  in
  (* A resting body given a new velocity: it lifts off, bounces off, or stays on each of
     its supports, and keeps the velocity its remaining constraints allow. *)
  let settle i v =
    let b = bodies.(i) in
    let v = ref v and kept = ref [] in
    List.iter
      (fun (f, n) ->
        let vn = V.dot !v n in
        if vn > 0. && not (slow g b vn) then ()
        else if vn < 0. && not (slow g b (b.restitution *. vn)) then
          v := V.madd !v (-.(1. +. b.restitution) *. vn) n
        else kept := (f, n) :: !kept)
      cons.(i);
    cons.(i) <- List.rev !kept;
    project cons.(i) !v
  in
  let truncated = ref false in
  let rec loop () =
    for i = 0 to nb - 1 do
      if static_dirty.(i) then (
        let s = cur i in
        static_c.(i) <-
          static_contact feats bodies.(i) s cons.(i) (Float.max 0. (until -. s.t0));
        static_dirty.(i) <- false);
      for j = i + 1 to nb - 1 do
        if pair_dirty.(i).(j) then (
          pair_c.(i).(j) <- pair_contact bodies.(i) bodies.(j) (cur i) (cur j) j until;
          pair_dirty.(i).(j) <- false)
      done
    done;
    let best = ref None in
    let consider i c =
      match (c, !best) with
      | None, _ -> ()
      | Some c, Some (_, b) when b.at <= c.at -> ()
      | Some c, _ -> best := Some (i, c)
    in
    for i = 0 to nb - 1 do
      consider i static_c.(i);
      for j = i + 1 to nb - 1 do
        consider i pair_c.(i).(j)
      done
    done;
    match !best with
    | Some (i, c) when c.at <= until ->
        if !count >= max_events then truncated := true
        else (
          incr count;
          let b = bodies.(i) in
          let s = cur i in
          (match c.action with
          | Leave_face feature ->
              let t = c.at in
              cons.(i) <- List.filter (fun (f, _) -> f <> feature) cons.(i);
              set_state i t (pos s c.tau) (vel s c.tau);
              evs :=
                {
                  time = t;
                  body = b.name;
                  target = Collider (owner feats.(feature));
                  kind = Leave;
                  speed = 0.;
                }
                :: !evs
          | Hit { feature; side } ->
              let t = c.at in
              let p = pos s c.tau and v = vel s c.tau in
              let n =
                match feats.(feature) with
                | Face f -> V.smul side f.n
                | Edge e -> V.normalize (perp e.u (V.sub p e.a))
                | Corner k -> V.normalize (V.sub p k.c)
              in
              let vn = V.dot v n in
              let vout = -.b.restitution *. vn in
              let is_face = match feats.(feature) with Face _ -> true | _ -> false in
              (* The resting rule: a flying body rests on a face, a resting one on any
                 feature its acceleration presses it into (a second support makes a
                 crease to slide along, a third stops it). *)
              let kind, v' =
                if (is_face || cons.(i) <> []) && below_rest s.acc b n vout then (
                  cons.(i) <- cons.(i) @ [ (feature, n) ];
                  (Rest, project cons.(i) v))
                else
                  let v' = settle i (V.madd v (-.(1. +. b.restitution) *. vn) n) in
                  (* A support's constraint can turn the rebound back into this feature
                     (a slope pressing into a wall): it is then a support too. *)
                  if cons.(i) <> [] && V.dot v' n < min_speed then (
                    cons.(i) <- cons.(i) @ [ (feature, n) ];
                    (Rest, project cons.(i) v'))
                  else (Bounce, v')
              in
              set_state i t p v';
              evs :=
                {
                  time = t;
                  body = b.name;
                  target = Collider (owner feats.(feature));
                  kind;
                  speed = -.vn;
                }
                :: !evs
          | Hit_body j ->
              let bj = bodies.(j) in
              let sj = cur j in
              let t = c.at in
              let ti = t -. s.t0 and tj = t -. sj.t0 in
              let pi = pos s ti and vi = vel s ti and pj = pos sj tj and vj = vel sj tj in
              let n = V.normalize (V.sub pj pi) in
              let vrel = V.dot (V.sub vj vi) n in
              let e = b.restitution *. bj.restitution in
              (* A body pressed into its supports by the impulse moves only as they allow
                 (their reaction is part of the impulse): the direction it is pushed in
                 is projected on its free motions, which lowers its effective inverse mass
                 along n; pushed away from a support, it is free (and [settle] lifts it). *)
              let free k dir =
                if List.exists (fun (_, ns) -> V.dot dir ns > 0.) cons.(k) then dir
                else project cons.(k) dir
              in
              let di = free i (V.neg n) and dj = free j n in
              let wi = 1. /. b.mass and wj = 1. /. bj.mass in
              let denom = (wj *. V.dot dj n) -. (wi *. V.dot di n) in
              let jimp = if denom > 0. then -.(1. +. e) *. vrel /. denom else 0. in
              let vi' = settle i (V.madd vi (jimp *. wi) di) in
              let vj' = settle j (V.madd vj (jimp *. wj) dj) in
              set_state i t pi vi';
              set_state j t pj vj';
              evs :=
                {
                  time = t;
                  body = b.name;
                  target = Body bj.name;
                  kind = Bounce;
                  speed = -.vrel;
                }
                :: !evs);
          loop ())
    | _ -> ()
  in
  loop ();
  let tracks = Array.map (fun l -> Segments (Array.of_list (List.rev l))) segs in
  (tracks, List.rev !evs, !truncated)

(* ---------- Fixed step ---------- *)

(* The closest point of a segment [a, b] to p. *)
let closest_on_segment a b p =
  let e = V.sub b a in
  let l2 = V.dot e e in
  let t =
    if l2 = 0. then 0. else Float.min 1. (Float.max 0. (V.dot (V.sub p a) e /. l2))
  in
  V.madd a t e

(* Push a body out of a collider it penetrates; the contact normal if it did. *)
let push_out collider (b : body) p v =
  let r = b.radius in
  let from_point c fallback =
    let d = V.sub p c in
    let l = V.length d in
    if l >= r then None
    else
      let n = if l = 0. then fallback else V.smul (1. /. l) d in
      Some (V.madd c r n, n)
  in
  let side n s = if s > 0. || (s = 0. && V.dot v n <= 0.) then n else V.neg n in
  match collider with
  | Plane { normal; offset } ->
      let n = V.normalize normal in
      let s = V.dot n p -. offset in
      if Float.abs s >= r then None
      else
        let n = side n s in
        Some (V.madd p (r -. Float.abs s) n, n)
  | Parallelogram { origin; edge1; edge2 } ->
      let nn = V.cross edge1 edge2 in
      let nn2 = V.dot nn nn in
      let alpha = V.smul (1. /. nn2) (V.cross edge2 nn)
      and beta = V.smul (1. /. nn2) (V.cross nn edge1) in
      let n = V.normalize nn in
      let s = V.dot n (V.sub p origin) in
      let fallback = side n s in
      if in_face alpha beta origin p then from_point (V.madd p (-.s) n) fallback
      else
        let p1 = V.add origin edge1 and p2 = V.add origin edge2 in
        let p12 = V.add p1 edge2 in
        let cands =
          List.map
            (fun (a, b) -> closest_on_segment a b p)
            [ (origin, p1); (origin, p2); (p1, p12); (p2, p12) ]
        in
        let c =
          List.fold_left
            (fun best c ->
              if V.length2 (V.sub p c) < V.length2 (V.sub p best) then c else best)
            (List.hd cands) (List.tl cands)
        in
        from_point c fallback
  | Box { min = lo; max = hi } ->
      let c = V.min hi (V.max lo p) in
      if not (V.equal_f ~eps:0. c p) then from_point c V.y_axis
      else
        (* Centre inside the box: out through the nearest face. *)
        let faces =
          [
            (p.x -. lo.x, V.neg V.x_axis);
            (hi.x -. p.x, V.x_axis);
            (p.y -. lo.y, V.neg V.y_axis);
            (hi.y -. p.y, V.y_axis);
            (p.z -. lo.z, V.neg V.z_axis);
            (hi.z -. p.z, V.z_axis);
          ]
        in
        let d, n =
          List.fold_left
            (fun (bd, bn) (d, n) -> if d < bd then (d, n) else (bd, bn))
            (List.hd faces) (List.tl faces)
        in
        Some (V.madd p (d +. r) n, n)

let simulate_fixed world colliders (bodies : body array) ~until =
  let g = world.gravity and dt = world.step in
  let nb = Array.length bodies in
  let nsteps =
    if until <= 0. then 0 else int_of_float (Float.ceil ((until /. dt) -. 1e-9))
  in
  let ps = Array.map (fun (b : body) -> Array.make (nsteps + 1) b.center) bodies in
  let vs = Array.map (fun (b : body) -> Array.make (nsteps + 1) b.velocity) bodies in
  let evs = ref [] in
  let p = Array.map (fun (b : body) -> b.center) bodies
  and v = Array.map (fun (b : body) -> b.velocity) bodies in
  for k = 1 to nsteps do
    let t = float k *. dt in
    for i = 0 to nb - 1 do
      match world.method_ with
      | Euler ->
          p.(i) <- V.madd p.(i) dt v.(i);
          v.(i) <- V.madd v.(i) dt g
      | Verlet | Exact ->
          (* velocity Verlet with a constant acceleration *)
          p.(i) <- V.add p.(i) (V.madd (V.smul dt v.(i)) (0.5 *. dt *. dt) g);
          v.(i) <- V.madd v.(i) dt g
    done;
    for i = 0 to nb - 1 do
      let b = bodies.(i) in
      List.iteri
        (fun ci col ->
          match push_out col b p.(i) v.(i) with
          | None -> ()
          | Some (p', n) ->
              p.(i) <- p';
              let vn = V.dot v.(i) n in
              if vn < 0. then (
                v.(i) <- V.madd v.(i) (-.(1. +. b.restitution) *. vn) n;
                evs :=
                  {
                    time = t;
                    body = b.name;
                    target = Collider ci;
                    kind = Bounce;
                    speed = -.vn;
                  }
                  :: !evs))
        colliders
    done;
    for i = 0 to nb - 1 do
      for j = i + 1 to nb - 1 do
        let bi = bodies.(i) and bj = bodies.(j) in
        let d = V.sub p.(j) p.(i) in
        let l = V.length d and rr = bi.radius +. bj.radius in
        if l < rr then (
          let n = if l = 0. then V.x_axis else V.smul (1. /. l) d in
          let wi = 1. /. bi.mass and wj = 1. /. bj.mass in
          let overlap = rr -. l in
          p.(i) <- V.madd p.(i) (-.overlap *. wi /. (wi +. wj)) n;
          p.(j) <- V.madd p.(j) (overlap *. wj /. (wi +. wj)) n;
          let vrel = V.dot (V.sub v.(j) v.(i)) n in
          if vrel < 0. then (
            let jimp =
              -.(1. +. (bi.restitution *. bj.restitution)) *. vrel /. (wi +. wj)
            in
            v.(i) <- V.madd v.(i) (-.jimp *. wi) n;
            v.(j) <- V.madd v.(j) (jimp *. wj) n;
            evs :=
              {
                time = t;
                body = bi.name;
                target = Body bj.name;
                kind = Bounce;
                speed = -.vrel;
              }
              :: !evs))
      done
    done;
    for i = 0 to nb - 1 do
      ps.(i).(k) <- p.(i);
      vs.(i).(k) <- v.(i)
    done
  done;
  let tracks =
    Array.init nb (fun i -> Steps { dt; ps = ps.(i); vs = vs.(i); gravity = g })
  in
  (tracks, List.rev !evs, false)

let simulate world colliders bodies ~until =
  validate world bodies;
  let arr = Array.of_list bodies in
  let tracks, evs, truncated =
    match world.method_ with
    | Exact ->
        let feats = Array.of_list (List.concat (List.mapi features_of colliders)) in
        simulate_exact world feats arr ~until
    | Verlet | Euler -> simulate_fixed world colliders arr ~until
  in
  (* Stable sort: time order, ties in body order as produced. *)
  let evs = List.stable_sort (fun a b -> Float.compare a.time b.time) evs in
  {
    names = Array.map (fun (b : body) -> b.name) arr;
    tracks;
    events = evs;
    until;
    truncated;
  }

(* ---------- Sampling ---------- *)

let sample_segments segs t =
  if t <= 0. then (segs.(0).p0, segs.(0).v0)
  else
    (* the last segment with t0 <= t *)
    let lo = ref 0 and hi = ref (Array.length segs - 1) in
    while !lo < !hi do
      let mid = (!lo + !hi + 1) / 2 in
      if segs.(mid).t0 <= t then lo := mid else hi := mid - 1
    done;
    let s = segs.(!lo) in
    let tau = t -. s.t0 in
    (pos s tau, vel s tau)

let sample_steps dt ps vs g t =
  let n = Array.length ps in
  if t <= 0. || n = 1 then
    if t <= 0. then (ps.(0), vs.(0))
    else
      let s = { t0 = 0.; p0 = ps.(0); v0 = vs.(0); acc = g } in
      (pos s t, vel s t)
  else
    let k =
      int_of_float (Float.min (float (n - 1)) (Float.of_int (truncate (t /. dt))))
    in
    if k >= n - 1 then
      let s = { t0 = float (n - 1) *. dt; p0 = ps.(n - 1); v0 = vs.(n - 1); acc = g } in
      let tau = t -. s.t0 in
      (pos s tau, vel s tau)
    else
      (* cubic Hermite on [k·dt, (k+1)·dt]: exact for constant acceleration *)
      let u = (t -. (float k *. dt)) /. dt in
      let u2 = u *. u in
      let u3 = u2 *. u in
      let h00 = (2. *. u3) -. (3. *. u2) +. 1. and h10 = u3 -. (2. *. u2) +. u in
      let h01 = (-2. *. u3) +. (3. *. u2) and h11 = u3 -. u2 in
      let p0 = ps.(k) and p1 = ps.(k + 1) and v0 = vs.(k) and v1 = vs.(k + 1) in
      let p =
        V.add
          (V.add (V.smul h00 p0) (V.smul (h10 *. dt) v0))
          (V.add (V.smul h01 p1) (V.smul (h11 *. dt) v1))
      in
      (p, V.add (V.smul (1. -. u) v0) (V.smul u v1))

let sample tr name t =
  let rec find i =
    if i >= Array.length tr.names then None
    else if String.equal tr.names.(i) name then Some i
    else find (i + 1)
  in
  match find 0 with
  | None -> None
  | Some i -> (
      match tr.tracks.(i) with
      | Segments segs -> Some (sample_segments segs t)
      | Steps { dt; ps; vs; gravity } -> Some (sample_steps dt ps vs gravity t))
