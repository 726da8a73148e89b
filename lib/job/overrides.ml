type t = {
  width : int option;
  height : int option;
  samples : int option;
  depth : int option;
  quality : Quality.t option;
}

let none = { width = None; height = None; samples = None; depth = None; quality = None }

let apply o (sc : Scene.t) =
  let ok = function Ok s -> s | Error m -> Job_error.user "%s" m in
  let sc = match o.quality with None -> sc | Some q -> ok (Quality.apply q sc) in
  (* Named by the option the user typed; Settings.validate holds the same bound. *)
  Option.iter
    (fun d ->
      if d > Settings.max_depth then
        Job_error.user "--depth must be at most %d (got %d)" Settings.max_depth d)
    o.depth;
  let s = sc.settings in
  let pick v d = Option.value v ~default:d in
  let settings =
    {
      s with
      width = pick o.width s.width;
      height = pick o.height s.height;
      samples = pick o.samples s.samples;
      depth = pick o.depth s.depth;
    }
  in
  if settings = s then sc else ok (Scene.with_settings sc settings)

let named_fields o =
  let opt f = function Some v -> f v | None -> "-" in
  [
    ("--width", opt string_of_int o.width);
    ("--height", opt string_of_int o.height);
    ("--samples", opt string_of_int o.samples);
    ("--depth", opt string_of_int o.depth);
    ("--quality", opt Quality.to_string o.quality);
  ]

let digest_fields o = List.map snd (named_fields o)
