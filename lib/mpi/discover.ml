(* Finds the C flags of an MPI library for the stubs: pkg-config first (Debian's
   alternative "mpi-c", then Open MPI's "ompi-c", then MPICH's "mpich"), and Open MPI's
   "mpicc --showme" where pkg-config knows none of them. Without any MPI, lancer-mpi is
   left out of the build by .ci/toolchain (LANCER_MPI=no); reaching this program
   then is an error that says what to install. Writes c_flags.sexp and
   c_library_flags.sexp. *)

module C = Configurator.V1

let from_pkg_config c =
  match C.Pkg_config.get c with
  | None -> None
  | Some pc ->
      List.find_map
        (fun package ->
          match C.Pkg_config.query pc ~package with
          | Some conf -> Some (package, conf.C.Pkg_config.cflags, conf.libs)
          | None -> None)
        [ "mpi-c"; "ompi-c"; "mpich" ]

let from_mpicc c =
  let showme what =
    match C.Process.run c "mpicc" [ "--showme:" ^ what ] with
    | { exit_code = 0; stdout; _ } -> Some (String.split_on_char ' ' (String.trim stdout))
    | _ | (exception _) -> None
  in
  match (showme "compile", showme "link") with
  | Some cflags, Some libs -> Some ("mpicc", cflags, libs)
  | _ -> None

let () =
  C.main ~name:"lancer-mpi" (fun c ->
      let found =
        match from_pkg_config c with Some r -> Some r | None -> from_mpicc c
      in
      match found with
      | Some (_, cflags, libs) ->
          C.Flags.write_sexp "c_flags.sexp" (List.filter (( <> ) "") cflags);
          C.Flags.write_sexp "c_library_flags.sexp" (List.filter (( <> ) "") libs)
      | None ->
          prerr_endline
            "lancer-mpi: no MPI library found (pkg-config mpi-c, ompi-c or mpich; mpicc).\n\
             Install Open MPI (libopenmpi-dev) or MPICH (libmpich-dev), or build without\n\
             lancer-mpi: LANCER_MPI=no dune build";
          exit 1)
