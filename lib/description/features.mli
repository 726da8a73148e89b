(** What a scene requires of the renderer, derived once from the scene so that the
    renderer does only that work: it models only what a scene requires. *)

type t = {
  shadows : bool;  (** shadow rays are cast (settings.shadows and at least one light) *)
  soft_shadows : bool;  (** some light is an area light with several samples *)
  reflection : bool;  (** some material reflects (or may, through Fresnel) *)
  refraction : bool;  (** some material is transparent *)
  textures : bool;  (** some material has a texture *)
  bump : bool;  (** some material has a bump map *)
  supersampling : bool;  (** samples > 1 or adaptive *)
  bvh : bool;  (** a bounding volume hierarchy is used *)
  orthographic : bool;  (** the camera is orthographic *)
  fisheye : bool;  (** the camera is a fisheye *)
  depth_of_field : bool;  (** the camera has an aperture: several lens rays per sample *)
  spot_lights : bool;  (** some light is a spot light *)
  sky : bool;  (** the background is a gradient *)
  fog : bool;  (** rays are fogged *)
  color_maps : bool;  (** some material's texture is coloured by a colour map *)
}

val to_list : t -> (string * bool) list
(** Each feature by name, in a fixed order (for [lancer check] and [--stats]). *)
