type t = {
  mutable x : float;
  mutable y : float;
  mutable z : float;
  mutable nx : float;
  mutable ny : float;
  mutable nz : float;
  mutable u : float;
  mutable v : float;
  mutable r : float;
  mutable g : float;
  mutable b : float;
}

let create () =
  {
    x = 0.;
    y = 0.;
    z = 0.;
    nx = 0.;
    ny = 0.;
    nz = 0.;
    u = 0.;
    v = 0.;
    r = 0.;
    g = 0.;
    b = 0.;
  }

let[@inline] set_point f x y z =
  f.x <- x;
  f.y <- y;
  f.z <- z

let[@inline] point f = Vec3.v f.x f.y f.z

let[@inline] set_normal f (n : Vec3.t) =
  f.nx <- n.x;
  f.ny <- n.y;
  f.nz <- n.z

let[@inline] set_color f (c : Color.t) =
  f.r <- c.r;
  f.g <- c.g;
  f.b <- c.b
