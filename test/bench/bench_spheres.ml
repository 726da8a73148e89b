(* Ray tracing random spheres through the bounding volume hierarchy.

   usage: bench_spheres.exe [--width W] [--height H] [--domains D] N1 N2 ...

   For each count N: N spheres from a fixed seed, uniformly in a cube of side N^(1/3)
   (so the density, and the number of spheres along a ray, stays about the same), radii
   in [0.1, 0.4], one point light with shadows, seen from outside the cube. Reported per
   count, as a Markdown table: building the scene (primitives and BVH) and the BVH alone,
   the render time, rays per second (primary + shadow), minor words allocated per ray, and
   peak resident memory (VmHWM, which only grows, so read it for the largest count).
   The scene is the one of `lancer bench scaling`, which runs each count in a process of
   its own and also sweeps domains and image sizes; this single-process form stays for
   profiling one count under perf. *)
open Lancer

let vm_hwm_mib () =
  try
    In_channel.with_open_text "/proc/self/status" (fun ic ->
        let rec go () =
          match In_channel.input_line ic with
          | None -> Float.nan
          | Some l when String.length l > 6 && String.sub l 0 6 = "VmHWM:" ->
              Scanf.sscanf (String.sub l 6 (String.length l - 6)) " %d kB" (fun kb -> Float.of_int kb /. 1024.)
          | Some _ -> go ()
        in
        go ())
  with _ -> Float.nan

let time f =
  let t0 = Unix.gettimeofday () in
  let r = f () in
  (r, Unix.gettimeofday () -. t0)

let () =
  let width = ref 320 and height = ref 240 and domains = ref 1 and counts = ref [] in
  Arg.parse
    [ ("--width", Arg.Set_int width, "W image width (320)");
      ("--height", Arg.Set_int height, "H image height (240)");
      ("--domains", Arg.Set_int domains, "D domains rendering (1)") ]
    (fun s -> match int_of_string_opt s with Some n when n > 0 -> counts := n :: !counts | _ -> raise (Arg.Bad ("not a count: " ^ s)))
    "bench_spheres.exe [--width W] [--height H] [--domains D] N1 N2 ...";
  let counts = if !counts = [] then [ 1000; 10000; 100000 ] else List.rev !counts in
  Printf.printf "Random spheres, %d×%d, 1 sample, shadows, %d domain(s), OCaml %s\n\n" !width !height !domains Sys.ocaml_version;
  print_endline "| spheres | scene build (s) | BVH build (s) | render (s) | rays | Mrays/s | minor words/ray | peak RSS (MiB) |";
  print_endline "|---:|---:|---:|---:|---:|---:|---:|---:|";
  List.iter
    (fun n ->
      let prims, camera, lights = Lancer_cli.Bench.sphere_field n in
      let settings = { Settings.default with width = !width; height = !height; depth = 1 } in
      let arr = Array.of_list prims in
      let _, bvh_s = time (fun () -> Accel.build arr) in
      let sc, build_s = time (fun () -> Scene.make_exn ~settings ~camera ~lights prims) in
      Gc.compact ();
      let w0 = Gc.minor_words () in
      let (_, stats), render_s = time (fun () -> Render.with_pool !domains (fun pool -> Render.render ?pool sc)) in
      let words = Gc.minor_words () -. w0 in
      let rays = Stats.total_rays stats in
      Printf.printf "| %d | %.3f | %.3f | %.3f | %d | %.3f | %.0f | %.0f |\n%!" n build_s bvh_s render_s rays
        (Float.of_int rays /. render_s /. 1e6)
        (words /. Float.of_int rays) (vm_hwm_mib ());
      ignore (Sys.opaque_identity sc))
    counts
