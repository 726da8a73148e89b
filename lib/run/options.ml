type t = {
  scene : string option;
  output : string option;
  width : int option;
  height : int option;
  samples : int option;
  depth : int option;
  quality : Quality.t option;
  domains : int option;
  time : float option;
  frame : int option;
  stats : string option;
  quiet : bool;
  progress : bool;
}

let default =
  {
    scene = None;
    output = None;
    width = None;
    height = None;
    samples = None;
    depth = None;
    quality = None;
    domains = None;
    time = None;
    frame = None;
    stats = None;
    quiet = false;
    progress = false;
  }

let overrides (o : t) : Overrides.t =
  {
    width = o.width;
    height = o.height;
    samples = o.samples;
    depth = o.depth;
    quality = o.quality;
  }

let max_side = 65536

(* The OCaml runtime refuses to start more than 128 domains. *)
let max_domains = 128

let domains o =
  match o.domains with
  | Some n when n < 1 -> Job_error.user "--domains must be at least 1 (got %d)" n
  | Some n when n > max_domains ->
      Job_error.user
        "--domains must be at most %d, the most the OCaml runtime can run (got %d; this \
         machine recommends %d)"
        max_domains n
        (Domain.recommended_domain_count ())
  | Some n -> n
  | None -> max 1 (Domain.recommended_domain_count ())

let time_of o src = Scenes.time_of src ~time:o.time ~frame:o.frame

let at_start o =
  Option.fold ~none:true ~some:(Float.equal 0.) o.time
  && Option.fold ~none:true ~some:(Int.equal 0) o.frame

let scene_at ?progress ?cancel o src ~time ~frame =
  fst (Scenes.scene ?progress ?cancel src (overrides o) ~time ~frame)
