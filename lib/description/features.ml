type t = {
  shadows : bool;
  soft_shadows : bool;
  reflection : bool;
  refraction : bool;
  textures : bool;
  bump : bool;
  supersampling : bool;
  bvh : bool;
  orthographic : bool;
  fisheye : bool;
  depth_of_field : bool;
  spot_lights : bool;
  sky : bool;
  fog : bool;
  color_maps : bool;
}

let to_list f =
  [
    ("shadows", f.shadows);
    ("soft_shadows", f.soft_shadows);
    ("reflection", f.reflection);
    ("refraction", f.refraction);
    ("textures", f.textures);
    ("bump", f.bump);
    ("supersampling", f.supersampling);
    ("bvh", f.bvh);
    ("orthographic", f.orthographic);
    ("fisheye", f.fisheye);
    ("depth_of_field", f.depth_of_field);
    ("spot_lights", f.spot_lights);
    ("sky", f.sky);
    ("fog", f.fog);
    ("color_maps", f.color_maps);
  ]
