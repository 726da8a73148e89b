(* Separable filtering of the five moments (x, y, x², y², xy) of one channel, over the
   columns where the window fits, then over the rows where it fits, summing the map. *)

let radius = 5
let window = (2 * radius) + 1
let sigma = 1.5
let c1 = (0.01 *. 255.) ** 2.
let c2 = (0.03 *. 255.) ** 2.

let kernel =
  let k =
    Float.Array.init window (fun i ->
        let x = Float.of_int (i - radius) in
        Float.exp (-.(x *. x) /. (2. *. sigma *. sigma)))
  in
  let s = Float.Array.fold_left ( +. ) 0. k in
  Float.Array.map_inplace (fun v -> v /. s) k;
  k

(* The sum of the SSIM map of channel c over the valid pixels; m holds five planes of
   (w - 2·radius)·h values. *)
let channel_sum w h a b c (m : Float.Array.t array) =
  let vw = w - (2 * radius) in
  let mx = m.(0) and my = m.(1) and mxx = m.(2) and myy = m.(3) and mxy = m.(4) in
  for y = 0 to h - 1 do
    for x = 0 to vw - 1 do
      let sx = ref 0.
      and sy = ref 0.
      and sxx = ref 0.
      and syy = ref 0.
      and sxy = ref 0. in
      for i = 0 to window - 1 do
        let j = (3 * ((y * w) + x + i)) + c in
        let u = Float.of_int (Char.code (Bytes.unsafe_get a j))
        and v = Float.of_int (Char.code (Bytes.unsafe_get b j)) in
        let k = Float.Array.unsafe_get kernel i in
        sx := !sx +. (k *. u);
        sy := !sy +. (k *. v);
        sxx := !sxx +. (k *. u *. u);
        syy := !syy +. (k *. v *. v);
        sxy := !sxy +. (k *. u *. v)
      done;
      let o = (y * vw) + x in
      Float.Array.unsafe_set mx o !sx;
      Float.Array.unsafe_set my o !sy;
      Float.Array.unsafe_set mxx o !sxx;
      Float.Array.unsafe_set myy o !syy;
      Float.Array.unsafe_set mxy o !sxy
    done
  done;
  let total = ref 0. in
  for y = 0 to h - window do
    for x = 0 to vw - 1 do
      let ux = ref 0.
      and uy = ref 0.
      and uxx = ref 0.
      and uyy = ref 0.
      and uxy = ref 0. in
      for i = 0 to window - 1 do
        let o = ((y + i) * vw) + x in
        let k = Float.Array.unsafe_get kernel i in
        ux := !ux +. (k *. Float.Array.unsafe_get mx o);
        uy := !uy +. (k *. Float.Array.unsafe_get my o);
        uxx := !uxx +. (k *. Float.Array.unsafe_get mxx o);
        uyy := !uyy +. (k *. Float.Array.unsafe_get myy o);
        uxy := !uxy +. (k *. Float.Array.unsafe_get mxy o)
      done;
      let ux = !ux and uy = !uy in
      let vx = !uxx -. (ux *. ux)
      and vy = !uyy -. (uy *. uy)
      and vxy = !uxy -. (ux *. uy) in
      total :=
        !total
        +. ((2. *. ux *. uy) +. c1)
           *. ((2. *. vxy) +. c2)
           /. (((ux *. ux) +. (uy *. uy) +. c1) *. (vx +. vy +. c2))
    done
  done;
  !total

let ssim (w, h, a) (w', h', b) =
  if w <> w' || h <> h' then
    Error (Printf.sprintf "the images differ in size: %d×%d and %d×%d" w h w' h')
  else if w < window || h < window then
    Error
      (Printf.sprintf "SSIM needs images of at least %d×%d pixels (these are %d×%d)"
         window window w h)
  else
    let m = Array.init 5 (fun _ -> Float.Array.make ((w - (2 * radius)) * h) 0.) in
    let valid = Float.of_int ((w - (2 * radius)) * (h - (2 * radius))) in
    let s = ref 0. in
    for c = 0 to 2 do
      s := !s +. (channel_sum w h a b c m /. valid)
    done;
    Ok (!s /. 3.)
