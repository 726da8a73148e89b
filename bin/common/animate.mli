(** [lancer animate]: render an animation's frames to [DIR/frame_0000.png …].

    Frames render one after the other, each over all domains in tiles. Each frame is
    written atomically, and a manifest ([DIR/lancer-frames.json]) records for each frame
    a digest of the scene text, the options that change pixels and the frame number, so
    [--resume] skips frames already written for the same scene and options and re-renders
    those that are missing or stale. [--video] assembles the frames with ffmpeg. *)

val frames_of_string : string -> (int * int, string) result
(** ["A..B"] (inclusive) or ["K"]. *)

val run : Cli.opts -> frames:(int * int) option -> resume:bool -> video:string option -> unit
