let user = Job_error.user

type kind = Object | Depth | Normal

let kinds = [ ("object", Object); ("depth", Depth); ("normal", Normal) ]

let parse s =
  let names = List.map String.trim (String.split_on_char ',' s) in
  let known () = String.concat ", " (List.map fst kinds) in
  if List.for_all (String.equal "") names then
    user "--aov needs a list of images, from %s" (known ());
  let asked =
    List.map
      (fun n ->
        match List.assoc_opt n kinds with
        | Some k -> k
        | None -> user "--aov: unknown image %S; the images are %s" n (known ()))
      (List.filter (fun n -> n <> "") names)
  in
  List.filter_map (fun (_, k) -> if List.mem k asked then Some k else None) kinds

type objects = {
  objs : Description.obj array;
  starts : int array;
      (** the index of each object's first primitive in the scene's [objects], one more
          entry: their count *)
}

let objects prog ~time ~frame (sc : Scene.t) =
  match Program.describe prog ~time ~frame with
  | Error _ -> user "the scene's objects could not be described again"
  | Ok d ->
      let objs = Array.of_list d.objects in
      let starts = Array.make (Array.length objs + 1) 0 in
      let assets = Program.assets prog in
      Array.iteri
        (fun k o -> starts.(k + 1) <- starts.(k) + Compile.primitive_count assets o)
        objs;
      if starts.(Array.length objs) <> Array.length sc.objects then
        user
          "the scene's description lists %d primitives but the scene has %d: its objects \
           cannot be named"
          starts.(Array.length objs)
          (Array.length sc.objects);
      { objs; starts }

(* The object that primitive [p] was made from, counting from 1: the last whose first
   primitive is at or before it. *)
let owner o p =
  let lo = ref 0 and hi = ref (Array.length o.objs - 1) in
  while !lo < !hi do
    let mid = (!lo + !hi + 1) / 2 in
    if o.starts.(mid) <= p then lo := mid else hi := mid - 1
  done;
  !lo + 1

let ids o (a : Aov.t) =
  (* Consecutive pixels mostly show one object: its search is not made again. *)
  let last_p = ref (-1) and last_id = ref 0 in
  Array.map
    (fun p ->
      if p < 0 then 0
      else (
        if p <> !last_p then (
          last_p := p;
          last_id := owner o p);
        !last_id))
    a.item

let place (l : Loc.t) = Printf.sprintf "%s:%d" l.file l.line

let label o k =
  if k = 0 then "the background"
  else
    let ob = o.objs.(k - 1) in
    Printf.sprintf "%s at %s" ob.kind (place ob.loc)

let stem out = Filename.remove_extension out

let paths out = function
  | Object -> [ stem out ^ ".object.png"; stem out ^ ".objects.json" ]
  | Depth -> [ stem out ^ ".depth.pfm" ]
  | Normal -> [ stem out ^ ".normal.png" ]

let written = function Ok () -> () | Error m -> raise (Job_error.User m)

let write_objects out o (a : Aov.t) =
  let ids = ids o a in
  let samples = Bytes.create (2 * Array.length ids) in
  Array.iteri (fun p k -> Bytes.set_uint16_be samples (2 * p) (min k 0xffff)) ids;
  written
    (Image.write_raster
       (stem out ^ ".object.png")
       (Raster.make ~width:a.width ~height:a.height ~channels:1 ~depth:16 samples));
  let entry k (ob : Description.obj) =
    `Assoc
      [
        ("id", `Int (k + 1));
        ("kind", `String ob.kind);
        ("file", `String ob.loc.file);
        ("line", `Int ob.loc.line);
        ("column", `Int ob.loc.col);
      ]
  in
  let doc =
    `Assoc
      [
        ("background", `Int 0);
        ("objects", `List (Array.to_list (Array.mapi entry o.objs)));
      ]
  in
  written
    (Image.write_atomic
       (stem out ^ ".objects.json")
       (fun oc ->
         Yojson.Safe.pretty_to_channel oc doc;
         output_char oc '\n'))

let write_depth out (a : Aov.t) =
  let fb = Framebuffer.create a.width a.height in
  for p = 0 to (a.width * a.height) - 1 do
    let d = Float.Array.get a.depth p in
    Framebuffer.set_rgb fb (p mod a.width) (p / a.width) d d d
  done;
  written (Image.save (stem out ^ ".depth.pfm") fb)

let write_normal out (a : Aov.t) =
  let n = a.width * a.height in
  let rgb = Bytes.create (3 * n) in
  for p = 0 to n - 1 do
    for c = 0 to 2 do
      let v =
        if Array.get a.item p < 0 then 0
        else
          let x = (Float.Array.get a.normal ((3 * p) + c) +. 1.) /. 2. in
          Float.to_int (Float.floor ((255. *. Float.min 1. (Float.max 0. x)) +. 0.5))
      in
      Bytes.set_uint8 rgb ((3 * p) + c) v
    done
  done;
  written (Image.write_rgb8 (stem out ^ ".normal.png") a.width a.height rgb)

let write ks ~out o a =
  List.iter
    (function
      | Object -> write_objects out o a
      | Depth -> write_depth out a
      | Normal -> write_normal out a)
    ks

(* The largest difference of a channel of pixel [p]. *)
let diff_at a b p =
  let d = ref 0 in
  for c = 0 to 2 do
    let i = (3 * p) + c in
    d := max !d (abs (Bytes.get_uint8 a i - Bytes.get_uint8 b i))
  done;
  !d

let shown = 5

let blame ~tolerance o ids (_, _, a) (_, _, b) =
  let n = Array.length ids in
  let over t =
    let counts = Hashtbl.create 16 in
    for p = 0 to n - 1 do
      if diff_at a b p > t then
        let k = ids.(p) in
        Hashtbl.replace counts k (1 + Option.value (Hashtbl.find_opt counts k) ~default:0)
    done;
    counts
  in
  let counts =
    let c = over tolerance in
    if Hashtbl.length c = 0 then over 0 else c
  in
  let sorted =
    List.sort
      (fun (ka, ca) (kb, cb) -> if ca <> cb then compare cb ca else compare ka kb)
      (Hashtbl.fold (fun k c acc -> (k, c) :: acc) counts [])
  in
  let first = List.filteri (fun i _ -> i < shown) sorted in
  let rest = List.filteri (fun i _ -> i >= shown) sorted in
  let parts = List.map (fun (k, c) -> Printf.sprintf "%d on %s" c (label o k)) first in
  let parts =
    match rest with
    | [] -> parts
    | _ ->
        let c = List.fold_left (fun s (_, c) -> s + c) 0 rest in
        parts @ [ Printf.sprintf "%d on %d other objects" c (List.length rest) ]
  in
  if parts = [] then "no pixel changed"
  else "most changed pixels: " ^ String.concat ", " parts

let golden_hint ~tolerance prog ~time ~frame (sc : Scene.t) ~golden ((w, h, _) as actual)
    =
  match Image.read_rgb8 golden with
  | Ok ((gw, gh, _) as g) when gw = w && gh = h ->
      let a = Aov.primary sc in
      Option.map
        (fun o -> blame ~tolerance o (ids o a) g actual)
        (try Some (objects prog ~time ~frame sc) with Job_error.User _ -> None)
  | Ok _ | Error _ -> None
