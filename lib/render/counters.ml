type t = {
  primary : int;
  shadow : int;
  reflected : int;
  refracted : int;
  bad_samples : int;
  first_bad : (int * int) option;
  noise_sq : int;
  noise_n : int;
}

(* The unit of [noise_sq]: 2⁻¹⁶ of a squared 8-bit step. *)
let noise_unit = 65536.

let zero =
  {
    primary = 0;
    shadow = 0;
    reflected = 0;
    refracted = 0;
    bad_samples = 0;
    first_bad = None;
    noise_sq = 0;
    noise_n = 0;
  }

let add a b =
  {
    primary = a.primary + b.primary;
    shadow = a.shadow + b.shadow;
    reflected = a.reflected + b.reflected;
    refracted = a.refracted + b.refracted;
    bad_samples = a.bad_samples + b.bad_samples;
    first_bad = (match a.first_bad with None -> b.first_bad | some -> some);
    noise_sq = a.noise_sq + b.noise_sq;
    noise_n = a.noise_n + b.noise_n;
  }

let sum = Array.fold_left add zero
let total_rays s = s.primary + s.shadow + s.reflected + s.refracted

let noise s =
  if s.noise_n = 0 then None
  else Some (Float.sqrt (Float.of_int s.noise_sq /. noise_unit /. Float.of_int s.noise_n))
