(** A small SVG chart of time against PSNR for [lancer bench quality --svg]: one series
    per knob, log-scaled time on x, PSNR on y (infinite PSNR drawn at the top). *)

val write : string -> (string * string * float * float) list -> unit
(** [write path rows] with rows (knob, value, seconds, psnr); atomic; raises
    [Cli.User_error] when the file cannot be written. *)
