(** A test helper executable: it runs one bad scene and prints its errors, for the diff
    rules of scenes/bad. *)
