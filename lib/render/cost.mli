(** An estimate of the rays a render of a scene will trace, before any is traced, from its
    settings, lights and materials alone: what [lancer check] prints for each quality
    preset, and what warns before a long render.

    It assumes every primary ray hits something lit by every light (so shadow rays are
    counted in full), and a pixel of adaptive sampling refined to the full grid: the real
    count is lower where rays miss, lights face away or pixels are smooth. *)

type t = {
  primary : float;
      (** camera rays: width × height × the most samples a pixel takes (× lens_samples²
          with depth of field) *)
  primary_low : float;
      (** the same with adaptive sampling refining no pixel (2×2 samples each); equal to
          [primary] without adaptive sampling *)
  direct : float;  (** [primary] rays and the shadow rays of each primary hit *)
  direct_low : float;  (** the same from [primary_low] *)
  bound : float;
      (** an upper bound with every reflection and refraction followed to the maximum
          depth (each ray that hits casts its shadow rays), but never more than the
          {!Lancer_render.Shade.max_secondary} secondary rays a camera sample may cast;
          equal to [direct] for a scene that neither reflects nor refracts *)
}

val samples_per_pixel : Settings.t -> int
(** The most samples a pixel takes: n² with n×n samples, or 2×2 plus the refined max(n,
    4)² grid with adaptive sampling. *)

val shadow_rays_per_hit : Scene.t -> int
(** Shadow rays cast at each lit point: 1 per point or directional light, n² per area
    light of n×n samples; 0 without shadows. *)

val estimate : Scene.t -> t
(** The figures above for [scene] as it is (settings, lights, materials). *)
