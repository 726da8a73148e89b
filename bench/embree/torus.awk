# A torus of 2·NU·NV triangles (R = 1, r = 0.35, lying in the y = 0 plane) as a Wavefront
# OBJ on standard output: awk -v NU=1000 -v NV=500 -f torus.awk > torus.obj
BEGIN {
  pi = atan2(0, -1)
  for (i = 0; i < NU; i++)
    for (j = 0; j < NV; j++) {
      u = 2 * pi * i / NU; v = 2 * pi * j / NV
      printf "v %.9f %.9f %.9f\n", (1 + 0.35 * cos(v)) * cos(u), 0.35 * sin(v), (1 + 0.35 * cos(v)) * sin(u)
    }
  for (i = 0; i < NU; i++)
    for (j = 0; j < NV; j++) {
      a = i * NV + j + 1; b = ((i + 1) % NU) * NV + j + 1
      c = ((i + 1) % NU) * NV + (j + 1) % NV + 1; d = i * NV + (j + 1) % NV + 1
      printf "f %d %d %d\nf %d %d %d\n", a, b, c, a, c, d
    }
}
