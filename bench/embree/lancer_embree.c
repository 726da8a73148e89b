/* The Embree side of `make bench-limit`: the scenes of the speed table traced by Embree on
   one thread (rtcIntersect1 for camera rays, rtcOccluded1 for shadow rays), shaded as
   doc/reference/shading.md says for what they use (a pinhole camera, one point light,
   ambient and diffuse terms, a plane, spheres or a flat-shaded mesh), written as a binary
   PPM. Embree works in single precision: each hit's t is recomputed in double on the
   primitive it found, so that only edge pixels may differ from lancer's image.

   lancer_embree field N W H OUT.ppm     the N×N sphere field of scenes/bench/field_*.rts
   lancer_embree grid N W H OUT.ppm      N×N spheres from a loop (bench/embree/bench.sh)
   lancer_embree gridc N W H OUT.ppm     the same, sphere (i, j) of colour (i/N, j/N, 0.5)
   lancer_embree mesh FILE.obj W H OUT.ppm  a white mesh above nothing (bench/embree/bench.sh) */
#include <embree4/rtcore.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct { double x, y, z; } v3;
static v3 V(double x, double y, double z) { v3 r = { x, y, z }; return r; }
static v3 sub(v3 a, v3 b) { return V(a.x - b.x, a.y - b.y, a.z - b.z); }
static v3 madd(v3 a, double s, v3 b) { return V(a.x + s * b.x, a.y + s * b.y, a.z + s * b.z); }
static double dot(v3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static v3 cross(v3 a, v3 b) { return V(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
static v3 normalize(v3 a) { double l = sqrt(dot(a, a)); return l == 0 ? V(0, 0, 0) : madd(V(0, 0, 0), 1 / l, a); }
static double maxabs(v3 a) { return fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z))); }

static int nsph, ntri, plane;            /* plane: y = 0, colour (0.8, 0.8, 0.8) */
static double *sph, *col, *vtx;          /* sphere: cx cy cz r; colour r g b; vertices */
static unsigned *tri;
static v3 cam, look, light, bg;
static double fov;
static RTCScene scene;

static void die(const char *m) { fprintf(stderr, "lancer_embree: %s\n", m); exit(1); }

static void spheres(int n, double s, double lift, int colours) {
  nsph = n * n;
  sph = malloc(sizeof(double) * 4 * nsph); col = malloc(sizeof(double) * 3 * nsph);
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      double *p = sph + 4 * (i * n + j), *c = col + 3 * (i * n + j);
      p[0] = (i - n / 2.) * s; p[1] = lift * s; p[2] = (j - n / 2.) * s; p[3] = 0.4 * s;
      if (colours == 2) { c[0] = (double)i / n; c[1] = (double)j / n; c[2] = 0.5; }
      else { c[0] = colours ? 0.5 + 0.5 * sin(i) : 1; c[1] = colours ? 0.5 + 0.5 * cos(j) : 1; c[2] = colours ? 0.6 : 1; }
    }
}

static void read_obj(const char *path) {
  FILE *f = fopen(path, "r");
  if (!f) die("cannot read the mesh");
  size_t nv = 0, cv = 1 << 16, ct = 1 << 16; char line[512];
  vtx = malloc(sizeof(double) * 3 * cv); tri = malloc(sizeof(unsigned) * 3 * ct);
  while (fgets(line, sizeof line, f)) {
    char *p = line;
    if (p[0] == 'v' && p[1] == ' ') {
      if (nv == cv) vtx = realloc(vtx, sizeof(double) * 3 * (cv *= 2));
      for (int k = 0; k < 3; k++) vtx[3 * nv + k] = strtod(p + (k ? 0 : 2), &p);
      nv++;
    } else if (p[0] == 'f' && p[1] == ' ') {
      if ((size_t)ntri == ct) tri = realloc(tri, sizeof(unsigned) * 3 * (ct *= 2));
      p += 2;
      for (int k = 0; k < 3; k++) { tri[3 * ntri + k] = (unsigned)strtoul(p, &p, 10) - 1; while (*p && *p != ' ') p++; }
      ntri++;
    }
  }
  fclose(f);
  RTCDevice d = rtcGetSceneDevice(scene);
  RTCGeometry g = rtcNewGeometry(d, RTC_GEOMETRY_TYPE_TRIANGLE);
  float *fv = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, nv);
  for (size_t k = 0; k < 3 * nv; k++) fv[k] = (float)vtx[k];
  memcpy(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, ntri), tri, 12 * (size_t)ntri);
  rtcCommitGeometry(g); rtcAttachGeometry(scene, g); rtcReleaseGeometry(g);
}

static void attach_spheres(void) {
  RTCGeometry g = rtcNewGeometry(rtcGetSceneDevice(scene), RTC_GEOMETRY_TYPE_SPHERE_POINT);
  float *b = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 16, nsph);
  for (int k = 0; k < 4 * nsph; k++) b[k] = (float)sph[k];
  rtcCommitGeometry(g); rtcAttachGeometry(scene, g); rtcReleaseGeometry(g);
}

/* The double-precision root on primitive k (the one Embree found), and its normal. */
static double refine(unsigned k, v3 o, v3 d, v3 *n) {
  if (nsph) {
    double *s = sph + 4 * k; v3 c = V(s[0], s[1], s[2]), f = sub(o, c);
    double b = dot(f, d), q = dot(f, f) - s[3] * s[3], disc = b * b - q;
    double t = -b - sqrt(fmax(disc, 0)); if (t <= 0) t = -b + sqrt(fmax(disc, 0));
    *n = normalize(sub(madd(o, t, d), c)); return t;
  }
  unsigned *i = tri + 3 * k; double *a = vtx + 3 * i[0], *b = vtx + 3 * i[1], *c = vtx + 3 * i[2];
  v3 A = V(a[0], a[1], a[2]), e1 = sub(V(b[0], b[1], b[2]), A), e2 = sub(V(c[0], c[1], c[2]), A);
  v3 pv = cross(d, e2); double det = dot(e1, pv); v3 tv = sub(o, A); v3 qv = cross(tv, e1);
  *n = normalize(cross(e1, e2)); return dot(e2, qv) / det;
}

static v3 trace(v3 o, v3 d) {
  struct RTCRayHit rh; memset(&rh, 0, sizeof rh);
  rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z; rh.ray.dir_x = d.x; rh.ray.dir_y = d.y; rh.ray.dir_z = d.z;
  rh.ray.tnear = 0; rh.ray.tfar = INFINITY; rh.ray.mask = -1; rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene, &rh, NULL);
  double tp = plane && d.y != 0 ? -o.y / d.y : INFINITY; if (!(tp > 0)) tp = INFINITY;
  v3 n, c; double t = INFINITY;
  if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
    t = refine(rh.hit.primID, o, d, &n);
    c = nsph ? V(col[3 * rh.hit.primID], col[3 * rh.hit.primID + 1], col[3 * rh.hit.primID + 2]) : V(1, 1, 1);
  }
  if (tp < t) { t = tp; n = V(0, 1, 0); c = V(0.8, 0.8, 0.8); }
  if (t == INFINITY) return bg;
  v3 p = madd(o, t, d), nf = dot(d, n) < 0 ? n : V(-n.x, -n.y, -n.z);
  double delta = 1e-9 * fmax(1e-300, fmax(maxabs(p), maxabs(o)));
  v3 os = madd(p, delta, nf), out = V(0.1 * c.x, 0.1 * c.y, 0.1 * c.z), l = sub(light, p);
  double dist = sqrt(dot(l, l)), k = 1 / dist; v3 ld = V(k * l.x, k * l.y, k * l.z);
  double ndl = dot(nf, ld);
  if (ndl > 0) {
    struct RTCRay r; memset(&r, 0, sizeof r);
    r.org_x = os.x; r.org_y = os.y; r.org_z = os.z; r.dir_x = ld.x; r.dir_y = ld.y; r.dir_z = ld.z;
    /* single precision: start past the rounding of the surface Embree stores */
    r.tnear = 1e-4f; r.tfar = dist; r.mask = -1;
    rtcOccluded1(scene, &r, NULL);
    double tps = plane && ld.y != 0 ? -os.y / ld.y : INFINITY;
    if (r.tfar >= 0 && !(tps > 0 && tps < dist)) {
      double kd = 0.9 * ndl;
      out = V(out.x + kd * c.x, out.y + kd * c.y, out.z + kd * c.z);
    }
  }
  return out;
}

static int encode(double v) {
  v = v > 0 ? v : 0; v = v < 1 ? v : 1;
  v = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1 / 2.4) - 0.055;
  return (int)floor(255 * v + 0.5);
}

int main(int argc, char **argv) {
  if (argc != 6) die("usage: lancer_embree field|grid|gridc N W H OUT.ppm, or mesh FILE.obj W H OUT.ppm");
  int w = atoi(argv[3]), h = atoi(argv[4]);
  RTCDevice dev = rtcNewDevice("threads=1");
  if (!dev) die("no Embree device");
  scene = rtcNewScene(dev);
  if (!strcmp(argv[1], "field")) {           /* scenes/bench/field_N².rts */
    int n = atoi(argv[2]);
    spheres(n, 40. / n, 0.4, 1); plane = 1; attach_spheres();
    cam = V(0, 30, -45); look = V(0, 0, 0); light = V(-20, 40, -30); fov = 50; bg = V(0.1, 0.1, 0.15);
  } else if (!strcmp(argv[1], "grid") || !strcmp(argv[1], "gridc")) { /* bench.sh's loops */
    int n = atoi(argv[2]);
    spheres(n, 1, 0.4, strcmp(argv[1], "grid") ? 2 : 0); attach_spheres();
    cam = V(0, 0.6 * n, -0.9 * n); look = V(0, 0, 0); light = V(-0.4 * n, 0.8 * n, -0.6 * n); fov = 50; bg = V(0, 0, 0);
  } else if (!strcmp(argv[1], "mesh")) {      /* bench/embree/torus.awk's torus */
    read_obj(argv[2]);
    cam = V(0, 3, -4); look = V(0, 0, 0); light = V(-3, 5, -4); fov = 50; bg = V(0, 0, 0);
  } else die("unknown scene kind");
  rtcCommitScene(scene);
  v3 f = normalize(sub(look, cam)), r = normalize(cross(V(0, 1, 0), f)), u = cross(f, r);
  double th = tan(fov * M_PI / 360), a = (double)w / h;
  FILE *o = fopen(argv[5], "wb");
  if (!o) die("cannot write the image");
  fprintf(o, "P6\n%d %d\n255\n", w, h);
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      double x = i + 0.5, y = j + 0.5;
      double sx = ((2 * x / w) - 1) * th * a, sy = (1 - (2 * y / h)) * th;
      v3 d = normalize(V(f.x + (sx * r.x + sy * u.x), f.y + (sx * r.y + sy * u.y), f.z + (sx * r.z + sy * u.z)));
      v3 c = trace(cam, d);
      fputc(encode(c.x), o); fputc(encode(c.y), o); fputc(encode(c.z), o);
    }
  if (fclose(o) != 0) die("cannot write the image");
  rtcReleaseScene(scene); rtcReleaseDevice(dev);
  return 0;
}
