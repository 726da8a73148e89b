(* A stream's primitives, gathered in order (Compile's stream). Most objects of a large
   scene are spheres placed without a transform, a loop's. Made into primitives as they
   come, each is five blocks (21 words with a colour of its own) that the collector
   marks at every cycle of the load while they pile up: over a million coloured spheres
   that was 2.25 G instructions of marking in 16 cycles, a quarter of the run. Such a
   sphere is held
   instead as floats (its centre, its radius where it changes, its colour where it is its
   own: [Floats], which the collector does not look into) and its material where it
   changes, and made at the end from the same values by {!Primitive.make}: the same
   primitive as the one its object compiled to, which dies young ({!add}) or is never
   made ({!add_sphere}, a sphere handed over by its parts). Any other primitive is kept
   as it is made. *)

(* Primitives in order, in arrays of up to [chunk_size] each (the first ones smaller, for
   a scene of a few objects): none copied as they grow, and each a block the collector
   marks on its own. *)
module Chunks = struct
  let chunk_size = 4096

  type t = {
    mutable full : Primitive.t array list;  (** newest first, each full *)
    mutable last : Primitive.t array;
    mutable n : int;  (** in [last] *)
    mutable total : int;
  }

  let create () = { full = []; last = [||]; n = 0; total = 0 }

  let add t p =
    if t.n = Array.length t.last then (
      if t.n > 0 then t.full <- t.last :: t.full;
      t.last <- Array.make (min chunk_size (max 16 t.total)) p;
      t.n <- 0);
    t.last.(t.n) <- p;
    t.n <- t.n + 1;
    t.total <- t.total + 1

  (* The arrays, oldest first, with how many each holds; [t] is emptied. *)
  let take t =
    let all = List.rev_map (fun c -> (c, Array.length c)) t.full @ [ (t.last, t.n) ] in
    t.full <- [];
    t.last <- [||];
    t.n <- 0;
    t.total <- 0;
    all
end

(* Floats in order, in arrays of up to [chunk_size] each outside the OCaml heap, a group
   of up to [group] never split between two: nothing in them for the collector to follow,
   and each freed as soon as [take] is past it, rather than by three cycles of the
   collector over the primitives made from them. A chunk that is never taken (a load
   that fails) is freed when the collector finds it dead. *)
module Floats = struct
  let chunk_size = 65536
  let group = 7

  type chunk = (float, Bigarray.float64_elt, Bigarray.c_layout) Bigarray.Array1.t

  external create : int -> chunk = "lancer_outside_create"
  external release : chunk -> unit = "lancer_outside_release" [@@noalloc]

  let chunk n =
    let c = create n in
    Gc.finalise release c;
    c

  let empty : chunk = Bigarray.Array1.create Bigarray.float64 Bigarray.c_layout 0

  (* A chunk of [take]'s list freed (never the shared empty one). *)
  let free (c, _) = if c != empty then release c

  type t = {
    mutable full : (chunk * int) list;  (** newest first, with how many each holds *)
    mutable last : chunk;
    mutable n : int;  (** in [last] *)
    mutable total : int;
  }

  let create () = { full = []; last = empty; n = 0; total = 0 }

  (* Room for [k] ≤ [group] floats in [last], at [t.n]. *)
  let room t k =
    if t.n + k > Bigarray.Array1.dim t.last then (
      if t.n > 0 then t.full <- (t.last, t.n) :: t.full;
      t.last <- chunk (min chunk_size (max 64 t.total));
      t.n <- 0)

  (* [k] floats written at [t.n] (after [room t k]) are taken. *)
  let[@inline] advance t k =
    t.n <- t.n + k;
    t.total <- t.total + k

  (* The arrays, oldest first, with how many each holds; [t] is emptied. *)
  let take t =
    let all = List.rev ((t.last, t.n) :: t.full) in
    t.full <- [];
    t.last <- empty;
    t.n <- 0;
    t.total <- 0;
    all
end

type t = {
  move : (Primitive.t -> Primitive.t) option;
  prims : Chunks.t;  (** those not held as floats, moved *)
  floats : Floats.t;
      (** by held sphere: centre, radius, then its colour where it is its own *)
  kinds : Buffer.t;
      (** by primitive, up to the last held sphere: [other] or a held sphere ([sphere]'s
          bits); those after it are [other] (none written where none is held) *)
  mutable count : int;  (** added since the last {!take} *)
  mutable material : Material.t option;  (** the last primitive's *)
  mutable color : Color.t;
      (** the last sphere's (held or kept), where it was not its material's *)
  mutable radius : float;  (** the last sphere's, held or kept *)
}

let create ?move () =
  {
    move;
    prims = Chunks.create ();
    floats = Floats.create ();
    kinds = Buffer.create 16;
    count = 0;
    material = None;
    color = Color.black;
    radius = Float.nan;
  }

let moves t = Option.is_some t.move
let total t = t.count
let held t = t.count - t.prims.total

(* A kind: [other], or [sphere] with its colour and radius bits. A held sphere's
   material is the primitive's before it: a sphere whose material is not is kept as it
   is made. Spheres whose materials all differ (a loop that computes a material's field
   other than its colour) would otherwise each keep their material beside their floats,
   and hold no fewer blocks for the collector to mark. *)
let other = 0
let sphere = 1
let color_material = 0 (* the sphere's colour is its material's *)
let color_last = 2 (* the last held sphere's colour record *)
let color_own = 4 (* its own, in the floats *)
let same_radius = 8 (* the last held sphere's radius, not in the floats *)

(* Whether [p] is what {!Primitive.make} makes of a sphere and its material with no
   transform, and [?color] or not: then made again from those it is the same. *)
let holds (p : Primitive.t) =
  match p.shape with
  | Shape.Sphere _ ->
      p.transform == Transform.identity
      && Option.is_some p.bounds && (not p.extra.flip)
      && Array.length p.extra.leaves = 0
      && p.shift == Vec3.zero
  | _ -> false

let same_material_as t (material : Material.t) =
  match t.material with Some m -> m == material | None -> false

let same_material t (p : Primitive.t) = same_material_as t p.material

(* A held sphere: its floats, its kind. [color] is the sphere's, [own] its material's. *)
let hold t (center : Vec3.t) radius (color : Color.t) (own : Color.t) =
  let c =
    if color == own then color_material
    else if color == t.color then color_last
    else (
      t.color <- color;
      color_own)
  in
  (* Equal radii made again share one float, as a loop's spheres of one radius share
     theirs. *)
  let r =
    if Int64.equal (Int64.bits_of_float radius) (Int64.bits_of_float t.radius) then
      same_radius
    else (
      t.radius <- radius;
      0)
  in
  for _ = Buffer.length t.kinds to t.count - 1 do
    Buffer.add_char t.kinds (Char.unsafe_chr other)
  done;
  Buffer.add_char t.kinds (Char.unsafe_chr (sphere lor c lor r));
  t.count <- t.count + 1;
  let f = t.floats in
  Floats.room f Floats.group;
  let b = f.last and i = f.n in
  let module A = Bigarray.Array1 in
  A.unsafe_set b i center.x;
  A.unsafe_set b (i + 1) center.y;
  A.unsafe_set b (i + 2) center.z;
  let i =
    if r = 0 then (
      A.unsafe_set b (i + 3) radius;
      i + 4)
    else i + 3
  in
  let i =
    if c = color_own then (
      A.unsafe_set b i color.r;
      A.unsafe_set b (i + 1) color.g;
      A.unsafe_set b (i + 2) color.b;
      i + 3)
    else i
  in
  Floats.advance f (i - f.n)

let add t (p : Primitive.t) =
  match p.shape with
  | Shape.Sphere { center; radius } when holds p && same_material t p ->
      hold t center radius p.color p.material.color
  | _ -> (
      let p = match t.move with Some move -> move p | None -> p in
      t.count <- t.count + 1;
      Chunks.add t.prims p;
      t.material <- Some p.material;
      (* A sphere kept as it is made (the first of a run, whose material is new) gives
         the spheres after it its radius and colour to share, as [take] reads them. *)
      match p.shape with
      | Shape.Sphere { radius; _ } ->
          t.radius <- radius;
          if p.color != p.material.color then t.color <- p.color
      | _ -> ())

let add_sphere t ~center ~radius ~color (material : Material.t) =
  if same_material_as t material then hold t center radius color material.color
  else add t (Primitive.make ~color material (Shape.sphere ~center ~radius))

(* All of them in one array, in order, each held sphere made again and moved; [t] is
   emptied. *)
let take_all t =
  let n = total t in
  let prims = ref (Chunks.take t.prims) and pi = ref 0 in
  let floats = ref (Floats.take t.floats) and fi = ref 0 in
  let kinds = Buffer.to_bytes t.kinds in
  Buffer.reset t.kinds;
  t.count <- 0;
  t.material <- None;
  t.color <- Color.black;
  t.radius <- Float.nan;
  let material = ref Material.default and color = ref Color.black in
  (* The last sphere made, whose radius the next one may share. *)
  let last = ref (Shape.sphere ~center:Vec3.zero ~radius:Float.nan) in
  let rec next_prim () =
    match !prims with
    | (c, k) :: rest ->
        if !pi < k then (
          let p = Array.unsafe_get c !pi in
          incr pi;
          p)
        else (
          prims := rest;
          pi := 0;
          next_prim ())
    | [] -> invalid_arg "Gathered.take"
  in
  let rec chunk () =
    match !floats with
    | (c, k) :: rest ->
        if !fi < k then c
        else (
          Floats.free (c, k);
          floats := rest;
          fi := 0;
          chunk ())
    | [] -> invalid_arg "Gathered.take"
  in
  let make kind =
    if kind = other then (
      let p = next_prim () in
      material := p.material;
      (match p.shape with
      | Shape.Sphere _ ->
          last := p.shape;
          if p.color != p.material.color then color := p.color
      | _ -> ());
      p)
    else
      let c = chunk () and i = !fi in
      let center =
        {
          Vec3.x = Bigarray.Array1.unsafe_get c i;
          y = Bigarray.Array1.unsafe_get c (i + 1);
          z = Bigarray.Array1.unsafe_get c (i + 2);
        }
      in
      let shape =
        match !last with
        | Shape.Sphere { radius; _ } when kind land same_radius <> 0 ->
            Shape.sphere ~center ~radius
        | _ -> Shape.sphere ~center ~radius:(Bigarray.Array1.unsafe_get c (i + 3))
      in
      last := shape;
      let i = if kind land same_radius <> 0 then i + 3 else i + 4 in
      let p =
        if kind land color_own <> 0 then (
          fi := i + 3;
          color :=
            {
              Color.r = Bigarray.Array1.unsafe_get c i;
              g = Bigarray.Array1.unsafe_get c (i + 1);
              b = Bigarray.Array1.unsafe_get c (i + 2);
            };
          Primitive.make ~color:!color !material shape)
        else (
          fi := i;
          if kind land color_last <> 0 then Primitive.make ~color:!color !material shape
          else Primitive.make !material shape)
      in
      match t.move with Some move -> move p | None -> p
  in
  if n = 0 then [||]
  else
    let[@inline] kind i =
      if i < Bytes.length kinds then Char.code (Bytes.unsafe_get kinds i) else other
    in
    let first = make (kind 0) in
    let a = Array.make n first in
    for i = 1 to n - 1 do
      Array.unsafe_set a i (make (kind i))
    done;
    List.iter Floats.free !floats;
    a

(* Held spheres are made again at {!Pace.all_live}: every primitive made lives, so a
   collection then finds nothing to free, and the collector paced at its default (its
   heap small, the floats being outside it) ran nine major cycles over the growing
   primitives of a million coloured spheres (0.5 s of processor time, 0.3 s at this
   overhead, five cycles), and marked 40 M instructions more of field_100000's 100 000 at
   480×270 than when the floats were in the heap. *)
let take t =
  if held t = 0 then take_all t else Pace.within Pace.all_live (fun () -> take_all t)

let discard t =
  List.iter Floats.free (Floats.take t.floats);
  ignore (Chunks.take t.prims);
  Buffer.reset t.kinds;
  t.count <- 0;
  t.material <- None;
  t.color <- Color.black;
  t.radius <- Float.nan
