type t = {
  shadows : bool;
  soft_shadows : bool;
  reflection : bool;
  refraction : bool;
  textures : bool;
  bump : bool;
  supersampling : bool;
  bvh : bool;
}

let to_list f =
  [ ("shadows", f.shadows); ("soft_shadows", f.soft_shadows); ("reflection", f.reflection);
    ("refraction", f.refraction); ("textures", f.textures); ("bump", f.bump);
    ("supersampling", f.supersampling); ("bvh", f.bvh) ]
