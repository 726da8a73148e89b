let height = 1.0
let radius = 0.1
let g = 9.81

(* First impact time and speed. *)
let first_impact = Float.sqrt (2. *. height /. g)
let impact_speed = g *. first_impact

let impact_time e k =
  let p = 2. *. impact_speed /. g in
  if e = 1. then first_impact +. (Float.of_int (k - 1) *. p)
  else if e = 0. then first_impact
  else first_impact +. (p *. e *. (1. -. (e ** Float.of_int (k - 1))) /. (1. -. e))

let zeno_time e =
  if e >= 1. then Float.infinity else first_impact *. (1. +. e) /. (1. -. e)

let apex_height e k = height *. (e ** (2. *. Float.of_int k))

let gap e t =
  if t <= first_impact then height -. (0.5 *. g *. t *. t)
  else if t >= zeno_time e then 0.
  else
    let k =
      if e = 1. then
        let k =
          1
          + int_of_float (Float.floor ((t -. first_impact) /. (2. *. impact_speed /. g)))
        in
        (* guard the floor against rounding at the impact instants *)
        if impact_time e k > t then k - 1
        else if impact_time e (k + 1) <= t then k + 1
        else k
      else
        let rec go k = if k < 2000 && impact_time e (k + 1) <= t then go (k + 1) else k in
        go 1
    in
    let v = (e ** Float.of_int k) *. impact_speed in
    let u = t -. impact_time e k in
    Float.max 0. ((v *. u) -. (0.5 *. g *. u *. u))
