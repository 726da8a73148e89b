// An independent reader of the linear images lancer writes, for the tests: OpenEXR files
// through OpenEXR's C++ library (Imf::InputFile), Radiance .hdr and .pfm files by
// their own few lines here. Prints "WIDTH HEIGHT CHANNELS" and then, row by row from the
// top, each pixel's values (R G B, and A for EXR), one pixel a line; for EXR the head
// line also says whether the channels are half or float.
#include <ImfInputFile.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

static int fail(const std::string &m) {
  std::cerr << "read_linear: " << m << "\n";
  return 2;
}

static int exr(const char *path) {
  Imf::InputFile file(path);
  const Imf::Header &hd = file.header();
  Imath::Box2i dw = hd.dataWindow();
  int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
  bool alpha = hd.channels().findChannel("A") != nullptr;
  int nc = alpha ? 4 : 3;
  const char *names[4] = {"R", "G", "B", "A"};
  const Imf::Channel *r = hd.channels().findChannel("R");
  if (!r) return fail("no R channel");
  std::vector<float> px((size_t)w * h * nc);
  Imf::FrameBuffer fb;
  for (int c = 0; c < nc; c++)
    fb.insert(names[c], Imf::Slice(Imf::FLOAT,
                                   (char *)(px.data() + c - ((size_t)dw.min.x + (size_t)dw.min.y * w) * nc),
                                   sizeof(float) * nc, sizeof(float) * nc * w));
  file.setFrameBuffer(fb);
  file.readPixels(dw.min.y, dw.max.y);
  printf("%d %d %d %s\n", w, h, nc, r->type == Imf::HALF ? "half" : "float");
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      const float *p = px.data() + ((size_t)j * w + i) * nc;
      for (int c = 0; c < nc; c++) printf(c ? " %.9g" : "%.9g", p[c]);
      printf("\n");
    }
  return 0;
}

static std::string slurp(const char *path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

static int pfm(const char *path) {
  std::string d = slurp(path);
  std::istringstream in(d);
  std::string magic;
  int w, h;
  double scale;
  in >> magic >> w >> h >> scale;
  if (magic != "PF") return fail("not an RGB PFM");
  in.get();
  size_t off = (size_t)in.tellg();
  if (d.size() < off + (size_t)w * h * 12) return fail("truncated PFM");
  bool little = scale < 0;
  printf("%d %d 3\n", w, h);
  for (int j = 0; j < h; j++)
    for (int i = 0; i < w; i++) {
      int row = h - 1 - j;  // rows are stored from the bottom
      float v[3];
      for (int c = 0; c < 3; c++) {
        unsigned char b[4];
        memcpy(b, d.data() + off + 4 * (3 * ((size_t)row * w + i) + c), 4);
        uint32_t u = little ? (b[0] | b[1] << 8 | b[2] << 16 | (uint32_t)b[3] << 24)
                            : (b[3] | b[2] << 8 | b[1] << 16 | (uint32_t)b[0] << 24);
        memcpy(&v[c], &u, 4);
      }
      printf("%.9g %.9g %.9g\n", v[0], v[1], v[2]);
    }
  return 0;
}

static int hdr(const char *path) {
  std::string d = slurp(path);
  size_t pos = 0;
  int w = -1, h = -1;
  bool format_ok = false;
  // Header lines up to an empty one, then the resolution line.
  for (;;) {
    size_t e = d.find('\n', pos);
    if (e == std::string::npos) return fail("no header end");
    std::string line = d.substr(pos, e - pos);
    pos = e + 1;
    if (line == "FORMAT=32-bit_rle_rgbe") format_ok = true;
    if (line.empty()) break;
  }
  if (!format_ok) return fail("no RGBE format line");
  size_t e = d.find('\n', pos);
  if (sscanf(d.substr(pos, e - pos).c_str(), "-Y %d +X %d", &h, &w) != 2)
    return fail("no -Y H +X W line");
  pos = e + 1;
  printf("%d %d 3\n", w, h);
  for (int j = 0; j < h; j++) {
    // Flat scanlines only: a run-length encoded one starts with 2 2.
    if (w >= 8 && w < 32768 && (unsigned char)d[pos] == 2 && (unsigned char)d[pos + 1] == 2)
      return fail("run-length encoded scanline");
    for (int i = 0; i < w; i++, pos += 4) {
      if (pos + 4 > d.size()) return fail("truncated HDR");
      unsigned char *p = (unsigned char *)d.data() + pos;
      double f = p[3] ? std::ldexp(1.0, (int)p[3] - (128 + 8)) : 0.0;
      printf("%.9g %.9g %.9g\n", p[0] * f, p[1] * f, p[2] * f);
    }
  }
  return 0;
}

int main(int argc, char **argv) {
  if (argc != 3) return fail("usage: read_linear exr|hdr|pfm FILE");
  try {
    if (!strcmp(argv[1], "exr")) return exr(argv[2]);
    if (!strcmp(argv[1], "pfm")) return pfm(argv[2]);
    if (!strcmp(argv[1], "hdr")) return hdr(argv[2]);
  } catch (const std::exception &e) {
    return fail(e.what());
  }
  return fail("unknown kind");
}
