// Benchmark pair with glass.rts (see there). The paraboloid x² + z² = (r²/h)·y is a
// quadric clipped to 0 ≤ y ≤ h.
#version 3.7;
global_settings { assumed_gamma 1.0 ambient_light rgb 1 max_trace_level 10 }
background { color rgb <0.3, 0.4, 0.6> }
camera { location <0, 2.5, -6> direction <0, 0, 0.8660254> up y right x*1920/1080 look_at <0, 0.8, 0> }
light_source { <-4, 6, -5> color rgb 1 }
plane { y, 0 pigment { checker color rgb 1 color rgb 0.2 } finish { ambient 0.1 diffuse 0.9 } }
#declare Glass = material {
  texture { pigment { color rgbf <1, 1, 1, 0.9> } finish { ambient 0 diffuse 0.1 phong 0.8 phong_size 100 reflection { 0 1 fresnel on } conserve_energy } }
  interior { ior 1.5 } }
sphere { <-1.3, 1, 0>, 1 material { Glass } }
quadric { <1, 0, 1>, <0, 0, 0>, <0, -0.625, 0>, 0
  clipped_by { box { <-1.01, 0, -1.01>, <1.01, 1.6, 1.01> } }
  material { Glass } translate <1.4, 0.01, 0> }
