// Benchmark pair with field_100000.rts (see there).
#version 3.7;
global_settings { assumed_gamma 1.0 ambient_light rgb 1 max_trace_level 5 }
background { color rgb <0.1, 0.1, 0.15> }
camera { location <0, 30, -45> direction <0, 0, 1.0722535> up y right x*1920/1080 look_at <0, 0, 0> }
light_source { <-20, 40, -30> color rgb 1 }
plane { y, 0 pigment { color rgb 0.8 } finish { ambient 0.1 diffuse 0.9 } }
#declare N = 316;
#declare S = 40 / N;
#declare I = 0;
#while (I < N)
  #declare J = 0;
  #while (J < N)
    sphere { <(I - N / 2) * S, 0.4 * S, (J - N / 2) * S>, 0.4 * S
      pigment { color rgb <0.5 + 0.5 * sin(I), 0.5 + 0.5 * cos(J), 0.6> } finish { ambient 0.1 diffuse 0.9 } }
    #declare J = J + 1;
  #end
  #declare I = I + 1;
#end
