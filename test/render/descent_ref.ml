(* The descent in its plain form: each box's entry t by six slabs, each bound a typed
   comparison (a NaN from 0·inf leaves the interval open), the nearer child met next and
   the farther pushed with its entry t. *)
module Bvh = Lancer_render.Bvh
module Probe = Lancer_math.Probe

let fget = Float.Array.get

let box_entry nodes k (q : Probe.t) nx ny nz tmin tmax =
  let off = 8 * k in
  let slab n o i t0 t1 =
    let a = (fget nodes (off + n) -. o) *. i
    and c = (fget nodes (off + if n < 3 then n + 3 else n - 3) -. o) *. i in
    ((if a > t0 then a else t0), if c < t1 then c else t1)
  in
  let t0, t1 = slab nx q.ox q.ix tmin tmax in
  let t0, t1 = slab ny q.oy q.iy t0 t1 in
  let t0, t1 = slab nz q.oz q.iz t0 t1 in
  if t0 <= t1 then t0 else Float.infinity

let near i = if i < 0. then 3 else 0

let next_leaf nodes (q : Probe.t) (st : Bvh.walk) =
  let nx = near q.ix and ny = 1 + near q.iy and nz = 2 + near q.iz in
  let tmin = fget st.span 0 and best = fget st.span 1 in
  let push k t =
    st.ids.(st.sp) <- k;
    Float.Array.set st.ts st.sp t;
    st.sp <- st.sp + 1
  in
  let rec pop () =
    if st.sp = 0 then -1
    else (
      st.sp <- st.sp - 1;
      if fget st.ts st.sp <= best then st.ids.(st.sp) else pop ())
  in
  let rec go k =
    if k < 0 then -1
    else if Bvh.count nodes k > 0 then k
    else
      let l = k + 1 and r = Bvh.link nodes k in
      let tl = box_entry nodes l q nx ny nz tmin best
      and tr = box_entry nodes r q nx ny nz tmin best in
      match (tl < Float.infinity, tr < Float.infinity) with
      | true, true ->
          if tr < tl then (
            push l tl;
            go r)
          else (
            push r tr;
            go l)
      | true, false -> go l
      | false, true -> go r
      | false, false -> go (pop ())
  in
  go (pop ())

let start nodes (q : Probe.t) (st : Bvh.walk) tmin tmax =
  st.sp <- 0;
  Float.Array.set st.span 0 tmin;
  Float.Array.set st.span 1 tmax;
  let t = box_entry nodes 0 q (near q.ix) (1 + near q.iy) (2 + near q.iz) tmin tmax in
  if t < Float.infinity then (
    st.ids.(0) <- 0;
    Float.Array.set st.ts 0 t;
    st.sp <- 1;
    next_leaf nodes q st)
  else -1
