type gamma = Lancer_image.Image.gamma = Srgb | Power of float
type sky = { horizon : Color.t; zenith : Color.t }
type fog = { color : Color.t; distance : float }

type t = {
  width : int;
  height : int;
  depth : int;
  samples : int;
  jitter : bool;
  adaptive : float;
  shadows : bool;
  background : Color.t;
  sky : sky option;
  fog : fog option;
  ambient : Color.t;
  gamma : gamma;
}

let default =
  {
    width = 640;
    height = 480;
    depth = 5;
    samples = 1;
    jitter = false;
    adaptive = 0.;
    shadows = true;
    background = Color.black;
    sky = None;
    fog = None;
    ambient = Color.white;
    gamma = Srgb;
  }

let max_pixels = Lancer_image.Image.max_pixels

(* Each bounce is a nested call: far beyond this the stack would overflow. *)
let max_depth = 1000

let validate s =
  if s.width < 1 || s.height < 1 then
    Error (Printf.sprintf "image size must be at least 1×1 (got %d×%d)" s.width s.height)
  else if s.width > max_pixels / s.height then
    (* About 27 bytes a pixel: the linear float framebuffer (24) and the encoded bytes. *)
    Error
      (Printf.sprintf
         "image %d×%d is larger than the limit of %d pixels (16384×16384); it would need \
          about %.0f GB of memory"
         s.width s.height max_pixels
         (27. *. Float.of_int s.width *. Float.of_int s.height /. 1e9))
  else if s.depth < 1 then
    Error (Printf.sprintf "depth must be at least 1 (got %d)" s.depth)
  else if s.depth > max_depth then
    Error (Printf.sprintf "depth must be at most %d (got %d)" max_depth s.depth)
  else if s.samples < 1 then
    Error (Printf.sprintf "samples must be at least 1 (got %d)" s.samples)
  else if s.samples > 64 then
    Error
      (Printf.sprintf "samples must be at most 64 (got %d; that is %d rays a pixel)"
         s.samples (s.samples * s.samples))
  else if not (Float.is_finite s.adaptive && s.adaptive >= 0.) then
    Error "adaptive must be a number >= 0"
  else
    match s.gamma with
    | Power g when not (Float.is_finite g && g > 0.) ->
        Error "gamma must be \"srgb\" or a number > 0"
    | _ -> (
        match s.fog with
        | Some f when not (Float.is_finite f.distance && f.distance > 0.) ->
            Error
              (Printf.sprintf "the fog distance must be a number > 0 (got %g)" f.distance)
        | _ -> Ok ())

let background_along s (d : Vec3.t) =
  match s.sky with
  | None -> s.background
  | Some { horizon = h; zenith = z } ->
      let t = if d.y > 0. then d.y else 0. in
      Color.v
        (h.r +. (t *. (z.r -. h.r)))
        (h.g +. (t *. (z.g -. h.g)))
        (h.b +. (t *. (z.b -. h.b)))

let fog_segment f t (c : Color.t) =
  let e = Float.exp (-.t /. f.distance) in
  let k = 1. -. e in
  let fc = f.color in
  Color.v
    ((c.r *. e) +. (fc.r *. k))
    ((c.g *. e) +. (fc.g *. k))
    ((c.b *. e) +. (fc.b *. k))
