/* The descent of every walk of a hierarchy ([Bvh.start], [Bvh.next_leaf]), the one loop
   of the renderer written in C. OCaml (without flambda) compiles each float minimum and
   maximum as a comparison and a jump, six of them a box, and the processor mispredicts
   many of them; here each is one instruction without a branch, and the two children's
   boxes are tested side by side in the two lanes of a vector (GCC's vector extensions,
   with SSE2's MAXPD and MINPD on x86-64). The arithmetic is the same, operation for
   operation, as the scalar test in double precision (no contraction into fused
   multiply-adds: -ffp-contract=off), so that the walk visits the same leaves in the same
   order; test/render/descent_ref.ml is that scalar test, and test_bvh compares the two
   step by step. It reads and writes the walk's OCaml values in place: it allocates
   nothing, and the integers it stores are immediate, so that no write barrier is due. */
#include <caml/mlvalues.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

typedef double v2 __attribute__((vector_size(16)));
typedef long long m2 __attribute__((vector_size(16)));

/* [a > b ? a : b] and [a < b ? a : b] per lane: a NaN in [a] gives [b], so that a slab
   whose t is NaN (0·inf: an origin on a slab plane, the ray parallel to it) leaves the
   interval open. */
static inline v2 vmax(v2 a, v2 b)
{
#ifdef __SSE2__
  return _mm_max_pd(a, b); /* MAXPD is defined as exactly this */
#else
  m2 m = a > b;
  return (v2)(((m2)a & m) | ((m2)b & ~m));
#endif
}

static inline v2 vmin(v2 a, v2 b)
{
#ifdef __SSE2__
  return _mm_min_pd(a, b); /* MINPD likewise */
#else
  m2 m = a < b;
  return (v2)(((m2)a & m) | ((m2)b & ~m));
#endif
}

/* Coordinate [k] of two boxes, [l]'s in lane 0 and [r]'s in lane 1. */
static inline v2 pair(const double *l, const double *r, int k)
{
  v2 v = {l[k], r[k]};
  return v;
}

/* Bvh.walk: ids, ts, sp, span. */
#define Ids(st) Field(st, 0)
#define Ts(st) ((double *)Field(st, 1))
#define Span(st) ((double *)Field(st, 3))

/* A walk's ray, each value in both lanes, and the offsets of its near and far planes in
   a node. */
struct ray {
  v2 ox, oy, oz, ix, iy, iz, tmin;
  int nx, ny, nz, fx, fy, fz;
};

/* The entry t of ray [y] into box [l] (lane 0) and box [r] (lane 1) within
   [y.tmin, tmax], or inf for a miss. */
static inline __attribute__((always_inline)) v2 entries(struct ray y, const double *l,
                                                        const double *r, v2 tmax)
{
  v2 inf = {__builtin_inf(), __builtin_inf()};
  v2 t0 = vmax((pair(l, r, y.nx) - y.ox) * y.ix, y.tmin);
  v2 t1 = vmin((pair(l, r, y.fx) - y.ox) * y.ix, tmax);
  t0 = vmax((pair(l, r, y.ny) - y.oy) * y.iy, t0);
  t1 = vmin((pair(l, r, y.fy) - y.oy) * y.iy, t1);
  t0 = vmax((pair(l, r, y.nz) - y.oz) * y.iz, t0);
  t1 = vmin((pair(l, r, y.fz) - y.oz) * y.iz, t1);
  m2 met = t0 <= t1;
  return (v2)(((m2)t0 & met) | ((m2)inf & ~met));
}

/* The walk of probe [q] (Probe.t: ox oy oz dx dy dz ix iy iz ..., a record of floats,
   stored flat) over [nodes], on stack [st], to its next leaf (-1: none is left). With
   [first], the stack is emptied and the walk begins at the root if the ray enters its
   box within the span. The stack's entries whose entry t is beyond the span's second (the best
   t of a nearest walk) are passed over; at an interior node the nearer child met comes
   next and the farther one is pushed with its entry t, so that leaves come nearest
   first. A node is 8 floats: min x y z, max x y z, then (first, count > 0) for a leaf,
   (right child, 0) for an interior node, whose left child is the next node. */
static inline __attribute__((always_inline)) intnat walk(value vnodes, value q, value st,
                                                         int first)
{
  const double *nodes = (const double *)vnodes;
  double ox = Double_flat_field(q, 0), oy = Double_flat_field(q, 1),
         oz = Double_flat_field(q, 2), ix = Double_flat_field(q, 6),
         iy = Double_flat_field(q, 7), iz = Double_flat_field(q, 8);
  double tmin = Span(st)[0], best = Span(st)[1], inf = __builtin_inf();
  /* Each axis's near plane by the sign of its reciprocal direction (0: the min plane, 3:
     the max), so that a slab costs one maximum and one minimum. */
  int nx = ix < 0. ? 3 : 0, ny = 1 + (iy < 0. ? 3 : 0), nz = 2 + (iz < 0. ? 3 : 0);
  struct ray y = {{ox, ox}, {oy, oy}, {oz, oz}, {ix, ix}, {iy, iy}, {iz, iz},
                  {tmin, tmin}, nx, ny, nz, 3 - nx, 5 - ny, 7 - nz};
  v2 vbest = {best, best};
  value ids = Ids(st);
  double *ts = Ts(st);
  intnat sp, node = -1, leaf = -1;
  if (first) {
    double t = entries(y, nodes, nodes, vbest)[0];
    if (!(t < inf)) {
      Field(st, 2) = Val_long(0);
      return -1;
    }
    node = 0;
    sp = 0;
  } else
    sp = Long_val(Field(st, 2));
  for (;;) {
    if (node < 0) {
      while (node < 0 && sp > 0) {
        sp--;
        if (ts[sp] <= best) node = Long_val(Field(ids, sp));
      }
      if (node < 0) break;
    } else {
      const double *nk = nodes + 8 * node;
      if ((intnat)nk[7] > 0) {
        leaf = node;
        break;
      }
      intnat l = node + 1, r = (intnat)nk[6];
      v2 t = entries(y, nodes + 8 * l, nodes + 8 * r, vbest);
      double tl = t[0], tr = t[1];
      if (tl < inf) {
        if (tr < inf) {
          if (tr < tl) {
            Field(ids, sp) = Val_long(l);
            ts[sp] = tl;
            sp++;
            node = r;
          } else {
            Field(ids, sp) = Val_long(r);
            ts[sp] = tr;
            sp++;
            node = l;
          }
        } else
          node = l;
      } else
        node = tr < inf ? r : -1;
    }
  }
  Field(st, 2) = Val_long(sp);
  return leaf;
}

intnat lancer_next_leaf(value nodes, value q, value st) { return walk(nodes, q, st, 0); }

intnat lancer_first_leaf(value nodes, value q, value st) { return walk(nodes, q, st, 1); }

value lancer_next_leaf_byte(value nodes, value q, value st)
{
  return Val_long(walk(nodes, q, st, 0));
}

value lancer_first_leaf_byte(value nodes, value q, value st)
{
  return Val_long(walk(nodes, q, st, 1));
}
