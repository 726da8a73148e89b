type t = (Texture.t, Bump.t) Description.material_of

let default : t = Description.default_material
