(** A small SVG chart of time against PSNR for [lancer bench quality --svg]: one series
    per knob, log-scaled time on x (ticks at 1, 2, 5 × 10ᵏ, each at its own value), PSNR
    on y (infinite PSNR drawn along the top), each point labelled with its value where the
    label does not overlap another, and an SVG tooltip with the exact figures. *)

val write : ?title:string -> string -> (string * string * float * float) list -> unit
(** [write ?title path rows] with rows (knob, value, seconds, psnr); atomic; raises
    [Lancer.Job_error.User] when the file cannot be written. *)
