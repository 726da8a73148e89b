# N literal sphere blocks, as exporters and scripts write them (coordinates at full
# precision, each sphere naming one of K materials defined at the top), on standard
# output; with POV=1 the same scene in POV-Ray's language (each material a #declare'd
# texture): awk -v N=100000 -v K=50 [-v POV=1] -f literal_spheres.awk > spheres.rts
BEGIN {
  if (N == "") N = 100000
  if (K == "") K = 50
  srand(7)
  if (POV) {
    print "camera { location <0, 60, -160> look_at <0, 0, 0> angle 60 }"
    print "light_source { <-100, 200, -150> color rgb <1, 1, 1> }"
  } else {
    print "camera { position: (0, 60, -160), look_at: (0, 0, 0), fov: 60 }"
    print "light { position: (-100, 200, -150) }"
  }
  for (k = 0; k < K; k++) {
    r = rand(); g = rand(); b = rand(); s = rand()
    if (POV) printf "#declare m%d = texture { pigment { color rgb <%.6f, %.6f, %.6f> } finish { specular %.6f } }\n", k, r, g, b, s
    else printf "let m%d = material { color: (%.6f, %.6f, %.6f), specular: %.6f }\n", k, r, g, b, s
  }
  for (i = 0; i < N; i++) {
    x = (rand() - 0.5) * 200; y = rand() * 20; z = (rand() - 0.5) * 200
    r = 0.05 + rand() * 0.5; k = int(rand() * K)
    if (POV) printf "sphere { <%.17g, %.17g, %.17g>, %.17g texture { m%d } }\n", x, y, z, r, k
    else printf "sphere { center: (%.17g, %.17g, %.17g), radius: %.17g, material: m%d }\n", x, y, z, r, k
  }
}
