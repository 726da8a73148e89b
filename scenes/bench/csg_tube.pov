// Benchmark pair with csg_tube.rts (see there).
#version 3.7;
global_settings { assumed_gamma 1.0 ambient_light rgb 1 max_trace_level 5 }
background { color rgb <0.1, 0.1, 0.15> }
camera { location <0, 2.2, -6> direction <0, 0, 1.0722535> up y right x*image_width/image_height look_at <0, 0.7, 0> }
light_source { <-3, 5, -4> color rgb 1 area_light <1, 0, 0>, <0, 0, 1>, 4, 4 circular orient }
#declare F = finish { ambient 0.1 diffuse 0.9 phong 0.5 phong_size 40 }
plane { y, 0 pigment { checker color rgb 1 color rgb 0.2 } finish { ambient 0.1 diffuse 0.9 } }
sphere { <-1.7, 0.8, 0.6>, 0.8 pigment { color rgb <0.9, 0.2, 0.2> } finish { F } }
sphere { <1.5, 0.45, -0.9>, 0.45 pigment { color rgb <0.2, 0.3, 0.9> } finish { F } }
box { <0.7, 0, 0.6>, <1.7, 0.7, 1.6> pigment { color rgb <0.2, 0.8, 0.3> } finish { F } }
difference {
  cylinder { <0, 0, 0>, <0, 1.4, 0>, 0.5 }
  cylinder { <0, -0.1, 0>, <0, 1.5, 0>, 0.4 }
  pigment { color rgb <0.8, 0.6, 0.3> } finish { F }
  translate <-0.1, 0, -0.4>
}
