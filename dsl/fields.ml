open Value

(* ------------------------------------------------------------------------------------ *)
(* A block's kind made ready: each field's default as a value *)

(* ------------------------------------------------------------------------------------ *)
(* A block as written *)

type entry = Kind.entry = { sch : Schema.field; default : Value.t; required : bool }

type site = {
  kind_ : Kind.t;
  block : Schema.block;
  kind : string;  (** the keyword, as messages name the block *)
  kloc : Loc.t;
  names : string array;
  entries : entry array;
  given : bool array;
  vlocs : Loc.t array;
  wrong : bool array;
  steps : (string * Loc.t) array;
  failed : bool;
  kind_known : bool;
}

let site (b : Tast.block) =
  let kind = b.kind in
  let n = Array.length kind.names in
  let given = Array.make n false and wrong = Array.make n false in
  let vlocs = Array.make n b.keyword.nloc in
  let steps = ref [] in
  List.iter
    (function
      | Tast.Field { slot = Slot i; value; wrong = w; _ } ->
          given.(i) <- true;
          wrong.(i) <- w;
          vlocs.(i) <- value.loc
      | Field { slot = Step s; value; _ } -> steps := (s, value.loc) :: !steps
      | Field { slot = Dropped; _ } | Stmts _ -> ())
    b.items;
  {
    kind_ = kind;
    block = kind.block;
    kind = b.keyword.id;
    kloc = b.keyword.nloc;
    names = kind.names;
    entries = kind.entries;
    given;
    vlocs;
    wrong;
    steps = Array.of_list (List.rev !steps);
    failed = b.failed;
    kind_known = b.kind_known;
  }

let step_count s = Array.length s.steps

type t = {
  site : site;
  vals : Value.t array;
  svals : Value.t array;
  mutable failed : bool;
  out : Value.sink;
}

let make site out vals svals = { site; vals; svals; failed = site.failed; out }

(* ------------------------------------------------------------------------------------ *)
(* Reading fields. Each accessor reports a value out of its range (or of a type the
   checker could not know) at the value, marks the block failed and gives the default, so
   that every mistake of a block is reported at once. *)

let slot site name =
  match Kind.slot site.kind_ name with
  | -1 ->
      invalid_arg
        (Printf.sprintf "Fields: no field %s of %s in the schema" name site.kind)
  | i -> i

let bad b loc msg =
  b.out.report loc msg;
  b.failed <- true

let finish b = not b.failed
let given b i = b.site.given.(i)

(* A field's value: [VPoison] where it is not given (nor any field after it). *)
let[@inline] value b i =
  if i < Array.length b.vals then Array.unsafe_get b.vals i else VPoison

(* A field whose value is usable: given, and not one that failed (already reported). *)
let live b i = value b i != VPoison

(* A field left out: its default ([default], or the schema's). One required is missing
   (reported by the checker), or its value failed: the same, the block failed. *)
let fallback default b i conv =
  let e = b.site.entries.(i) in
  if (not (given b i)) && e.required then b.failed <- true;
  if given b i then b.failed <- true;
  match default with
  | Some d -> d
  | None -> (
      match conv e.default with
      | Some x -> x
      | None -> invalid_arg ("Build: the schema has no default of " ^ e.sch.name))

(* A value of the wrong type: only one whose type the checker could not know. *)
let get default b i conv =
  if given b i then
    match value b i with
    | VPoison -> fallback default b i conv
    | v -> (
        match conv v with
        | Some x -> x
        | None ->
            bad b b.site.vlocs.(i) (Msg.field_type b.site.entries.(i).sch (ty v));
            fallback default b i conv)
  else fallback default b i conv

let as_number = function VNum x -> Some x | _ -> None
let as_vector = function VVec v -> Some v | _ -> None

let[@inline] check_range b (e : entry) i x =
  if not (Schema.in_range e.sch.range x) then
    bad b b.site.vlocs.(i) (Msg.out_of_range e.sch x)

(* A number, refused outside the field's range; [check] instead checks it otherwise. *)
let number ?default ?check b i =
  match value b i with
  | VNum x -> (
      match check with
      | Some c -> c b.site.vlocs.(i) x
      | None ->
          check_range b b.site.entries.(i) i x;
          x)
  | _ when not (given b i) -> (
      match (default, b.site.entries.(i)) with
      | Some d, { required = false; _ } -> d
      | None, { required = false; default = VNum x; _ } -> x
      | _ -> get default b i as_number)
  | _ -> get default b i as_number

(* A number left out is [default], and read no further; one given as {!number} reads it. *)
let number_or b i default =
  match value b i with
  | VNum x ->
      check_range b b.site.entries.(i) i x;
      x
  | _ when not (given b i) -> default
  | _ -> number ~default b i

(* A whole number in the field's range. *)
let integer b i =
  match value b i with
  | VNum x ->
      let e = b.site.entries.(i) in
      if Schema.in_range e.sch.range x then int_of_float x
      else (
        check_range b e i x;
        int_of_float (fallback None b i as_number))
  | _ -> int_of_float (get None b i as_number)

let boolean ?default b i =
  match value b i with
  | VBool x -> x
  | _ -> get default b i (function VBool x -> Some x | _ -> None)

let file b i = get None b i (function VStr s -> Some s | _ -> None)

let[@inline] check_coords b i (v : Vec3.t) =
  let big = Schema.big in
  if not (Float.abs v.x <= big && Float.abs v.y <= big && Float.abs v.z <= big) then
    bad b b.site.vlocs.(i) (Msg.coordinates b.site.names.(i))

(* A vector with coordinates within ±1e150; [check] checks it further. *)
let point ?default ?check b i =
  match value b i with
  | VVec v -> (
      check_coords b i v;
      match check with Some c -> c b.site.vlocs.(i) v | None -> v)
  | _ when not (given b i) -> (
      match (default, b.site.entries.(i)) with
      | Some d, { required = false; _ } -> d
      | None, { required = false; default = VVec v; _ } -> v
      | _ -> get default b i as_vector)
  | _ -> get default b i as_vector

let direction b i =
  match value b i with
  | VVec v ->
      check_coords b i v;
      if Vec3.max_abs v < 1e-150 then
        bad b b.site.vlocs.(i) (Msg.non_zero b.site.names.(i));
      v
  | _ -> point b i

let color ?default b i =
  match value b i with
  | VVec v ->
      check_coords b i v;
      if v.x < 0. || v.y < 0. || v.z < 0. then
        bad b b.site.vlocs.(i) (Msg.negative_colour b.site.names.(i) v);
      Color.of_vec3 v
  | _ -> Color.of_vec3 (point ?default:(Option.map Color.to_vec3 default) b i)

(* The same, [default] where it is left out. *)
let color_or b i default =
  match value b i with
  | VVec _ -> color b i
  | _ when not (given b i) -> default
  | _ -> color ~default b i
