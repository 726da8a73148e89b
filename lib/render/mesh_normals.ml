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
    let out = Tri_builder.floats 3 in
    Tri_builder.(out.fl <- Float.Array.copy nrm);
    out.len <- Float.Array.length nrm / 3;
    let tn' = Trimesh.ints (3 * count) in
    if has then Bigarray.Array1.blit tn tn' else Bigarray.Array1.fill tn' (-1l);
    for v = 0 to nv - 1 do
      (* The normals computed at this vertex so far start here: a corner whose average
         is one of them, to the bit, shares it. *)
      let first = out.len in
      for p = start.(v) to start.(v + 1) - 1 do
        let corner = iget around p in
        let k = corner / 3 in
        if missing k then (
          let fx = fget fn (3 * k)
          and fy = fget fn ((3 * k) + 1)
          and fz = fget fn ((3 * k) + 2) in
          let sx = ref 0. and sy = ref 0. and sz = ref 0. in
          for p' = start.(v) to start.(v + 1) - 1 do
            let c' = iget around p' in
            let k' = c' / 3 in
            let gx = fget fn (3 * k')
            and gy = fget fn ((3 * k') + 1)
            and gz = fget fn ((3 * k') + 2) in
            if (fx *. gx) +. (fy *. gy) +. (fz *. gz) >= cos_crease then (
              let w = fget ang c' in
              sx := !sx +. (w *. gx);
              sy := !sy +. (w *. gy);
              sz := !sz +. (w *. gz))
          done;
          let l = Vec3.length3 !sx !sy !sz in
          (* The corner's own face is always in its sum; a sum that still vanishes (a
             face of no angle) falls back to the face's normal. *)
          let nx, ny, nz =
            if l > 0. then (!sx /. l, !sy /. l, !sz /. l) else (fx, fy, fz)
          in
          let same = ref (-1) and q = ref first in
          while !same < 0 && !q < out.len do
            let o = 3 * !q in
            if
              Float.equal (fget out.fl o) nx
              && Float.equal (fget out.fl (o + 1)) ny
              && Float.equal (fget out.fl (o + 2)) nz
            then same := !q;
            incr q
          done;
          let index =
            if !same >= 0 then !same
            else (
              Tri_builder.push3 out nx ny nz;
              out.len - 1)
          in
          iset tn' corner index)
      done
    done;
    (Tri_builder.trimmed_floats out, tn', !n_missing)

let mesh ~smooth ~pos ~nrm ~tex ~tv ~tn ~tt =
  if smooth then
    let nrm, tn, computed = complete ~pos ~nrm ~tv ~tn () in
    Trimesh.make ~computed ~pos ~nrm ~tex ~tv ~tn ~tt ()
  else Trimesh.make ~pos ~nrm ~tex ~tv ~tn ~tt ()
