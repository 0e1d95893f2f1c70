// synth_texture KIND SIZE OUT.png [SEED]: procedural stand-ins for photographs that the shared
// textures do not cover, with pixel-level detail at any size (resampled photos are smooth at full
// size, real ones are not):
//   siding   horizontal lap-siding boards (about SIZE / 11.7 px each) with wood grain along x, a
//            shadow under each lap, a tone per board, a lighting gradient and sensor noise
//   flemish  a Flemish-bond brick wall (header and stretcher alternating in every course, each
//            header centred on the stretcher below) with mortar joints, a tone per brick, surface
//            noise and a few chipped edges
// Greyscale 8-bit PNG. Deterministic: the same arguments give the same file.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "tailor/image.h"

namespace {

uint64_t hash3(uint64_t a, uint64_t b, uint64_t c) {
  uint64_t z = a * 0x9E3779B97F4A7C15ull ^ (b + 0xBF58476D1CE4E5B9ull) * 0x94D049BB133111EBull ^ (c << 17);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

//! Uniform in [-1, 1) from a lattice point.
double lattice(int64_t x, int64_t y, uint64_t seed) {
  return static_cast<double>(hash3(static_cast<uint64_t>(x), static_cast<uint64_t>(y), seed) >> 11) * 0x1.0p-52 - 1.0;
}

//! Smooth value noise with cells of cx x cy px.
double value_noise(double x, double y, double cx, double cy, uint64_t seed) {
  const double u = x / cx, v = y / cy;
  const auto i = static_cast<int64_t>(std::floor(u)), j = static_cast<int64_t>(std::floor(v));
  double fu = u - static_cast<double>(i), fv = v - static_cast<double>(j);
  fu = fu * fu * (3 - 2 * fu);
  fv = fv * fv * (3 - 2 * fv);
  const double a = lattice(i, j, seed), b = lattice(i + 1, j, seed), c = lattice(i, j + 1, seed),
               d = lattice(i + 1, j + 1, seed);
  return (a * (1 - fu) + b * fu) * (1 - fv) + (c * (1 - fu) + d * fu) * fv;
}

//! Approximately normal (sum of 4 uniforms), unit variance.
double gauss(int x, int y, uint64_t seed) {
  double s = 0;
  for (uint64_t k = 0; k < 4; ++k) s += lattice(x, y, seed * 8 + k);
  return s * std::sqrt(3.0) / 2.0;
}

uint8_t to_byte(double v) { return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0, 255.0))); }

void siding(tailor::Image& img, uint64_t seed) {
  const int n = img.width;
  const double board = n / 11.7;  // not a divisor of the side: the photo does not tile as it is
  for (int y = 0; y < n; ++y) {
    const double t = y / board;
    const auto b = static_cast<int64_t>(std::floor(t));
    const double f = t - static_cast<double>(b);  // 0 at the lap's lower edge, 1 at the next one
    const double tone = 150 + 25 * lattice(b, 0, seed + 1);
    // The lap: a dark shadow line, then a soft shadow fading down the board.
    const double shadow = f < 0.025 ? 0.35 : 1.0 - 0.3 * std::exp(-(f - 0.025) / 0.08);
    for (int x = 0; x < n; ++x) {
      // Grain: streaks along x (long cells along x, short along y), two octaves, offset per board.
      const double gx = x + 9973.0 * static_cast<double>(b);
      const double grain = 18 * value_noise(gx, y, n / 6.0, n / 300.0, seed + 2) +
                           10 * value_noise(gx, y, n / 24.0, n / 1200.0 + 1, seed + 3);
      const double light = 1.0 - 0.15 * x / n - 0.1 * y / n;
      img.pixels[static_cast<size_t>(y) * n + x] = to_byte((tone + grain) * shadow * light + 6 * gauss(x, y, seed + 4));
    }
  }
}

void flemish(tailor::Image& img, uint64_t seed) {
  const int n = img.width;
  // Brick 2 units long, 1 deep (the header), courses 0.6 high; unit = n / 9.3 px (not a divisor).
  const double unit = n / 9.3, course = 0.6 * unit, joint = 0.08 * unit;
  for (int y = 0; y < n; ++y) {
    const double cy = y / course;
    const auto row = static_cast<int64_t>(std::floor(cy));
    const double fy = (cy - static_cast<double>(row)) * course;  // px into the course
    // Flemish bond: stretcher (2) + header (1) repeating every 3 units; alternate courses shift
    // by 1.5 units so each header sits centred on the stretcher below.
    const double offset = (row % 2 != 0 ? 1.5 : 0.0) + 0.07 * lattice(row, 7, seed);
    for (int x = 0; x < n; ++x) {
      const double u = x / unit + offset;
      const auto period = static_cast<int64_t>(std::floor(u / 3.0));
      const double p = u - 3.0 * static_cast<double>(period);  // [0, 3): stretcher [0, 2), header [2, 3)
      const bool header = p >= 2.0;
      const double start = header ? 2.0 : 0.0, len = header ? 1.0 : 2.0;
      const double fx = (p - start) * unit;  // px into the brick
      const int64_t id = period * 2 + (header ? 1 : 0);
      // Jittered joint widths and chipped edges from low-frequency noise along the joint.
      const double jx = joint * (1.0 + 0.5 * value_noise(x, y, unit / 3, unit / 3, seed + 5));
      const bool mortar = fy < jx || fx < jx * 0.8 || fx > len * unit - jx * 0.2;
      double v;
      if (mortar) {
        v = 195 + 10 * value_noise(x, y, 3, 3, seed + 6);
      } else {
        const double tone = (header ? 95.0 : 120.0) + 30 * lattice(id, row, seed + 8);
        v = tone + 14 * value_noise(x, y, unit / 5, unit / 5, seed + 9) + 8 * value_noise(x, y, 4, 4, seed + 10);
      }
      img.pixels[static_cast<size_t>(y) * n + x] = to_byte(v + 5 * gauss(x, y, seed + 11));
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4 || argc > 5) {
    std::fprintf(stderr, "usage: synth_texture siding|flemish SIZE OUT.png [SEED]\n");
    return 2;
  }
  const std::string kind = argv[1];
  const int size = std::atoi(argv[2]);
  const uint64_t seed = argc == 5 ? std::strtoull(argv[4], nullptr, 10) : 1;
  if (size < 32 || size > 8192 || (kind != "siding" && kind != "flemish")) {
    std::fprintf(stderr, "synth_texture: KIND is siding or flemish, SIZE 32..8192\n");
    return 2;
  }
  tailor::Image img;
  img.width = img.height = size;
  img.channels = 1;
  img.pixels.assign(static_cast<size_t>(size) * size, 0);
  if (kind == "siding")
    siding(img, seed);
  else
    flemish(img, seed);
  if (tailor::Status s = tailor::write_png(argv[3], img); !s.is_ok()) {
    std::fprintf(stderr, "synth_texture: %s\n", s.message().c_str());
    return 1;
  }
  return 0;
}
