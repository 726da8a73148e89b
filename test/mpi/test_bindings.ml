(* The MPI bindings under mpirun: every rank checks what it received and rank 0 prints
   one line per check. Exit status 0 when all pass on every rank. *)
module Mpi = Lancer_mpi.Mpi

let fail fmt =
  Printf.ksprintf
    (fun s ->
      prerr_endline ("rank " ^ string_of_int (Mpi.rank ()) ^ ": " ^ s);
      Mpi.abort 1)
    fmt

let () =
  Mpi.init ();
  let me = Mpi.rank () and n = Mpi.size () in
  let say s = if me = 0 then print_endline s in
  (* Broadcast of a value. *)
  let v = Mpi.bcast (if me = 0 then Some ("scene", [ 1; 2; 3 ]) else None) ~root:0 in
  if v <> Some ("scene", [ 1; 2; 3 ]) then fail "bcast gave the wrong value";
  say "a broadcast value reaches every rank";
  (* Ring of marshalled values with tags. *)
  if n > 1 then (
    let next = (me + 1) mod n and prev = (me + n - 1) mod n in
    (if me = 0 then (
       Mpi.send (`Token [ 0 ]) ~dest:next ~tag:7;
       let (`Token l : [ `Token of int list ]), src, tag =
         Mpi.recv ~source:Mpi.any_source ~tag:7
       in
       if src <> prev || tag <> 7 || l <> List.init n (fun i -> n - 1 - i) then
         fail "ring token is wrong")
     else
       let (`Token l : [ `Token of int list ]), src, _ = Mpi.recv ~source:prev ~tag:7 in
       if src <> prev then fail "wrong source";
       Mpi.send (`Token (me :: l)) ~dest:next ~tag:7);
    say "a marshalled token goes round the ring with its tag and source";
    (* Floats, bit for bit, including NaN payloads and signed zeros; and probe. *)
    let len = 1000 in
    let a = Bigarray.Array1.create Bigarray.float64 Bigarray.c_layout len in
    for i = 0 to len - 1 do
      a.{i} <-
        (if i = 0 then -0.
         else if i = 1 then Float.nan
         else Float.of_int ((me * 1_000_000) + i) /. 3.)
    done;
    (if me <> 0 then Mpi.send_floats a ~len:(len - me) ~dest:0 ~tag:3
     else
       let b = Bigarray.Array1.create Bigarray.float64 Bigarray.c_layout len in
       for _ = 1 to n - 1 do
         let src, tag, bytes = Mpi.probe ~source:Mpi.any_source ~tag:3 in
         if tag <> 3 || bytes <> 8 * (len - src) then
           fail "probe gave tag %d, %d bytes" tag bytes;
         let count, src', _ = Mpi.recv_floats b ~source:src ~tag:3 in
         if src' <> src || count <> len - src then fail "recv_floats count %d" count;
         for i = 0 to count - 1 do
           let want =
             if i = 0 then -0.
             else if i = 1 then Float.nan
             else Float.of_int ((src * 1_000_000) + i) /. 3.
           in
           if Int64.bits_of_float b.{i} <> Int64.bits_of_float want then
             fail "float %d from %d differs" i src
         done
       done;
       if Mpi.iprobe ~source:Mpi.any_source ~tag:Mpi.any_tag <> None then
         fail "iprobe found a message that is not there");
    say "float arrays arrive bit for bit; probe tells the source, tag and length");
  Mpi.barrier ();
  let t0 = Mpi.wtime () in
  if not (Float.is_finite t0) then fail "wtime";
  say
    (Printf.sprintf "bindings: all checks passed on %d rank%s" n
       (if n = 1 then "" else "s"));
  Mpi.finalize ()
