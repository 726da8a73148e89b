(* A test helper executable: no interface. *)
