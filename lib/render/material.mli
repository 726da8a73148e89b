(** Surface materials as the renderer shades them: the description's material record
    ({!Lancer_description.Description.material_of}, where every field, its default and its
    invariants are written), with its texture and bump map decoded. *)

type t = (Texture.t, Bump.t) Description.material_of

val default : t
(** {!Lancer_description.Description.default_material}: white, ambient 0.1, diffuse 0.9,
    no texture or bump. *)
