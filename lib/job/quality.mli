(** The [--quality] presets: named points on the speed/accuracy trade.

    | preset | samples | adaptive | depth | area-light samples |
    |-----------|---------|----------|----------|--------------------| | draft | 1 | off |
    ≤ 3 | 1 (hard shadows) | | preview | 1 | off | scene | ≤ 3 | | final | 4 | 0.02 | ≥ 8
    | scene | | reference | 8 | off | ≥ 16 | ≥ 8 |

    Explicit [--samples] and [--depth] override a preset. *)

type t = Draft | Preview | Final | Reference

val all : (string * t) list
(** Each preset with its name, from the fastest to the most accurate. *)

val to_string : t -> string
(** The preset's name, as [--quality] takes it. *)

val apply : t -> Scene.t -> (Scene.t, string) result
(** The scene with the preset's settings and area-light samples. *)
