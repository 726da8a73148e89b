(** The [--quality] presets: named points on the speed/accuracy trade.

    | preset    | samples | adaptive | depth    | area-light samples |
    |-----------|---------|----------|----------|--------------------|
    | draft     | 1       | off      | ≤ 3      | 1 (hard shadows)   |
    | preview   | 1       | off      | scene    | ≤ 3                |
    | final     | 4       | 0.02     | ≥ 8      | scene              |
    | reference | 8       | off      | ≥ 16     | ≥ 8                |

    Explicit [--samples] and [--depth] override a preset. *)

type t = Draft | Preview | Final | Reference

val all : (string * t) list
val to_string : t -> string
val apply : t -> Lancer.Scene.t -> (Lancer.Scene.t, string) result
