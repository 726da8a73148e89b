(** The [--quality] presets: named points on the speed/accuracy trade.

    - draft: 1 sample, adaptive off, depth ≤ 3, area lights 1 sample (hard shadows), an
      open shutter 1 instant;
    - preview: 1 sample, adaptive off, the scene's depth, area lights ≤ 3, shutter 4
      instants;
    - final: 4 samples, adaptive 0.02, depth ≥ 8, the scene's area lights, shutter 8
      instants;
    - reference: 8 samples, adaptive off, depth ≥ 16, area lights ≥ 8, shutter 32
      instants.

    Explicit [--samples] and [--depth] override a preset. *)

type t = Draft | Preview | Final | Reference

val all : (string * t) list
(** Each preset with its name, from the fastest to the most accurate. *)

val to_string : t -> string
(** The preset's name, as [--quality] takes it. *)

val apply : t -> Scene.t -> (Scene.t, string) result
(** The scene with the preset's settings, area-light samples and shutter samples (for an
    open shutter). *)
