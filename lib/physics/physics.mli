(** Newtonian motion of dynamic spheres under gravity, bouncing off static colliders and
    each other: computed once per scene, then sampled at any time.

    Everything here is a pure function of its inputs: the same world, colliders, bodies
    and horizon give the same trajectory bit for bit, however and wherever it is sampled.
    Units are the scene's (metres, seconds, kilograms in the examples); times are seconds
    from the start of the animation.

    {2 Methods}

    - [Exact] is event-driven. Between events a body moves in closed form, p(τ) = p₀ +
      v₀·τ + ½·a·τ² with a = g in flight. Impacts are the roots of the contact equation
      (gap = 0 while approaching): a degree-2 polynomial for a face or plane and for two
      flying spheres (both share gravity), degree 4 for an edge (capsule), a corner
      (point) or a pair where one body rests. Quadratics use the stable form; higher
      degrees are isolated between the roots of their derivative and bisected, so no
      impact is missed at any speed (no tunnelling). Events are processed in time order
      and each event's time is the body's last event time plus the root Δt, never a sum of
      steps.
    - [Verlet] (velocity Verlet) and [Euler] (explicit) advance every body by [step] and
      exist to measure the speed/accuracy trade (see below).

    {2 Impacts}

    The impulse is along the contact normal. A body with restitution e reflects its normal
    velocity as v'ₙ = −e·vₙ off static colliders; a pair uses e₁·e₂, conserves momentum
    and applies the impulse along the line of centres. Colliders are two-sided and
    frictionless; a box is its six faces, twelve edges and eight corners (so a ball inside
    a box bounces off its inner walls).

    {2 Resting rule (Exact)}

    A bounce off a face or plane whose rebound would rise less than {!rest_fraction} of
    the body's radius (v'ₙ² / (2·|a·n̂|) < rest_fraction·r, the acceleration a pointing
    into the surface) ends the Zeno cascade: the body rests on that surface. Its normal
    velocity is set to 0 and its acceleration becomes the tangential part of gravity, g −
    (g·n̂)·n̂, so it stays put on a level surface and slides (frictionless) on an incline. A
    resting body that slides into a second surface (face, edge or corner) under the same
    rule, or whose rebound its support would turn back into it, rests on both and slides
    along their crease; a third support stops it. Approach speeds under 1e-9 m/s are
    grazing touches, not impacts. A supported body struck by another moves only as its
    supports allow (they take their share of the impulse). It leaves a support when an
    impulse lifts it or bounces it off faster than the resting threshold, or, on a finite
    face, when its centre passes the face's border (it then flies; it does not roll around
    the edge, which it may graze). An [Exact] simulation stops handling collisions after
    {!max_events} events ({!truncated} then holds) rather than loop.

    Not modelled: friction and rolling; a sphere resting on another sphere (after its
    bounces die out, a ball dropped exactly on top of another sinks through it).

    {2 Fixed-step collision handling (Verlet, Euler)}

    After each step, each body is tested against each collider in order, then each pair:
    if the centre is closer than r to the collider's closest point (or two spheres
    overlap), it is pushed out along the normal to touching distance (pairs share the push
    by inverse mass) and, if approaching, its normal velocity is reflected with
    restitution. Contacts are only seen at step ends, so these methods show the documented
    errors: a fast small sphere can pass through a thin plate, and clamping at step end
    adds energy to every bounce (first apex ≈ 1.068 m instead of 1 m for a 1 m drop at
    step 1/30). In free flight Verlet is exact for constant gravity and Euler lags by
    g·dt·t/2. There is no resting rule: a ball on the floor jitters by about g·dt².
    Between steps, positions are interpolated by cubic Hermite (exact for constant
    acceleration), velocities linearly. *)

type body = Description.body = {
  name : string;  (** unique among the bodies of a simulation *)
  center : Vec3.t;  (** initial centre *)
  radius : float;  (** > 0 *)
  velocity : Vec3.t;  (** initial velocity *)
  mass : float;  (** > 0 *)
  restitution : float;  (** in [0, 1]; 1 is elastic *)
  loc : Loc.t;  (** where the scene defines it *)
}
(** A scene's bodies, as its description states them. *)

val body :
  ?velocity:Vec3.t ->
  ?mass:float ->
  ?restitution:float ->
  ?loc:Loc.t ->
  name:string ->
  center:Vec3.t ->
  radius:float ->
  unit ->
  body
(** [body ~name ~center ~radius ()] is a sphere at rest (defaults: velocity 0, mass 1,
    restitution 1, defined at {!Lancer_diag.Loc.whole_file} [name]). *)

type collider =
  | Plane of { normal : Vec3.t; offset : float }
      (** n̂·P = offset with n̂ = normalize normal; infinite, two-sided *)
  | Parallelogram of { origin : Vec3.t; edge1 : Vec3.t; edge2 : Vec3.t }
      (** the points origin + u·edge1 + v·edge2, u, v ∈ [0, 1]; two-sided *)
  | Box of { min : Vec3.t; max : Vec3.t }
      (** axis-aligned, solid from outside, walls from inside *)

type method_ = Description.physics_method = Exact | Verlet | Euler

type world = Description.physics = {
  gravity : Vec3.t;  (** m/s², default (0, −9.81, 0) *)
  method_ : method_;  (** default [Exact] *)
  step : float;  (** s, the fixed step of [Verlet] and [Euler] (> 0), default 1/240 *)
}
(** A scene's [physics] block, as its description states it. *)

val default_world : world
(** Gravity (0, −9.81, 0), [Exact], step 1/240 s
    ({!Lancer_description.Description.default_physics}). *)

val colliders : Description.obj list -> (collider list, Description.obj) result
(** The static obstacles among a description's objects (those that are not a body's
    sphere): every plane, parallelogram and box, in world space (a rotated box as its six
    faces), and the members of a union or merge made only of those, in order. Other shapes
    are not obstacles. [Error o]: [o] is a CSG object that is not such a union or merge,
    which bodies could not collide with as it is drawn. *)

(** What a body hit: a collider, by its index in the list given to {!simulate}, or another
    body, by name. *)
type target = Collider of int | Body of string

type kind =
  | Bounce  (** an impact that reflected the normal velocity *)
  | Rest  (** an impact under the resting threshold: the body now rests on the surface *)
  | Leave  (** a resting body slid off the border of a finite face and flies again *)

type event = {
  time : float;  (** s *)
  body : string;
  target : target;  (** for a pair, the other body; the event is listed once per pair *)
  kind : kind;
  speed : float;  (** normal approach speed at the event, m/s (≥ 0; 0 for [Leave]) *)
}

type trajectory
(** The motion of every body from time 0 to the horizon, with its events. *)

val simulate : world -> collider list -> body list -> until:float -> trajectory
(** [simulate world colliders bodies ~until] computes the motion over [0, until] s. Raises
    [Invalid_argument] on a non-positive radius, mass or step, a restitution outside
    [0, 1], or a duplicated body name. *)

val sample : trajectory -> string -> float -> (Vec3.t * Vec3.t) option
(** [sample tr name t] is the (position, velocity) of body [name] at time [t] s, or [None]
    for an unknown name. Before 0 it is the initial state; after the horizon the last
    motion continues without collisions. Positions are continuous in [t]; velocities jump
    at impacts (the value at an impact's time is the one after it). *)

val events : trajectory -> event list
(** [events tr] are the impacts and state changes, in time order (ties in body order). *)

val names : trajectory -> string list
(** The bodies' names, in the order given. *)

val until : trajectory -> float
(** The horizon the trajectory was computed for, s. *)

val truncated : trajectory -> bool
(** Whether an [Exact] simulation hit {!max_events} before its horizon. *)

val rest_fraction : float
(** 1e-4: a bounce rising less than this fraction of the radius comes to rest. *)

val max_events : int
(** 100_000: the most events an [Exact] simulation processes. *)
