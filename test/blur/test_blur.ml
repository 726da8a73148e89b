(* Motion blur: what the camera's shutter makes of a frame. *)
open Lancer

let errors_text es = String.concat "" (List.map Lancer_dsl.Error.to_string es)

let load text =
  match Program.load_string ~filename:"test.rts" text with
  | Ok p -> p
  | Error es -> Alcotest.failf "unexpected errors:\n%s" (errors_text es)

(* The frame as lancer render makes it: the scene, and with an open shutter its
   instants. *)
let frame_scene ?(overrides = Overrides.none) p ~frame =
  let fps = match Program.animation p with Some (fps, _) -> fps | None -> 24. in
  let time = Float.of_int frame /. fps in
  fst (Scenes.scene (Program.as_scenes ~builtin:false p) overrides ~time ~frame)

let render ?(domains = 1) sc =
  fst (Render.with_pool domains (fun pool -> Render.render ?pool sc))

(* The root mean square difference of two linear images, over every channel. *)
let rmse (a : Framebuffer.t) (b : Framebuffer.t) =
  let n = Float.Array.length a.data in
  let s = ref 0. in
  for k = 0 to n - 1 do
    let d = Float.Array.get a.data k -. Float.Array.get b.data k in
    s := !s +. (d *. d)
  done;
  Float.sqrt (!s /. Float.of_int n)

(* The average of the renders of frame [frame] at [n] instants evenly spaced across the
   shutter (open, close): the middles of n equal parts. *)
let average_of_instants p ~frame ~shutter:(o, c) ~n =
  let fps = match Program.animation p with Some (fps, _) -> fps | None -> 24. in
  let times =
    Array.init n (fun k ->
        (Float.of_int frame +. o
        +. ((c -. o) *. (Float.of_int k +. 0.5) /. Float.of_int n))
        /. fps)
  in
  match Program.scenes_with_files p ~times ~frame with
  | Error es -> Alcotest.failf "unexpected errors:\n%s" (errors_text es)
  | Ok scenes ->
      let images = Array.map (fun (sc, _) -> render sc) scenes in
      let first = images.(0) in
      let avg = Framebuffer.create first.width first.height in
      Array.iter
        (fun (im : Framebuffer.t) ->
          Float.Array.iteri
            (fun k v ->
              Float.Array.set avg.data k
                (Float.Array.get avg.data k +. (v /. Float.of_int n)))
            im.data)
        images;
      avg

let moving_sphere =
  {|settings { width: 48, height: 36, samples: 8, background: (0.2, 0.2, 0.3) }
camera { position: (0, 1, -7), look_at: (0, 0.5, 0), fov: 50, shutter: (0, 1), shutter_samples: 64 }
light { position: (-5, 8, -6) }
animation { fps: 4, frames: 4 }
plane { normal: (0, 1, 0), offset: -1, material: material { color: (0.8, 0.8, 0.8) } }
sphere { center: (-2 + 6 * time, 0.5, 0), radius: 0.6, material: material { color: (0.9, 0.2, 0.1) } }
|}

(* A ball dropped from 1.5 m onto the floor: it meets it at √(2/9.81) ≈ 0.45 s, inside
   frame 1 (0.25 s to 0.5 s at 4 fps), and bounces back up. *)
let bouncing_ball =
  {|settings { width: 48, height: 36, samples: 8, background: (0.2, 0.2, 0.3) }
camera { position: (0, 1, -5), look_at: (0, 0.8, 0), fov: 50, shutter: (0, 1), shutter_samples: 64 }
light { position: (-5, 8, -6) }
animation { fps: 4, frames: 4 }
physics { gravity: (0, -9.81, 0), method: "exact" }
plane { normal: (0, 1, 0), offset: 0, material: material { color: (0.8, 0.8, 0.8) } }
body ball {
  sphere { center: (0, 1.5, 0), radius: 0.5, material: material { color: (0.9, 0.2, 0.1) } }
  mass: 1, restitution: 0.8
}
|}

(* The blurred frame equals the average of 64 instants within [tolerance]; the frame's
   own instant does not. *)
let converges text ~tolerance () =
  let p = load text in
  let blurred = frame_scene p ~frame:1 in
  Alcotest.(check int) "the frame has 64 instants" 64 (Array.length blurred.moments);
  let avg = average_of_instants p ~frame:1 ~shutter:(0., 1.) ~n:64 in
  let e = rmse (render blurred) avg in
  let instant =
    match Program.scene_at p ~time:0.25 ~frame:1 with
    | Ok sc -> sc
    | Error es -> Alcotest.failf "unexpected errors:\n%s" (errors_text es)
  in
  let e0 = rmse (render instant) avg in
  if not (e < tolerance) then
    Alcotest.failf "RMSE %g against the average of 64 instants (at most %g)" e tolerance;
  if not (e0 > 4. *. tolerance) then
    Alcotest.failf "the frame's instant is as close to the average (%g) as the blur (%g)"
      e0 e

let test_impact_inside_frame () =
  let p = load bouncing_ball in
  match Program.simulate p ~until:1. with
  | Error es -> Alcotest.failf "unexpected errors:\n%s" (errors_text es)
  | Ok tr ->
      let impacts =
        List.filter
          (fun (e : Physics.event) -> e.time > 0.25 && e.time < 0.5)
          (Physics.events tr)
      in
      Alcotest.(check bool) "an impact between 0.25 s and 0.5 s" true (impacts <> [])

(* With the shutter closed (absent, or close = open) the frame is the instant, byte for
   byte. *)
let test_closed_shutter () =
  let text extra =
    Printf.sprintf
      {|settings { width: 40, height: 30, samples: 2 }
animation { fps: 4, frames: 4 }
camera { position: (0, 1, -7), look_at: (0, 0.5, 0)%s }
light { position: (-5, 8, -6) }
sphere { center: (-2 + 6 * time, 0.5, 0), radius: 0.6 }
|}
      extra
  in
  let bytes extra =
    let sc = frame_scene (load (text extra)) ~frame:1 in
    (Array.length sc.moments, Image.to_bytes sc.settings.gamma (render sc))
  in
  let n, plain = bytes "" in
  Alcotest.(check int) "no instants without a shutter" 0 n;
  let n, closed = bytes ", shutter: (0.5, 0.5), shutter_samples: 16" in
  Alcotest.(check int) "no instants with a closed one" 0 n;
  Alcotest.(check bool) "a closed shutter renders as none" true (Bytes.equal plain closed);
  let n, opened = bytes ", shutter: (0, 1)" in
  Alcotest.(check int) "8 instants by default" 8 n;
  Alcotest.(check bool) "an open one does not" false (Bytes.equal plain opened)

let test_domains () =
  let sc = frame_scene (load moving_sphere) ~frame:1 in
  let sc =
    Result.get_ok (Scene.with_settings sc { sc.settings with samples = 2; jitter = true })
  in
  let one = render ~domains:1 sc in
  List.iter
    (fun n ->
      let other = render ~domains:n sc in
      Alcotest.(check bool)
        (Printf.sprintf "%d domains give the bytes of one" n)
        true
        (Bytes.equal
           (Image.to_bytes Settings.Srgb one)
           (Image.to_bytes Settings.Srgb other)
        && rmse one other = 0.))
    [ 2; 3 ]

(* The instants are built on the part that does not move: one structure for them all. *)
let test_still_part_shared () =
  let check text =
    let sc = frame_scene (load text) ~frame:0 in
    let parts = Array.map (fun (m : Scene.t) -> Accel.fixed_key m.accel) sc.moments in
    Alcotest.(check bool) "instants made" true (Array.length parts > 1);
    match parts.(0) with
    | None -> Alcotest.fail "an instant without a still part"
    | Some f ->
        Array.iter
          (function
            | Some g -> Alcotest.(check bool) "the same still part" true (f = g)
            | None -> Alcotest.fail "an instant without a still part")
          parts
  in
  check moving_sphere;
  (* a still without an animation block: 24 frames a second *)
  check
    {|camera { shutter: (-0.5, 0.5), shutter_samples: 4 }
plane { normal: (0, 1, 0), offset: -1 }
sphere { center: (time, 0, 0), radius: 1 }
|}

let test_instants () =
  let p = load moving_sphere in
  let sc = frame_scene p ~frame:2 in
  let times = Array.map (fun (m : Scene.t) -> m.time) sc.moments in
  Alcotest.(check (float 1e-12))
    "the first instant"
    ((2. +. (0.5 /. 64.)) /. 4.)
    times.(0);
  Alcotest.(check (float 1e-12))
    "the last instant"
    ((3. -. (0.5 /. 64.)) /. 4.)
    times.(63);
  Array.iter (fun (m : Scene.t) -> Alcotest.(check int) "the frame" 2 m.frame) sc.moments

let test_quality () =
  let p = load moving_sphere in
  List.iter
    (fun (q, n) ->
      let sc =
        frame_scene ~overrides:{ Overrides.none with quality = Some q } p ~frame:1
      in
      Alcotest.(check int)
        (Quality.to_string q ^ ": shutter samples")
        n sc.camera.shutter_samples;
      Alcotest.(check int)
        (Quality.to_string q ^ ": instants")
        n (Array.length sc.moments))
    [ (Quality.Draft, 1); (Preview, 4); (Final, 8); (Reference, 32) ]

let () =
  Alcotest.run "blur"
    [
      ( "converges",
        [
          Alcotest.test_case
            "a sphere in a straight line: the blurred frame is the average of 64 instants"
            `Quick
            (converges moving_sphere ~tolerance:0.005);
          Alcotest.test_case "the bouncing ball meets the floor inside frame 1" `Quick
            test_impact_inside_frame;
          Alcotest.test_case
            "a ball bouncing across an impact: the blurred frame is the average of 64 \
             instants"
            `Quick
            (converges bouncing_ball ~tolerance:0.005);
        ] );
      ( "frames",
        [
          Alcotest.test_case "a closed shutter gives the bytes of none" `Quick
            test_closed_shutter;
          Alcotest.test_case "the instants are the middles of the shutter's parts" `Quick
            test_instants;
          Alcotest.test_case "1, 2 and 3 domains give the same bytes" `Quick test_domains;
          Alcotest.test_case "the instants share one still part" `Quick
            test_still_part_shared;
          Alcotest.test_case "quality presets set the shutter samples" `Quick test_quality;
        ] );
    ]
