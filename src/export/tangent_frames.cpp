// Per-vertex tangents for normal maps (glTF TANGENT: unit xyz, w = +-1 the bitangent's handedness).
// MikkTSpace in spirit, written here because Debian packages no mikktspace library: per face the
// tangent and bitangent from the UV derivatives (dP/ds, dP/dt), weighted by the corner's angle and
// accumulated per split vertex (vertices are already split on position + UV, so UV seams and
// mirrored islands get their own frames), then Gram-Schmidt against the vertex normal and w from
// the side the accumulated bitangent lies on. UVs are t up (OBJ), so the bitangent points up the
// image, as glTF's normal textures (+Y up) and three.js expect.
#include <algorithm>
#include <cmath>
#include <vector>

#include "export/writers.h"

namespace tailor::internal {
namespace {

struct Vec3 {
  double x = 0, y = 0, z = 0;
};
Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec3 operator*(Vec3 a, double k) { return {a.x * k, a.y * k, a.z * k}; }
double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double length(Vec3 a) { return std::sqrt(dot(a, a)); }

// The corner angle between edges a and b (0 for a degenerate corner).
double angle(Vec3 a, Vec3 b) {
  const double la = length(a), lb = length(b);
  if (la == 0 || lb == 0) return 0;
  return std::acos(std::clamp(dot(a, b) / (la * lb), -1.0, 1.0));
}

}  // namespace

void compute_tangents(const Mesh& mesh, const SplitMesh& split, std::span<const float> normals,
                      std::vector<float>& tangents) {
  const size_t ns = split.xref.size(), nf = split.indices.size() / 3;
  std::vector<double> sum(6 * ns, 0.0);  // tangent xyz, bitangent xyz per split vertex
  auto position = [&](uint32_t s) {
    const float* p = &mesh.positions[3 * size_t{split.xref[s]}];
    return Vec3{p[0], p[1], p[2]};
  };
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t* c = &split.indices[3 * f];
    const Vec3 p[3] = {position(c[0]), position(c[1]), position(c[2])};
    const double s0 = split.uvs[2 * size_t{c[0]}], t0 = split.uvs[2 * size_t{c[0]} + 1];
    const double ds1 = split.uvs[2 * size_t{c[1]}] - s0, dt1 = split.uvs[2 * size_t{c[1]} + 1] - t0;
    const double ds2 = split.uvs[2 * size_t{c[2]}] - s0, dt2 = split.uvs[2 * size_t{c[2]} + 1] - t0;
    const double r = ds1 * dt2 - ds2 * dt1;
    if (r == 0 || !std::isfinite(r)) continue;  // no UV area: no direction to give
    const Vec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
    Vec3 t = (e1 * dt2 - e2 * dt1) * (1 / r), b = (e2 * ds1 - e1 * ds2) * (1 / r);
    const double lt = length(t), lb = length(b);
    if (lt == 0 || lb == 0) continue;
    t = t * (1 / lt);
    b = b * (1 / lb);
    for (int k = 0; k < 3; ++k) {
      const double w = angle(p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
      double* out = &sum[6 * size_t{c[k]}];
      out[0] += w * t.x, out[1] += w * t.y, out[2] += w * t.z;
      out[3] += w * b.x, out[4] += w * b.y, out[5] += w * b.z;
    }
  }
  tangents.resize(4 * ns);
  for (size_t s = 0; s < ns; ++s) {
    const float* nf3 = &normals[3 * size_t{split.xref[s]}];
    const Vec3 n{nf3[0], nf3[1], nf3[2]};
    const double* a = &sum[6 * s];
    Vec3 t = Vec3{a[0], a[1], a[2]}, b{a[3], a[4], a[5]};
    t = t - n * dot(n, t);  // Gram-Schmidt: in the tangent plane
    double lt = length(t);
    if (!(lt > 1e-12)) {  // no UV direction here: any unit vector perpendicular to n
      t = std::abs(n.x) < 0.9 ? cross(n, Vec3{1, 0, 0}) : cross(n, Vec3{0, 1, 0});
      lt = length(t);
    }
    t = t * (1 / lt);
    float* out = &tangents[4 * s];
    out[0] = static_cast<float>(t.x);
    out[1] = static_cast<float>(t.y);
    out[2] = static_cast<float>(t.z);
    out[3] = dot(cross(n, t), b) < 0 ? -1.0f : 1.0f;
  }
}

}  // namespace tailor::internal
