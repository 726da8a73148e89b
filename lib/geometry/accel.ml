(* A linear scan: every primitive is tested. The bounding volume hierarchy replaces the
   scan for bounded primitives in large scenes. *)
type t = { prims : Primitive.t array }

let build prims = { prims }
let primitives a = a.prims
let uses_bvh _ = false

let nearest a r tmin tmax =
  let best_t = ref tmax and best_i = ref (-1) in
  let prims = a.prims in
  for i = 0 to Array.length prims - 1 do
    let t = Primitive.intersect prims.(i) r tmin !best_t in
    if t < !best_t then begin
      best_t := t;
      best_i := i
    end
  done;
  if !best_i < 0 then (Float.infinity, -1) else (!best_t, !best_i)

let is_black (c : Color.t) = c.r = 0. && c.g = 0. && c.b = 0.

(* Every crossing of one primitive: advance tmin to the last root found; roots are
   recomputed identically each time, so the strict test t > tmin never returns the same
   root twice. *)
let fold_hits a r tmin tmax f acc =
  let acc = ref acc in
  let prims = a.prims in
  let i = ref 0 in
  while !i < Array.length prims && not (is_black !acc) do
    let p = prims.(!i) in
    let t = ref (Primitive.intersect p r tmin tmax) in
    while !t < tmax && not (is_black !acc) do
      acc := f p !t !acc;
      t := Primitive.intersect p r !t tmax
    done;
    incr i
  done;
  !acc
