// Benchmark pair with three_spheres.rts (see there).
#version 3.7;
global_settings { assumed_gamma 1.0 ambient_light rgb 1 max_trace_level 5 }
background { color rgb <0.1, 0.1, 0.15> }
camera { location <0, 2, -6> direction <0, 0, 0.8660254> up y right x*1920/1080 look_at <0, 0.7, 0> }
light_source { <-3, 5, -4> color rgb 1 }
#declare F = finish { ambient 0.1 diffuse 0.9 phong 0.5 phong_size 40 }
plane { y, 0 pigment { checker color rgb 1 color rgb 0.2 } finish { ambient 0.1 diffuse 0.9 } }
sphere { <-1.6, 1, 0>, 1 pigment { color rgb <0.9, 0.2, 0.2> } finish { F } }
sphere { <0.6, 0.7, 1>, 0.7 pigment { color rgb <0.2, 0.8, 0.3> } finish { F } }
sphere { <1.4, 0.5, -1.2>, 0.5 pigment { color rgb <0.2, 0.3, 0.9> } finish { F } }
