let render ?cancel ?checkpoint ?region ?alpha ~domains ~on_tile sc =
  match checkpoint with
  | Some ck ->
      (* Finished tiles go to the checkpoint, and come back from it. *)
      (try
         Render.with_pool ?cancel domains (fun pool ->
             Checkpoint.render ?cancel ?pool ~on_tile ck sc)
       with Sys.Break ->
         (try Checkpoint.save ck
          with Job_error.User m ->
            raise (Job_error.Interrupted ("the finished tiles could not be kept: " ^ m)));
         raise Sys.Break);
      (Checkpoint.framebuffer ck, Checkpoint.stats ck)
  | None ->
      Render.with_pool ?cancel domains (fun pool ->
          Render.render ?cancel ?pool
            ~on_tile:(fun d _ rays -> on_tile d rays)
            ?region ?alpha sc)
