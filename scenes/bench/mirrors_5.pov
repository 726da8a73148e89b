// Benchmark pair with mirrors_5.rts (see there).
#version 3.7;
global_settings { assumed_gamma 1.0 ambient_light rgb 1 max_trace_level 5 }
background { color rgb <0.1, 0.1, 0.15> }
camera { location <0, 1.5, -2.5> direction <0, 0, 0.8660254> up y right x*1920/1080 look_at <2, 1, 2> }
light_source { <0, 4, 0> color rgb 1 }
plane { y, 0 pigment { checker color rgb 1 color rgb 0.2 } finish { ambient 0.1 diffuse 0.9 } }
plane { x, -3 pigment { color rgb 0.9 } finish { ambient 0 diffuse 0.1 reflection 0.9 } }
plane { x, 3 pigment { color rgb 0.9 } finish { ambient 0 diffuse 0.1 reflection 0.9 } }
sphere { <0, 1, 1>, 0.8 pigment { color rgb <0.9, 0.2, 0.2> } finish { ambient 0.1 diffuse 0.9 phong 0.5 phong_size 50 } }
