(** The developers' benchmarks: [lancer_bench physics|scaling|language] (see bench/dune).
*)
