let fget = Float.Array.unsafe_get
let fset = Float.Array.unsafe_set
let[@inline] iget (a : Trimesh.ints) i = Int32.to_int (Bigarray.Array1.unsafe_get a i)
let[@inline] iset (a : Trimesh.ints) i x = Bigarray.Array1.unsafe_set a i (Int32.of_int x)

(* The unit normal of each triangle into [fn] (3 floats each), and the angle at each of
   its corners into [ang] (1 float per corner): atan2(|u × w|, u·w) of the two edges
   leaving the corner, accurate at every angle. *)
let faces_into pos tv fn ang count =
  let cross_len ux uy uz wx wy wz =
    Vec3.length3
      ((uy *. wz) -. (uz *. wy))
      ((uz *. wx) -. (ux *. wz))
      ((ux *. wy) -. (uy *. wx))
  in
  let angle ux uy uz wx wy wz =
    Float.atan2 (cross_len ux uy uz wx wy wz) ((ux *. wx) +. (uy *. wy) +. (uz *. wz))
  in
  for k = 0 to count - 1 do
    let a = 3 * iget tv (3 * k)
    and b = 3 * iget tv ((3 * k) + 1)
    and c = 3 * iget tv ((3 * k) + 2) in
    let ax = fget pos a and ay = fget pos (a + 1) and az = fget pos (a + 2) in
    let bx = fget pos b and by = fget pos (b + 1) and bz = fget pos (b + 2) in
    let cx = fget pos c and cy = fget pos (c + 1) and cz = fget pos (c + 2) in
    let abx = bx -. ax and aby = by -. ay and abz = bz -. az in
    let acx = cx -. ax and acy = cy -. ay and acz = cz -. az in
    let nx = (aby *. acz) -. (abz *. acy)
    and ny = (abz *. acx) -. (abx *. acz)
    and nz = (abx *. acy) -. (aby *. acx) in
    let l = Vec3.length3 nx ny nz in
    let s = if l > 0. then 1. /. l else 0. in
    fset fn (3 * k) (s *. nx);
    fset fn ((3 * k) + 1) (s *. ny);
    fset fn ((3 * k) + 2) (s *. nz);
    fset ang (3 * k) (angle abx aby abz acx acy acz);
    fset ang
      ((3 * k) + 1)
      (angle (cx -. bx) (cy -. by) (cz -. bz) (-.abx) (-.aby) (-.abz));
    fset ang
      ((3 * k) + 2)
      (angle (-.acx) (-.acy) (-.acz) (bx -. cx) (by -. cy) (bz -. cz))
  done

(* The corners around each vertex: those of vertex v are
   [around.(start.(v)) .. around.(start.(v + 1) − 1)], corner 3k + j being corner j of
   triangle k, in increasing order. *)
let corners_around tv nv count =
  let start = Array.make (nv + 1) 0 in
  for i = 0 to (3 * count) - 1 do
    let v = iget tv i in
    start.(v + 1) <- start.(v + 1) + 1
  done;
  for v = 1 to nv do
    start.(v) <- start.(v) + start.(v - 1)
  done;
  let around = Trimesh.ints (3 * count) and next = Array.sub start 0 nv in
  for i = 0 to (3 * count) - 1 do
    let v = iget tv i in
    iset around next.(v) i;
    next.(v) <- next.(v) + 1
  done;
  (start, around)

(* Union–find over the corners around one vertex (local indices), with path halving. *)
let rec find parent i =
  let p = parent.(i) in
  if p = i then i
  else (
    parent.(i) <- parent.(p);
    find parent parent.(i))

(* [keys.(0) .. keys.(n − 1)] in increasing order (distinct integers, so any sort gives
   the same order): by insertion where they are few, as around almost every vertex of a
   mesh (12 keys around a vertex of six faces), else by [Array.sort]. *)
let sort_prefix keys n =
  if n <= 32 then
    for i = 1 to n - 1 do
      let x = Array.unsafe_get keys i in
      let j = ref (i - 1) in
      while !j >= 0 && Array.unsafe_get keys !j > x do
        Array.unsafe_set keys (!j + 1) (Array.unsafe_get keys !j);
        decr j
      done;
      Array.unsafe_set keys (!j + 1) x
    done
  else
    let a = Array.sub keys 0 n in
    Array.sort Int.compare a;
    Array.blit a 0 keys 0 n

let complete ?(crease = Description.crease) ~pos ~nrm ~tv ~tn () =
  let count = Bigarray.Array1.dim tv / 3 in
  let has = Bigarray.Array1.dim tn > 0 in
  let missing k = (not has) || iget tn (3 * k) < 0 in
  let n_missing = ref 0 in
  for k = 0 to count - 1 do
    if missing k then incr n_missing
  done;
  if !n_missing = 0 then (nrm, tn, 0)
  else
    let nv = Float.Array.length pos / 3 in
    let fn = Float.Array.create (3 * count) and ang = Float.Array.create (3 * count) in
    faces_into pos tv fn ang count;
    let start, around = corners_around tv nv count in
    let cos_crease = Float.cos (crease *. Float.pi /. 180.) in
    let within k k' =
      (fget fn (3 * k) *. fget fn (3 * k'))
      +. (fget fn ((3 * k) + 1) *. fget fn ((3 * k') + 1))
      +. (fget fn ((3 * k) + 2) *. fget fn ((3 * k') + 2))
      >= cos_crease
    in
    let out = Tri_builder.floats 3 in
    Tri_builder.(out.fl <- Float.Array.copy nrm);
    out.len <- Float.Array.length nrm / 3;
    let tn' = Trimesh.ints (3 * count) in
    if has then Bigarray.Array1.blit tn tn' else Bigarray.Array1.fill tn' (-1l);
    (* Scratch for the corners around one vertex, as large as the most there are. *)
    let most = ref 0 in
    for v = 0 to nv - 1 do
      most := max !most (start.(v + 1) - start.(v))
    done;
    let parent = Array.make !most 0
    and index = Array.make !most (-1)
    and sums = Float.Array.make (3 * !most) 0.
    and keys = Array.make (2 * !most) 0 in
    for v = 0 to nv - 1 do
      let first = start.(v) and d = start.(v + 1) - start.(v) in
      let face i = iget around (first + i) / 3 in
      (* The faces around v that share an edge from v (the same other vertex) and meet
         within the crease are one smooth group: each corner's edges as keys
         (other vertex, corner), sorted, so that the faces of an edge are neighbours. *)
      for i = 0 to d - 1 do
        let c = iget around (first + i) in
        let k = c / 3 and j = c mod 3 in
        let other o = iget tv ((3 * k) + ((j + o) mod 3)) in
        keys.(2 * i) <- (other 1 lsl 31) lor i;
        keys.((2 * i) + 1) <- (other 2 lsl 31) lor i;
        parent.(i) <- i;
        index.(i) <- -1
      done;
      sort_prefix keys (2 * d);
      let mask = (1 lsl 31) - 1 in
      for e = 1 to (2 * d) - 1 do
        let a = keys.(e - 1) and b = keys.(e) in
        if a lsr 31 = b lsr 31 then
          let i = a land mask and i' = b land mask in
          if within (face i) (face i') then parent.(find parent i) <- find parent i'
      done;
      (* Each group's angle-weighted sum of its faces' normals, in the corners' order. *)
      for i = 0 to d - 1 do
        let r = find parent i in
        if r = i then (
          Float.Array.set sums (3 * i) 0.;
          Float.Array.set sums ((3 * i) + 1) 0.;
          Float.Array.set sums ((3 * i) + 2) 0.)
      done;
      for i = 0 to d - 1 do
        let r = 3 * find parent i and k = face i in
        let w = fget ang (iget around (first + i)) in
        for x = 0 to 2 do
          fset sums (r + x) (fget sums (r + x) +. (w *. fget fn ((3 * k) + x)))
        done
      done;
      (* One normal per group, given to the corners of its faces that have none. *)
      for i = 0 to d - 1 do
        let k = face i in
        if missing k then (
          let r = find parent i in
          if index.(r) < 0 then (
            let sx = fget sums (3 * r)
            and sy = fget sums ((3 * r) + 1)
            and sz = fget sums ((3 * r) + 2) in
            let l = Vec3.length3 sx sy sz in
            (* A group's sum includes its own faces' normals, weighted by angles in
               (0, π): it vanishes only for faces of no angle, which keep their own. *)
            if l > 0. then Tri_builder.push3 out (sx /. l) (sy /. l) (sz /. l)
            else
              Tri_builder.push3 out
                (fget fn (3 * k))
                (fget fn ((3 * k) + 1))
                (fget fn ((3 * k) + 2));
            index.(r) <- out.len - 1);
          iset tn' (iget around (first + i)) index.(r))
      done
    done;
    (Tri_builder.trimmed_floats out, tn', !n_missing)

let build ~smooth (m : Tri_builder.mesh) =
  let { Tri_builder.pos; nrm; tex; tv; tn; tt } = m in
  if smooth then
    let nrm, tn, computed = complete ~pos ~nrm ~tv ~tn () in
    Trimesh.make ~computed ~pos ~nrm ~tex ~tv ~tn ~tt ()
  else Trimesh.make ~pos ~nrm ~tex ~tv ~tn ~tt ()
