type t = {
  color : Color.t;
  texture : Texture.t option;
  ambient : float;
  diffuse : float;
  specular : float;
  shininess : float;
  reflection : float;
  transparency : float;
  ior : float;
  fresnel : bool;
  bump : Bump.t option;
}

let default =
  {
    color = Color.white;
    texture = None;
    ambient = 0.1;
    diffuse = 0.9;
    specular = 0.;
    shininess = 50.;
    reflection = 0.;
    transparency = 0.;
    ior = 1.;
    fresnel = false;
    bump = None;
  }

let validate m =
  let nonneg name v =
    if Float.is_finite v && v >= 0. then Ok ()
    else Error (Printf.sprintf "%s must be a finite number >= 0 (got %g)" name v)
  in
  let ( let* ) = Result.bind in
  let* () = nonneg "ambient" m.ambient in
  let* () = nonneg "diffuse" m.diffuse in
  let* () = nonneg "specular" m.specular in
  let* () = nonneg "shininess" m.shininess in
  let* () = nonneg "reflection" m.reflection in
  let* () = nonneg "transparency" m.transparency in
  if m.reflection > 1. then Error "reflection must be at most 1"
  else if m.transparency > 1. then Error "transparency must be at most 1"
  else if m.reflection +. m.transparency > 1. then
    Error
      (Printf.sprintf "reflection + transparency must be at most 1 (got %g + %g)"
         m.reflection m.transparency)
  else if not (Float.is_finite m.ior && m.ior > 0.) then
    Error (Printf.sprintf "ior must be > 0 (got %g)" m.ior)
  else Ok ()
