(* Golden-image tests of this project's scenes. Each case renders a scene (at the size its
   settings give) and compares the picture with its golden PNG in golden/.

   First run, or after an intended change:  LANCER_UPDATE_GOLDEN=1 dune test test/example-user
   then look at the new golden/*.png and commit them. *)

let () =
  Alcotest.run "example scenes"
    [
      ( "scenes",
        [
          Lancer_alcotest.test_case "the blue ball" ~scene:"ball.rts"
            ~golden:"golden/ball.png" ();
          Lancer_alcotest.test_case "the tower" ~scene:"tower.rts"
            ~golden:"golden/tower.png" ();
          (* One frame of an animation: the ball just after its first bounce. *)
          Lancer_alcotest.test_case "the dropped ball at frame 20" ~scene:"drop.rts"
            ~frame:20 ~golden:"golden/drop_20.png" ();
        ] );
    ]
