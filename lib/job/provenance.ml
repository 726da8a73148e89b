type budget = { metric : string; limit : float; values : (string * float) list }

type t = {
  version : string;
  scene : string option;
  scene_digest : string;
  files : (string * string) list;
  options : Overrides.t;
  frame : int;
  time : float;
  region : Image.region option;
  crop : bool;
  alpha : bool;
  bits : int;
  max_error : budget option;
  blocks : string;
}

let keyword = "lancer"
let block_size = 32

(* An absolute, resolved form of [p]: the real path of its directory, then its name (the
   file itself may not exist yet). *)
let resolved p =
  let dir = Filename.dirname p and base = Filename.basename p in
  let dir =
    match Unix.realpath dir with
    | d -> d
    | exception Unix.Unix_error _ ->
        if Filename.is_relative dir then Filename.concat (Sys.getcwd ()) dir else dir
  in
  if base = "." then dir else Filename.concat dir base

(* [p] as a path from directory [dir]. *)
let relative ~dir p =
  let parts s = List.filter (fun x -> x <> "" && x <> ".") (String.split_on_char '/' s) in
  let rec drop a b =
    match (a, b) with x :: a', y :: b' when String.equal x y -> drop a' b' | _ -> (a, b)
  in
  let up, down = drop (parts (resolved (Filename.concat dir "."))) (parts (resolved p)) in
  match List.map (fun _ -> "..") up @ down with [] -> "." | l -> String.concat "/" l

let make ?max_error ~image (src : Scenes.t) options ~files ~time ~frame ~region ~crop
    ~alpha ~bits =
  let scene_dir = Filename.dirname src.file in
  let includes =
    List.filter_map
      (fun p ->
        if src.builtin || String.lowercase_ascii (Filename.extension p) <> ".rts" then
          None
        else
          let md5 = try Digest.to_hex (Digest.file p) with Sys_error _ -> "-" in
          Some (relative ~dir:scene_dir p, md5))
      (src.inputs ())
  in
  {
    version = Version.v;
    scene =
      (if src.builtin then None
       else if src.file = "<stdin>" then Some "-"
       else Some (relative ~dir:(Filename.dirname image) src.file));
    scene_digest = src.text_digest ();
    files = List.sort_uniq compare (includes @ files);
    options;
    frame;
    time;
    region;
    crop;
    alpha;
    bits;
    max_error;
    blocks = "";
  }

let block_count (r : Raster.t) =
  ((r.width + block_size - 1) / block_size, (r.height + block_size - 1) / block_size)

let blocks r = Image.block_digests ~size:block_size r

let to_json t =
  let opt name f = function Some v -> [ (name, f v) ] | None -> [] in
  let int n = `Int n in
  `Assoc
    ([
       ("lancer", `String t.version);
       ("scene", match t.scene with Some s -> `String s | None -> `Null);
       ("scene_digest", `String t.scene_digest);
       ("files", `Assoc (List.map (fun (f, d) -> (f, `String d)) t.files));
       ( "options",
         `Assoc
           (opt "width" int t.options.width
           @ opt "height" int t.options.height
           @ opt "samples" int t.options.samples
           @ opt "depth" int t.options.depth
           @ opt "quality" (fun q -> `String (Quality.to_string q)) t.options.quality) );
       ("frame", `Int t.frame);
       ("time", `Float t.time);
     ]
    @ opt "region"
        (fun (r : Image.region) -> `List [ int r.x0; int r.y0; int r.x1; int r.y1 ])
        t.region
    @ [ ("crop", `Bool t.crop); ("alpha", `Bool t.alpha); ("bits", `Int t.bits) ]
    @ opt "max_error"
        (fun b ->
          `Assoc
            [
              ("metric", `String b.metric);
              ("limit", `Float b.limit);
              ("settings", `Assoc (List.map (fun (k, v) -> (k, `Float v)) b.values));
            ])
        t.max_error
    @ [ ("blocks", `String t.blocks) ])

let text t r =
  let blocks = match r with Some r -> blocks r | None -> "" in
  [ (keyword, Yojson.Safe.to_string (to_json { t with blocks })) ]

exception Bad of string

let of_text s =
  let bad fmt = Printf.ksprintf (fun m -> raise (Bad m)) fmt in
  let field j name =
    match j with
    | `Assoc l -> ( match List.assoc_opt name l with Some v -> v | None -> `Null)
    | _ -> bad "not a JSON object"
  in
  let str j name =
    match field j name with `String s -> s | _ -> bad "no text in field %S" name
  in
  let num j name =
    match field j name with `Int n -> n | _ -> bad "no whole number in field %S" name
  in
  let flag j name =
    match field j name with `Bool b -> b | _ -> bad "no true or false in field %S" name
  in
  let float j name =
    match field j name with
    | `Float x when Float.is_finite x -> x
    | `Int n -> Float.of_int n
    | _ -> bad "no number in field %S" name
  in
  let opt_int j name =
    match field j name with
    | `Null -> None
    | `Int n when n > 0 -> Some n
    | _ -> bad "field %S of options is not a positive whole number" name
  in
  match Yojson.Safe.from_string s with
  | exception Yojson.Json_error m -> Error ("its record is not JSON: " ^ m)
  | j -> (
      try
        let o = field j "options" in
        let quality =
          match field o "quality" with
          | `Null -> None
          | `String q -> (
              match List.assoc_opt q Quality.all with
              | Some q -> Some q
              | None -> bad "unknown quality %S" q)
          | _ -> bad "field \"quality\" of options is not text"
        in
        let bits = num j "bits" in
        if bits <> 8 && bits <> 16 then bad "bits %d (8 or 16)" bits;
        let blocks = str j "blocks" in
        if
          String.length blocks mod 8 <> 0
          || not
               (String.for_all
                  (function '0' .. '9' | 'a' .. 'f' -> true | _ -> false)
                  blocks)
        then bad "its blocks are not 8 hexadecimal digits each";
        Ok
          {
            version = str j "lancer";
            scene =
              (match field j "scene" with
              | `String s -> Some s
              | `Null -> None
              | _ -> bad "field \"scene\" is not text");
            scene_digest = str j "scene_digest";
            files =
              (match field j "files" with
              | `Assoc l ->
                  List.map
                    (fun (f, d) ->
                      match d with
                      | `String d -> (f, d)
                      | _ -> bad "a file's MD5 is not text")
                    l
              | _ -> bad "no object in field \"files\"");
            options =
              {
                width = opt_int o "width";
                height = opt_int o "height";
                samples = opt_int o "samples";
                depth = opt_int o "depth";
                quality;
              };
            frame = num j "frame";
            time =
              (match field j "time" with
              | `Float t -> t
              | `Int n -> Float.of_int n
              | _ -> bad "no number in field \"time\"");
            region =
              (match field j "region" with
              | `Null -> None
              | `List [ `Int x0; `Int y0; `Int x1; `Int y1 ]
                when 0 <= x0 && x0 < x1 && 0 <= y0 && y0 < y1 ->
                  Some { Image.x0; y0; x1; y1 }
              | _ -> bad "field \"region\" is not four whole numbers x0 < x1, y0 < y1");
            crop = flag j "crop";
            alpha = flag j "alpha";
            bits;
            max_error =
              (match field j "max_error" with
              | `Null -> None
              | m ->
                  let values =
                    match field m "settings" with
                    | `Assoc l ->
                        List.map (fun (k, _) -> (k, float (field m "settings") k)) l
                    | _ -> bad "no object in field \"settings\" of max_error"
                  in
                  Some { metric = str m "metric"; limit = float m "limit"; values });
            blocks;
          }
      with Bad m -> Error ("its record is not one lancer writes: " ^ m))
