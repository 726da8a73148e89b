(** The drop of doc/reference/numerics.md in closed form: a ball of radius {!radius} whose
    lowest point starts {!height} above the floor y = 0, at rest, under g = {!g}, bouncing
    with restitution [e]. Written independently of {!Physics}, so that it can check it. *)

val height : float
(** 1 m: the starting gap under the ball. *)

val radius : float
(** 0.1 m. *)

val g : float
(** 9.81 m/s². *)

val first_impact : float
(** The time of the first impact, √(2·height/g) s. *)

val impact_speed : float
(** The speed at the first impact, g·{!first_impact} m/s. *)

val impact_time : float -> int -> float
(** [impact_time e k]: time of the k-th impact (k ≥ 1), s, from the first one and a closed
    sum, never by accumulating flight times. *)

val zeno_time : float -> float
(** The instant the infinitely many bounces of [e] < 1 end; infinite for [e] ≥ 1. *)

val apex_height : float -> int -> float
(** [apex_height e k]: the gap under the ball at the top of its flight after the k-th
    impact. *)

val gap : float -> float -> float
(** [gap e t]: height of the ball's lowest point above the floor at time [t] s. *)
