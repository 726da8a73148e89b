/* The first step of the sphere test (Shape.sphere_gen) over a leaf's spheres, two at a
   time in the two lanes of a vector. Most rays that reach a leaf of a scene's hierarchy
   miss most of its spheres, which the test's early miss (the ray's line farther from
   the centre than the radius) tells; OCaml computes that test in scalars, a slot at a
   time, its kind read and its result compared one by one. Here a leaf's slots
   [lo, lo + n) of a tree's flat spheres (centre x, y, z and radius, 4 floats a slot;
   NaN for a slot that holds no sphere) are tested at once, with the same operations in
   double precision as Shape.sphere_gen's, in the same order (no contraction into fused
   multiply-adds: -ffp-contract=off), so that a slot is left out exactly where that test
   would take its early miss. The others, whose test goes on past it (and every slot
   without a sphere, whose NaN never compares), are the walk's to test as before. It
   reads its arguments in place and allocates nothing; test/render/test_spheres.ml
   compares it with the OCaml test. */
#include <caml/mlvalues.h>

typedef double v2 __attribute__((vector_size(16)));
typedef long long m2 __attribute__((vector_size(16)));

/* Bit k set for slot lo + k (n ≤ 62) unless that slot's sphere is missed for certain by
   the ray of probe [q] (Probe.t: ox oy oz dx dy dz ..., a record of floats, stored
   flat). */
intnat lancer_sphere_candidates(value vflat, intnat lo, intnat n, value q)
{
  const double *s = (const double *)vflat + 4 * lo;
  double ox = Double_flat_field(q, 0), oy = Double_flat_field(q, 1),
         oz = Double_flat_field(q, 2), dx = Double_flat_field(q, 3),
         dy = Double_flat_field(q, 4), dz = Double_flat_field(q, 5);
  double a = (dx * dx) + (dy * dy) + (dz * dz);
  v2 vox = {ox, ox}, voy = {oy, oy}, voz = {oz, oz};
  v2 vdx = {dx, dx}, vdy = {dy, dy}, vdz = {dz, dz}, va = {a, a};
  v2 slack = {1. + 1e-9, 1. + 1e-9}, huge = {1e280, 1e280};
  intnat misses = 0;
  for (intnat k = 0; k < n; k += 2) {
    /* An odd count's last pair tests its last slot twice; the bit past it is cut. */
    const double *p = s + 4 * k, *r = k + 1 < n ? p + 4 : p;
    v2 fx = vox - (v2){p[0], r[0]}, fy = voy - (v2){p[1], r[1]},
       fz = voz - (v2){p[2], r[2]}, rad = {p[3], r[3]};
    v2 b = (fx * vdx) + (fy * vdy) + (fz * vdz);
    v2 t = -b / va;
    v2 px = fx + (t * vdx), py = fy + (t * vdy), pz = fz + (t * vdz);
    v2 l2 = (px * px) + (py * py) + (pz * pz);
    m2 miss = (l2 > rad * rad * slack) & (l2 < huge);
    misses |= (intnat)(miss[0] & 1) << k;
    misses |= (intnat)(miss[1] & 1) << (k + 1);
  }
  return ~misses & (((intnat)1 << n) - 1);
}

value lancer_sphere_candidates_byte(value flat, value lo, value n, value q)
{
  return Val_long(lancer_sphere_candidates(flat, Long_val(lo), Long_val(n), q));
}
