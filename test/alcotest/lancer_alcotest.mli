(** Golden-image tests for lancer scenes, as alcotest checks.

    A golden test renders a scene and compares the encoded image with a stored PNG under a
    per-channel tolerance, or a limit in another metric (mean FLIP, SSIM, RMSE, PSNR). On
    failure it writes [NAME.actual.png] and [NAME.diff.png] next to the golden file (in
    the source tree when run by dune), prints their paths, the figures and the objects of
    the scene the changed pixels lie on ({!Lancer.Aov_run.golden_hint}), and fails. With
    the environment variable [LANCER_UPDATE_GOLDEN=1] it writes the golden instead (making
    its directory if needed) and passes: goldens change only on that explicit request.

    {[
      let () =
        Alcotest.run "my scenes"
          [
            ( "looks",
              [
                Lancer_alcotest.test_case "the red ball" ~scene:"ball.rts"
                  ~golden:"ball.png" ();
              ] );
          ]
    ]} *)

type outcome = Lancer.Compare.outcome =
  | Same of Lancer.Compare.t  (** within tolerance *)
  | Updated of string  (** golden (re)written at this path *)
  | Different of { figures : Lancer.Compare.t; actual : string; diff : string }
      (** beyond tolerance; where the actual and diff images were written *)
  | Missing of { actual : string }  (** no golden yet; the actual image was written *)

val render_scene :
  ?width:int ->
  ?height:int ->
  ?samples:int ->
  ?quality:Lancer.Quality.t ->
  ?time:float ->
  ?frame:int ->
  ?domains:int ->
  string ->
  (int * int * Bytes.t, string) result
(** [render_scene path] loads, evaluates and renders a scene file, and encodes it with its
    gamma: (width, height, RGB bytes). The scene is evaluated at [time] (seconds), or at
    frame [frame] of its animation (time = frame / fps; the scene needs an animation block
    with more than [frame] frames), at time 0 by default. [quality] applies a preset, then
    [width], [height] and [samples] (N×N per pixel) override the scene's settings: the
    image [lancer render --quality --samples --width --height --time/--frame] writes. *)

val compare_golden :
  ?tolerance:int ->
  ?max_share:float ->
  ?metric:Lancer.Compare.metric ->
  golden:string ->
  int * int * Bytes.t ->
  (outcome, string) result
(** Compare an encoded image with the golden file, writing images as described above. *)

val check :
  ?tolerance:int ->
  ?max_share:float ->
  ?metric:Lancer.Compare.metric ->
  ?width:int ->
  ?height:int ->
  ?samples:int ->
  ?quality:Lancer.Quality.t ->
  ?time:float ->
  ?frame:int ->
  scene:string ->
  golden:string ->
  unit ->
  unit
(** Render as {!render_scene} does and compare; an alcotest failure with a useful message
    unless [Same] or [Updated]. [tolerance] (default 1) is the largest per-channel
    difference allowed; [max_share] (default 0) the share of pixels allowed to exceed it.
    A [metric] judges the image by another figure instead, e.g.
    [~metric:(Lancer.Compare.Flip 0.01)] (mean FLIP at most 0.01) or
    [~metric:(Lancer.Compare.Ssim 0.98)], and makes the diff image FLIP's error map. Under
    dune it also fails when a file the scene reads (an include, an image, a mesh) or the
    golden is not among the test's dependencies, naming the file and what to add to the
    stanza's [deps]: without it dune would not run the test again when that file changes.
    After a pass the [.actual.png] and [.diff.png] of an earlier failure are removed. *)

val test_case :
  ?speed:Alcotest.speed_level ->
  ?tolerance:int ->
  ?max_share:float ->
  ?metric:Lancer.Compare.metric ->
  ?width:int ->
  ?height:int ->
  ?samples:int ->
  ?quality:Lancer.Quality.t ->
  ?time:float ->
  ?frame:int ->
  string ->
  scene:string ->
  golden:string ->
  unit ->
  unit Alcotest.test_case
(** [test_case name ~scene ~golden ()] is {!check} as a named alcotest case. *)

val updating : unit -> bool
(** Whether [LANCER_UPDATE_GOLDEN] asks for goldens to be rewritten. *)

val source_path : string -> string
(** Under dune, a path relative to the test's directory in the source tree (found through
    [DUNE_SOURCEROOT] and the build directory); elsewhere the path itself. *)
