type t = {
  primary : int;
  shadow : int;
  reflected : int;
  refracted : int;
  bad_samples : int;
  first_bad : (int * int) option;
}

let zero =
  {
    primary = 0;
    shadow = 0;
    reflected = 0;
    refracted = 0;
    bad_samples = 0;
    first_bad = None;
  }

let add a b =
  {
    primary = a.primary + b.primary;
    shadow = a.shadow + b.shadow;
    reflected = a.reflected + b.reflected;
    refracted = a.refracted + b.refracted;
    bad_samples = a.bad_samples + b.bad_samples;
    first_bad = (match a.first_bad with None -> b.first_bad | some -> some);
  }

let sum = Array.fold_left add zero
let total_rays s = s.primary + s.shadow + s.reflected + s.refracted
