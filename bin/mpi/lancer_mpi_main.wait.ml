(* Built in place of lancer_mpi_main.cli.ml while the lancer_cli library (bin/common) is
   not part of the build: the command needs its options, loading and writing. *)
let () =
  prerr_endline "lancer-mpi: built without lancer's command-line library (bin/common); rebuild once it is in the tree";
  exit 2
