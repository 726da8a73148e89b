// Benchmark pair with transforms.rts (see there).
#version 3.7;
global_settings { assumed_gamma 1.0 ambient_light rgb 1 max_trace_level 5 }
background { color rgb <0.1, 0.1, 0.15> }
camera { location <0, 4, -9> direction <0, 0, 0.8660254> up y right x*1920/1080 look_at <0, 0.8, 0> }
light_source { <-4, 8, -6> color rgb 1 }
#declare F = finish { ambient 0.1 diffuse 0.9 phong 0.5 phong_size 40 }
plane { y, 0 pigment { checker color rgb 1 color rgb 0.2 } finish { ambient 0.1 diffuse 0.9 } }
#for (K, 0, 7)
  union {
    union {
      box { <-0.5, 0, -0.5>, <0.5, 1, 0.5> rotate <0, 30, 0>
            pigment { color rgb <0.9, 0.5, 0.2> } finish { F } }
      sphere { <0, 0, 0>, 0.5 scale <0.6, 1.2, 0.6> translate <0, 2, 0>
               pigment { color rgb <0.2, 0.5, 0.9> } finish { F } }
      translate <3, 0, 0>
    }
    rotate <0, 45 * K, 0>
  }
#end
