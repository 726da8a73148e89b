(* The developers' benchmarks, outside the shipped lancer: scaling, the physics methods,
   the scene language, memory per object. Not installed; `make bench` runs them. *)

open Lancer
open Lancer_benchmarks
open Cmdliner

(* A benchmark's failure as lancer says it: one message, exit 1 for a user error. *)
let run f =
  match f () with
  | () -> 0
  | exception e ->
      let text, status = Job_error.describe e in
      prerr_string text;
      status

let json =
  Arg.(value & flag & info [ "json" ] ~doc:"Print JSON instead of a Markdown table.")

let physics =
  let rates =
    Arg.(
      value
      & opt (list float) [ 30.; 240.; 1000. ]
      & info [ "rates" ] ~docv:"HZ,HZ,..."
          ~doc:"Steps per second of the fixed-step methods (the step is 1/HZ s).")
  in
  let until =
    Arg.(
      value & opt float 10.
      & info [ "until" ] ~docv:"S" ~doc:"Simulated time, in seconds.")
  in
  let sample_rate =
    Arg.(
      value & opt float 240.
      & info [ "sample-rate" ] ~docv:"HZ"
          ~doc:"Rate at which positions are compared with the closed form.")
  in
  let man =
    [
      `S Manpage.s_description;
      `P
        "Drops a ball (radius 0.1 m) from 1 m onto a floor under g = 9.81 m/s², with \
         restitution 1 and 0.8, and simulates it with the exact (event-driven) method \
         and with velocity Verlet and explicit Euler at each step. Each row gives the \
         cost (wall time of the simulation, median of repeated runs; fixed steps taken; \
         events) and the error against the closed-form motion: the largest position \
         error over frames, the largest error of the impact times and of the apex \
         heights (all impacts for e = 1, the first five for e = 0.8), and the first \
         apex, which is 1 m (e = 1) or 0.64 m (e = 0.8) exactly.";
      `P
        "For e = 0.8 the ideal ball bounces infinitely often before 4.0637 s; the exact \
         method rests the ball once a rebound would rise less than 1e-4 of its radius, \
         so its position error there is at most 1e-5 m.";
      `S Manpage.s_examples;
      `Pre "  lancer_bench physics --rates 30,240,1000 --json";
    ]
  in
  Cmd.v
    (Cmd.info "physics"
       ~doc:
         "error and cost of the physics methods on a bouncing ball with a closed-form \
          answer"
       ~man)
    Term.(
      const (fun rates until sample_rate json ->
          run (fun () -> Physics_bench.run ~rates ~until ~sample_rate ~json))
      $ rates $ until $ sample_rate $ json)

let scaling =
  let counts =
    Arg.(
      value
      & opt (list int) [ 1000; 10_000; 100_000 ]
      & info [ "counts" ] ~docv:"N,N,..."
          ~doc:
            "Sphere counts of the object-count sweep (1000000 takes a few GiB and \
             minutes).")
  in
  let width =
    Arg.(
      value & opt int 320
      & info [ "width" ] ~docv:"W" ~doc:"Image width of the count and domain sweeps.")
  in
  let height =
    Arg.(
      value & opt int 240
      & info [ "height" ] ~docv:"H" ~doc:"Image height of the count and domain sweeps.")
  in
  let domains =
    Arg.(
      value & opt int 1 & info [ "domains" ] ~docv:"D" ~doc:"Domains of the count sweep.")
  in
  let domain_counts =
    Arg.(
      value
      & opt (list int) []
      & info [ "domain-counts" ] ~docv:"N,N,..."
          ~doc:
            "Domain counts of the domain sweep (default 1, 2, 4, … up to the recommended \
             count for this machine).")
  in
  let sizes =
    Arg.(
      value
      & opt (list string) [ "160x120"; "320x240"; "640x480"; "1280x960" ]
      & info [ "sizes" ] ~docv:"WxH,..."
          ~doc:"Image sizes of the size sweep (one domain).")
  in
  let base_count =
    Arg.(
      value & opt int 10_000
      & info [ "base-count" ] ~docv:"N" ~doc:"Sphere count of the domain and size sweeps.")
  in
  let sweeps =
    Arg.(
      value
      & opt (list string) [ "counts"; "domains"; "sizes" ]
      & info [ "sweeps" ] ~docv:"NAME,..."
          ~doc:"Which sweeps to run: counts, domains, sizes.")
  in
  let in_process =
    Arg.(
      value & flag
      & info [ "in-process" ]
          ~doc:
            "Measure every configuration in this process instead of one child process \
             each (peak memory is then the running maximum, not the configuration's \
             own).")
  in
  let row =
    Arg.(
      value
      & opt (some string) None
      & info [ "row" ] ~docv:"COUNT,WxH,DOMAINS"
          ~doc:
            "Measure this one configuration in this process and print it as one line of \
             JSON (what the sweeps run in their child processes).")
  in
  let repeat =
    Arg.(
      value & opt int 3
      & info [ "repeat" ] ~docv:"R"
          ~doc:"Renders per configuration; the median time is reported.")
  in
  let man =
    [
      `S Manpage.s_description;
      `P
        "Renders N random spheres (fixed seed, uniform in a cube of side N^(1/3), one \
         point light with shadows, one sample, depth 1) and reports the scene build and \
         BVH build times, the render time (median of R renders), rays per second, minor \
         words allocated per ray and peak resident memory (VmHWM). Three sweeps: the \
         sphere count, the domain count and the image size. Each configuration runs in a \
         child process of this executable, so its peak memory is its own.";
      `S Manpage.s_examples;
      `Pre
        "  lancer_bench scaling --counts 1000,10000,100000,1000000\n\
        \  lancer_bench scaling --sweeps counts --counts 100,1000 --json";
    ]
  in
  Cmd.v
    (Cmd.info "scaling"
       ~doc:
         "build time, render time, rays/s and memory against object count, domains and \
          image size"
       ~man)
    Term.(
      const
        (fun
          counts
          width
          height
          domains
          domain_counts
          sizes
          base_count
          sweeps
          in_process
          row
          repeat
          json
        ->
          run (fun () ->
              Scaling.run ~counts ~width ~height ~domains ~domain_counts ~sizes
                ~base_count ~sweeps ~in_process ~row ~repeat ~json))
      $ counts $ width $ height $ domains $ domain_counts $ sizes $ base_count $ sweeps
      $ in_process $ row $ repeat $ json)

(* The size of the object programs: N × N spheres. *)
let grid doc = Arg.(value & opt int 1000 & info [ "grid" ] ~docv:"N" ~doc)

let language =
  let repeat =
    Arg.(
      value & opt int 3
      & info [ "repeat" ] ~docv:"N" ~doc:"Runs of each program (the median is shown).")
  in
  let grid = grid "The object program builds N × N spheres (1000: a million)." in
  let man =
    [
      `S Manpage.s_description;
      `P
        "Times the scene language on four programs, each a whole check in this process \
         (parse, static check, evaluation): a loop of 3 000 001 iterations computing \
         sin(i) * cos(i); a million sphere blocks built by two nested loops (the \
         objects' evaluation, without the renderer's build); as many spheres, each with \
         a material { color: … } of its own; and as many rotated boxes with a material, \
         in translated groups. When $(b,python3) is on the PATH, the same loop in \
         CPython (math.sin, math.cos) is timed as a whole process, alternating with \
         lancer's runs, and the ratio is shown.";
      `S Manpage.s_examples;
      `Pre "  lancer_bench language --repeat 5";
    ]
  in
  Cmd.v
    (Cmd.info "language"
       ~doc:"speed of the scene language's evaluator, beside CPython on the same loop"
       ~man)
    Term.(
      const (fun repeat grid json -> run (fun () -> Language.run ~repeat ~grid ~json))
      $ repeat $ grid $ json)

let materials =
  let grid = grid "N × N spheres (1000: a million)." in
  let colour =
    Arg.(
      value & flag
      & info [ "colour" ]
          ~doc:"Each sphere with a material of its own, its colour computed in the loop.")
  in
  let man =
    [
      `S Manpage.s_description;
      `P
        "Loads and compiles N × N spheres made by a loop, as a still's render does, in \
         this process, and prints the words per object that each stage holds: the \
         description the language makes, the compiled primitives (their materials \
         included), the materials alone, the acceleration structure, and the largest \
         heap of the process. Run it once with $(b,--colour) and once without: each run \
         is a fresh process, so that the largest heap is that program's.";
      `S Manpage.s_examples;
      `Pre "  lancer_bench materials --grid 1000 --colour";
    ]
  in
  Cmd.v
    (Cmd.info "materials" ~doc:"memory per object of spheres with a colour each" ~man)
    Term.(
      const (fun grid colour json -> run (fun () -> Materials.run ~grid ~colour ~json))
      $ grid $ colour $ json)

let () =
  let doc =
    "the developers' benchmarks of lancer: scaling, physics methods, the language, \
     memory per object"
  in
  exit
    (Cmd.eval'
       (Cmd.group
          (Cmd.info "lancer_bench" ~doc)
          [ physics; scaling; language; materials ]))
