// UV map quality metrics (see include/tailor/metrics.h and docs/metrics.md).
//
// This work is based on:
//   - Sai Yeshwanth Chaganti, "Efficient Texture Mapping by Homogeneous Patch Discovery", MS thesis,
//     IIIT Hyderabad, ch. 4 (stretch as the spread of the area ratio, distortion as the median angle
//     difference);
//   - P. V. Sander, J. Snyder, S. J. Gortler, H. Hoppe, "Texture Mapping Progressive Meshes",
//     SIGGRAPH 2001 (L2 and Linf stretch of the map from texture to surface).
#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "metrics/stored_metrics.h"
#include "surface/face_winding.h"
#include "tailor/export.h"
#include "tailor/metrics.h"
#include "util/bin_select.h"
#include "util/face_components.h"
#include "util/huge_pages.h"
#include "util/parallel_chunks.h"

namespace tailor {
namespace {

// A triangle is degenerate when twice its area is below this fraction of its longest edge squared
// (a needle whose height is 1e-12 of its length): its angles and ratios carry no information and
// would otherwise divide by zero.
constexpr double kDegenerateRelativeHeight = 1e-12;
// ... or when it is a sliver (twice its area below 2^-10 of its longest edge squared) whose height
// is below what 32-bit floats resolve where it lies (4 half-steps, 2^-22, of its first corner's
// largest coordinate plus its longest edge, a bound on its largest coordinate): its orientation and
// shape are the rounding of its corners, so its UVs' orientation and area ratio are noise (a
// corner moved onto the opposite edge, a decimation's leftover).
constexpr double kSliverRelativeHeight = 0x1p-10;
constexpr double kFloatResolvedHeight = 0x1p-22;

struct Vec3 {
  double x, y, z;
};

Vec3 position(const Mesh& mesh, uint32_t v) {
  const float* p = &mesh.positions[3 * size_t{v}];
  return {p[0], p[1], p[2]};
}
Vec3 sub(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double norm(Vec3 a) { return std::sqrt(dot(a, a)); }

// The corners of one face in 3D and in UV.
struct Face {
  Vec3 p[3];
  double u[3], v[3];
  double area3d = 0;   // A_f
  double area_uv = 0;  // signed a_f (positive = counter-clockwise in UV)
  bool degenerate = false;
};

Face load_face(const Mesh& mesh, std::span<const float> corner_uv, size_t f) {
  Face face;
  for (int k = 0; k < 3; ++k) {
    face.p[k] = position(mesh, mesh.indices[3 * f + k]);
    face.u[k] = corner_uv[2 * (3 * f + k)];
    face.v[k] = corner_uv[2 * (3 * f + k) + 1];
  }
  const Vec3 e1 = sub(face.p[1], face.p[0]), e2 = sub(face.p[2], face.p[0]), e3 = sub(face.p[2], face.p[1]);
  const double twice_area = norm(cross(e1, e2));
  const double longest2 = std::max({dot(e1, e1), dot(e2, e2), dot(e3, e3)});
  face.area3d = 0.5 * twice_area;
  face.degenerate = !(twice_area > kDegenerateRelativeHeight * longest2);
  if (!face.degenerate && twice_area < kSliverRelativeHeight * longest2) [[unlikely]] {
    const double longest = std::sqrt(longest2);
    const double far = std::max(std::max(std::abs(face.p[0].x), std::abs(face.p[0].y)), std::abs(face.p[0].z));
    face.degenerate = !(twice_area > kFloatResolvedHeight * (far + longest) * longest);
  }
  face.area_uv =
      0.5 * ((face.u[1] - face.u[0]) * (face.v[2] - face.v[0]) - (face.u[2] - face.u[0]) * (face.v[1] - face.v[0]));
  return face;
}

// Unsigned angle between two vectors; atan2 stays finite (0) for zero vectors.
double angle3(Vec3 a, Vec3 b) { return std::atan2(norm(cross(a, b)), dot(a, b)); }
double angle2(double ax, double ay, double bx, double by) {
  return std::atan2(std::abs(ax * by - ay * bx), ax * bx + ay * by);
}

// sum_k |angle_uv_k - angle_3d_k| in degrees. Each difference comes from one atan2 of the two
// angles' sine and cosine products: angle_uv - angle_3d = atan2(c2 d3 - d2 c3, d2 d3 + c2 c3) for
// angles atan2(c, d) in [0, pi], where the difference lies within (-pi, pi). A triangle's interior
// angles sum to pi, in 3D and in UV alike, so the third corner's difference is minus the sum of the
// other two: two atan2 per triangle (atan2 is most of the metrics' time). Not when a UV edge has
// zero length, where the UV angles at its ends are atan2(0, 0) = 0: there, all six angles.
double angle_distortion_deg(const Face& face) {
  bool zero_uv_edge = false;
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3;
    zero_uv_edge = zero_uv_edge || (face.u[i] == face.u[k] && face.v[i] == face.v[k]);
  }
  double sum = 0.;
  if (zero_uv_edge) {
    for (int k = 0; k < 3; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      const double uv =
          angle2(face.u[i] - face.u[k], face.v[i] - face.v[k], face.u[j] - face.u[k], face.v[j] - face.v[k]);
      sum += std::abs(uv - angle3(sub(face.p[i], face.p[k]), sub(face.p[j], face.p[k])));
    }
  } else {
    double difference[2];
    for (int k = 0; k < 2; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      const Vec3 a = sub(face.p[i], face.p[k]), b = sub(face.p[j], face.p[k]);
      const double c3 = norm(cross(a, b)), d3 = dot(a, b);
      const double ax = face.u[i] - face.u[k], ay = face.v[i] - face.v[k];
      const double bx = face.u[j] - face.u[k], by = face.v[j] - face.v[k];
      const double c2 = std::abs(ax * by - ay * bx), d2 = ax * bx + ay * by;
      difference[k] = std::atan2(c2 * d3 - d2 * c3, d2 * d3 + c2 * c3);
    }
    sum = std::abs(difference[0]) + std::abs(difference[1]) + std::abs(difference[0] + difference[1]);
  }
  return sum * (180.0 / std::numbers::pi);
}

// Sander et al. 2001: Jacobian of the affine map (s, t) -> 3D of a face with non-zero UV area.
// Returns (a + c) / 2 (the squared L2 stretch of the face) and sets G, the largest singular value.
double sander_stretch(const Face& face, double& gamma_max) {
  const double s1 = face.u[0], s2 = face.u[1], s3 = face.u[2];
  const double t1 = face.v[0], t2 = face.v[1], t3 = face.v[2];
  const double twice = 2.0 * face.area_uv;
  const Vec3& q1 = face.p[0];
  const Vec3& q2 = face.p[1];
  const Vec3& q3 = face.p[2];
  const Vec3 ss = {(q1.x * (t2 - t3) + q2.x * (t3 - t1) + q3.x * (t1 - t2)) / twice,
                   (q1.y * (t2 - t3) + q2.y * (t3 - t1) + q3.y * (t1 - t2)) / twice,
                   (q1.z * (t2 - t3) + q2.z * (t3 - t1) + q3.z * (t1 - t2)) / twice};
  const Vec3 st = {(q1.x * (s3 - s2) + q2.x * (s1 - s3) + q3.x * (s2 - s1)) / twice,
                   (q1.y * (s3 - s2) + q2.y * (s1 - s3) + q3.y * (s2 - s1)) / twice,
                   (q1.z * (s3 - s2) + q2.z * (s1 - s3) + q3.z * (s2 - s1)) / twice};
  const double a = dot(ss, ss), b = dot(ss, st), c = dot(st, st);
  gamma_max = std::sqrt(0.5 * ((a + c) + std::sqrt((a - c) * (a - c) + 4 * b * b)));
  return 0.5 * (a + c);
}

// Lattice gap for one rotation of g's side: `rot` quarter turns counter-clockwise (pixels).
double lattice_gap(const float* fa, const float* fb, const float* ga, const float* gb, int rot, double w, double h) {
  const auto turned = [rot](const float* uv, double& u, double& v) {
    const double x = uv[0], y = uv[1];
    switch (rot) {
      case 0: u = x, v = y; break;
      case 1: u = -y, v = x; break;
      case 2: u = -x, v = -y; break;
      default: u = y, v = -x; break;
    }
  };
  double gau, gav, gbu, gbv;
  turned(ga, gau, gav);
  turned(gb, gbu, gbv);
  const double dau = fa[0] - gau, dav = fa[1] - gav, dbu = fb[0] - gbu, dbv = fb[1] - gbv;
  const double ku = w * std::round(0.5 * (dau + dbu) / w), kv = h * std::round(0.5 * (dav + dbv) / h);
  const double ga2 = (dau - ku) * (dau - ku) + (dav - kv) * (dav - kv);
  const double gb2 = (dbu - ku) * (dbu - ku) + (dbv - kv) * (dbv - kv);
  return std::sqrt(std::max(ga2, gb2));
}

bool same_uv(std::span<const float> uv, size_t c0, size_t c1) {
  return uv[2 * c0] == uv[2 * c1] && uv[2 * c0 + 1] == uv[2 * c1 + 1];
}

// The corners on both sides of paired edge e (face f, edge k) and its opposite o (face g, edge j):
// e runs a -> b in f, o runs b -> a in g.
struct EdgeSides {
  size_t fa, fb, ga, gb;
};
EdgeSides edge_sides(size_t e, size_t o) {
  const size_t f = e / 3, k = e % 3, g = o / 3, j = o % 3;
  return {3 * f + k, 3 * f + (k + 1) % 3, 3 * g + (j + 1) % 3, 3 * g + j};
}

// The middle value, or the mean of the two middle ones (by selection; reorders values).
double plain_median(std::vector<double>& values) {
  if (values.empty()) return 0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid), values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  const double lower = *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid));
  return 0.5 * (lower + upper);
}

// plain_median's value, on threads (util/bin_select.h): non-negative doubles order as their bits,
// so counting the top 16 bits of every value finds the bins of the middle ones, and only those
// bins' values are selected among. A negative, infinite or NaN value (never one of the metrics'
// angles) takes the plain selection.
double median(std::vector<double>& values, size_t threads) {
  using internal::kSelectBins;
  const size_t n = values.size();
  const size_t parts = internal::parallel_parts(n, threads);
  if (parts < 2) return plain_median(values);
  std::vector<uint32_t> counts(parts * kSelectBins, 0);
  std::vector<uint8_t> unordered(parts, 0);
  internal::for_each_part(n, parts, [&](size_t t, size_t begin, size_t end) {
    uint32_t* count = counts.data() + t * kSelectBins;
    bool odd = false;
    for (size_t i = begin; i < end; ++i) {
      const auto bits = std::bit_cast<uint64_t>(values[i]);
      odd |= (bits >> 52) >= 0x7FF;  // the sign, or an exponent of all ones
      ++count[bits >> 48];
    }
    unordered[t] = odd;
  });
  if (std::find(unordered.begin(), unordered.end(), 1) != unordered.end()) return plain_median(values);
  internal::sum_bin_rows(counts, parts);
  // The lower middle value's bin and the upper one's (the same one, or the next that holds any):
  // their values gathered in one pass, the lower bin's first, then selected among as plain_median
  // selects among all.
  const size_t mid = n / 2, first = n % 2 == 1 ? mid : mid - 1;
  uint64_t rank = first, upper_rank = mid;
  const uint64_t low = internal::select_bin(counts, rank), high = internal::select_bin(counts, upper_rank);
  std::vector<std::vector<double>> gathered(parts);
  internal::for_each_part(n, parts, [&](size_t t, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i)
      if (const uint64_t bin = std::bit_cast<uint64_t>(values[i]) >> 48; bin >= low && bin <= high)
        gathered[t].push_back(values[i]);
  });
  std::vector<double> near;
  for (const std::vector<double>& g : gathered) near.insert(near.end(), g.begin(), g.end());
  const size_t at = static_cast<size_t>(rank) + (mid - first);  // the upper middle's rank in `near`
  if (at >= near.size()) return plain_median(values);           // not when the counts are near's
  const auto upper = near.begin() + static_cast<std::ptrdiff_t>(at);
  std::nth_element(near.begin(), upper, near.end());
  if (n % 2 == 1) return *upper;
  return 0.5 * (*std::max_element(near.begin(), upper) + *upper);
}

// The sums of the metrics' pass over the edges.
struct SeamSums {
  double total_length = 0, seam_length = 0, gap_weighted = 0, gap_plain = 0, invisible_length = 0;
  double visible_length = 0, visible_off_sharp = 0;
  size_t seam_edges = 0, invisible_count = 0;
};

double seam_gap_of(const float* uv, const EdgeSides& s, const MetricsOptions& options) {
  return seam_gap_px(uv + 2 * s.fa, uv + 2 * s.fb, uv + 2 * s.ga, uv + 2 * s.gb, options);
}

// A seam edge (its faces' UVs disagree) of `length` whose sides are `s`, between face s.fa / 3 and
// face g, into `sums`: visible unless a whole-repeat offset joins them, then on a sharp edge or not
// (`same_way`: g is wound against the other face, so their normals are compared as if it were
// not). True when visible.
bool add_seam(const Mesh& mesh, std::span<const float> corner_uv, const MetricsOptions& options, double sharp_cos,
              const EdgeSides& s, size_t g, double length, bool same_way, SeamSums& sums) {
  ++sums.seam_edges;
  sums.seam_length += length;
  const double gap = seam_gap_of(corner_uv.data(), s, options);
  sums.gap_weighted += length * gap;
  sums.gap_plain += gap;
  if (gap < options.invisible_gap_px) {
    sums.invisible_length += length;
    ++sums.invisible_count;
    return false;
  }
  sums.visible_length += length;
  const Face face_f = load_face(mesh, corner_uv, s.fa / 3), face_g = load_face(mesh, corner_uv, g);
  const Vec3 nf3 = cross(sub(face_f.p[1], face_f.p[0]), sub(face_f.p[2], face_f.p[0]));
  const Vec3 ng3 = cross(sub(face_g.p[1], face_g.p[0]), sub(face_g.p[2], face_g.p[0]));
  const double nn = norm(nf3) * norm(ng3);
  const bool sharp = nn > 0 && (same_way ? -dot(nf3, ng3) : dot(nf3, ng3)) < sharp_cos * nn;
  if (!sharp) sums.visible_off_sharp += length;
  return true;
}

}  // namespace

uint32_t derive_patches(const Mesh& mesh, const Topology& topology, std::span<const float> corner_uv,
                        std::vector<uint32_t>& patch, uint32_t threads) {
  const size_t nf = mesh.face_count();
  // Components through the seamless edges, numbered by their lowest face, the same for any count
  // (util/face_components.h).
  patch.resize(nf);
  const auto seamless = [&](uint32_t f, const auto& wanted, const auto& visit) {
    for (uint32_t e = 3 * f; e < 3 * f + 3; ++e) {
      const uint32_t o = topology.opposite[e];
      if (o == kInvalid || !wanted(o / 3)) continue;
      const EdgeSides s = edge_sides(e, o);
      if (same_uv(corner_uv, s.fa, s.ga) && same_uv(corner_uv, s.fb, s.gb)) visit(o / 3);
    }
  };
  return internal::label_components(nf, internal::parallel_parts(nf, threads), seamless, patch.data());
}

double seam_gap_px(const float* uv_fa, const float* uv_fb, const float* uv_ga, const float* uv_gb,
                   const MetricsOptions& options) {
  const double w = options.texture_width_px, h = options.texture_height_px;
  double gap = lattice_gap(uv_fa, uv_fb, uv_ga, uv_gb, 0, w, h);
  if (options.symmetry == 4)
    for (int rot = 1; rot < 4; ++rot) gap = std::min(gap, lattice_gap(uv_fa, uv_fb, uv_ga, uv_gb, rot, w, h));
  return gap;
}

void classify_seam_edges(const Mesh& mesh, const Topology& topology, std::span<const float> corner_uv,
                         const MetricsOptions& options, std::vector<uint8_t>& seam_class) {
  const size_t edges = 3 * mesh.face_count();
  seam_class.assign(edges, 0);
  const float* uv = corner_uv.data();
  for (size_t e = 0; e < edges; ++e) {
    const uint32_t o = topology.opposite[e];
    if (o == kInvalid || o < e) continue;
    const EdgeSides s = edge_sides(e, o);
    if (same_uv(corner_uv, s.fa, s.ga) && same_uv(corner_uv, s.fb, s.gb)) continue;
    const double gap = seam_gap_px(uv + 2 * s.fa, uv + 2 * s.fb, uv + 2 * s.ga, uv + 2 * s.gb, options);
    seam_class[e] = seam_class[o] = gap < options.invisible_gap_px ? 1 : 2;
  }
}

void face_area_stretch(const Mesh& mesh, std::span<const float> corner_uv, std::vector<float>& ratio) {
  const size_t nf = mesh.face_count();
  ratio.assign(nf, 1.0f);
  double sum_uv = 0, sum_3d = 0;
  for (size_t f = 0; f < nf; ++f) {
    const Face face = load_face(mesh, corner_uv, f);
    if (face.degenerate) continue;
    sum_uv += std::abs(face.area_uv);
    sum_3d += face.area3d;
  }
  if (!(sum_uv > 0) || !(sum_3d > 0)) {
    std::fill(ratio.begin(), ratio.end(), 0.0f);
    return;
  }
  const double scale = sum_uv / sum_3d;
  for (size_t f = 0; f < nf; ++f) {
    const Face face = load_face(mesh, corner_uv, f);
    if (face.degenerate) continue;
    ratio[f] = static_cast<float>(std::abs(face.area_uv) / face.area3d / scale);
  }
}

Status compute_uv_metrics(const Mesh& mesh, const Topology& topology, std::span<const float> corner_uv,
                          std::span<const uint32_t> patch_in, const MetricsOptions& options, UvMetrics& metrics) {
  const auto start = std::chrono::steady_clock::now();
  metrics = UvMetrics{};
  const size_t nf = mesh.face_count();
  if (corner_uv.size() != 6 * nf)
    return Status::error(ErrorCode::kInvalidArgument, "", "corner UVs do not match the mesh",
                         std::to_string(corner_uv.size()) + " floats for " + std::to_string(nf) + " faces");
  if (topology.opposite.size() != 3 * nf)
    return Status::error(ErrorCode::kInvalidArgument, "", "topology does not match the mesh");
  if (!patch_in.empty() && patch_in.size() != nf)
    return Status::error(ErrorCode::kInvalidArgument, "", "patch ids do not match the mesh",
                         std::to_string(patch_in.size()) + " ids for " + std::to_string(nf) + " faces");
  if (!(options.texture_width_px > 0) || !(options.texture_height_px > 0) || !std::isfinite(options.texture_width_px) ||
      !std::isfinite(options.texture_height_px))
    return Status::error(ErrorCode::kInvalidArgument, "", "texture size must be positive");
  if (options.symmetry != 1 && options.symmetry != 4)
    return Status::error(ErrorCode::kInvalidArgument, "", "symmetry must be 1 or 4");
  if (options.symmetry == 4 && options.texture_width_px != options.texture_height_px)
    return Status::error(ErrorCode::kInvalidArgument, "", "symmetry 4 needs a square texture");
  if (!(options.invisible_gap_px > 0) || !(options.sharp_angle_deg >= 0) || !(options.sharp_angle_deg <= 180))
    return Status::error(ErrorCode::kInvalidArgument, "", "invisible gap or sharp angle out of range");
  for (size_t i = 0; i < corner_uv.size(); ++i)
    if (!std::isfinite(corner_uv[i]))
      return Status::error(ErrorCode::kInvalidMesh, "", "UV is not finite", "corner " + std::to_string(i / 2));
  for (size_t f = 0; f < patch_in.size(); ++f)
    if (patch_in[f] >= nf)
      return Status::error(ErrorCode::kInvalidArgument, "", "patch id out of range", "face " + std::to_string(f));

  std::vector<uint32_t> derived;
  std::span<const uint32_t> patch = patch_in;
  if (patch.empty()) {
    derive_patches(mesh, topology, corner_uv, derived, options.threads);
    patch = derived;
  }
  metrics.faces = nf;

  // The per-face and per-edge passes run on fixed chunks (internal/parallel_chunks.h), their
  // partial sums added in chunk order: the figures do not depend on the thread count.
  const size_t threads = internal::parallel_threads(nf, options.threads);
  const size_t chunks = internal::chunk_count(nf);

  // Pass 1: areas and the sign of each face's UV area (kDegenerate: skipped), then, in face order,
  // orientation votes per patch and patch sizes.
  constexpr int8_t kDegenerate = 2;
  std::vector<int8_t> sign(nf);
  struct AreaSums {
    double uv = 0, surface = 0;
    size_t kept = 0;  // non-degenerate faces
  };
  std::vector<AreaSums> area_sums(chunks);
  internal::for_each_chunk(nf, threads, [&](size_t begin, size_t end, size_t chunk) {
    AreaSums sums;
    for (size_t f = begin; f < end; ++f) {
      const Face face = load_face(mesh, corner_uv, f);
      if (face.degenerate) {
        sign[f] = kDegenerate;
        continue;
      }
      sums.uv += std::abs(face.area_uv);
      sums.surface += face.area3d;
      ++sums.kept;
      sign[f] = face.area_uv > 0 ? 1 : (face.area_uv < 0 ? -1 : 0);
    }
    area_sums[chunk] = sums;
  });
  uint32_t patch_end = 0;  // ids are < #F, but usually few: per-patch arrays sized by the largest
  for (const uint32_t p : patch) patch_end = std::max(patch_end, p + 1);
  std::vector<uint32_t> patch_faces(patch_end, 0);
  std::vector<int64_t> patch_vote(patch_end, 0);  // (# positive) - (# negative) UV-area faces
  for (size_t f = 0; f < nf; ++f) {
    ++patch_faces[patch[f]];
    if (sign[f] != kDegenerate) patch_vote[patch[f]] += sign[f];
  }
  double sum_uv = 0, sum_3d = 0;
  std::vector<size_t> kept_before(chunks + 1, 0);  // non-degenerate faces in the chunks before
  for (size_t c = 0; c < chunks; ++c) {
    sum_uv += area_sums[c].uv;
    sum_3d += area_sums[c].surface;
    kept_before[c + 1] = kept_before[c] + area_sums[c].kept;
  }
  const size_t counted = kept_before[chunks];
  metrics.degenerate_faces = nf - counted;
  for (size_t p = 0; p < patch_end; ++p) {
    if (patch_faces[p] > 0) ++metrics.patches;
    if (patch_faces[p] == 1) ++metrics.single_face_patches;
  }
  if (!(sum_3d > 0))
    return Status::error(ErrorCode::kInvalidMesh, "",
                         "every face has zero 3D area or is a sliver thinner than 32-bit floats resolve at its "
                         "coordinates");
  if (!(sum_uv > 0)) return Status::error(ErrorCode::kInvalidMesh, "", "every face has zero UV area");
  const double scale = sum_uv / sum_3d;  // R
  metrics.uv_scale = scale;

  // Pass 2: per-face quantities, per non-degenerate face in face order.
  std::vector<double> angles, ratios, areas;
  for (std::vector<double>* v : {&angles, &ratios, &areas}) {
    internal::reserve_huge(*v, counted);  // fresh and large: huge pages (huge_pages.h)
    v->resize(counted);
  }
  struct FaceSums {
    double r = 0, l2_num = 0, l2_den = 0, gamma_max = 0;
    size_t flipped = 0, zero_uv_area = 0;
  };
  std::vector<FaceSums> face_sums(chunks);
  internal::for_each_chunk(nf, threads, [&](size_t begin, size_t end, size_t chunk) {
    FaceSums sums;
    size_t i = kept_before[chunk];
    for (size_t f = begin; f < end; ++f) {
      if (sign[f] == kDegenerate) continue;
      const Face face = load_face(mesh, corner_uv, f);
      const double r = std::abs(face.area_uv) / face.area3d;
      sums.r += r;
      ratios[i] = r;
      areas[i] = face.area3d;
      angles[i] = angle_distortion_deg(face);
      ++i;
      // Ties (and empty votes) count as counter-clockwise, the orientation the mapping produces.
      const bool majority_positive = patch_vote[patch[f]] >= 0;
      if (face.area_uv == 0) {
        ++sums.flipped;
        ++sums.zero_uv_area;
        continue;  // infinite Sander stretch: excluded from L2 / Linf
      }
      if ((face.area_uv > 0) != majority_positive) ++sums.flipped;
      double g = 0;
      sums.l2_num += face.area3d * sander_stretch(face, g);
      sums.l2_den += face.area3d;
      sums.gamma_max = std::max(sums.gamma_max, g);
    }
    face_sums[chunk] = sums;
  });
  double sum_r = 0, l2_num = 0, l2_den = 0, gamma_max = 0;
  for (const FaceSums& sums : face_sums) {
    sum_r += sums.r;
    l2_num += sums.l2_num;
    l2_den += sums.l2_den;
    gamma_max = std::max(gamma_max, sums.gamma_max);
    metrics.flipped += sums.flipped;
    metrics.zero_uv_area_faces += sums.zero_uv_area;
  }
  const double mean_r = sum_r / static_cast<double>(counted);
  // Second pass over r for a numerically stable variance (both forms).
  double var_sum = 0, var_w_sum = 0;
  for (size_t i = 0; i < ratios.size(); ++i) {
    const double r = ratios[i];
    var_sum += (r - mean_r) * (r - mean_r);
    var_w_sum += areas[i] * (r - scale) * (r - scale);  // the area-weighted mean of r is R
  }
  metrics.stretch = mean_r > 0 ? std::sqrt(var_sum / static_cast<double>(counted)) / mean_r : 0;
  metrics.stretch_area_weighted = std::sqrt(var_w_sum / sum_3d) / scale;
  metrics.distortion_deg = median(angles, threads);
  if (l2_den > 0) {
    metrics.l2_stretch = std::sqrt(l2_num / l2_den) * std::sqrt(scale);
    metrics.linf_stretch = gamma_max * std::sqrt(scale);
  }

  // Seams: over distinct edges (a paired edge once, a boundary edge once). Visible seam edges are
  // marked on their lower edge id for the vertex pass below.
  const size_t corners = 3 * nf;
  const double sharp_cos = std::cos(options.sharp_angle_deg * (std::numbers::pi / 180.0));
  std::vector<uint8_t> visible(corners, 0);
  std::vector<SeamSums> seam_sums(internal::chunk_count(corners));
  internal::for_each_chunk(corners, threads, [&](size_t begin, size_t end, size_t chunk) {
    SeamSums sums;
    for (size_t e = begin; e < end; ++e) {
      const uint32_t o = topology.opposite[e];
      if (o != kInvalid && o < e) continue;
      const size_t f = e / 3, k = e % 3;
      const double length =
          norm(sub(position(mesh, mesh.indices[3 * f + (k + 1) % 3]), position(mesh, mesh.indices[3 * f + k])));
      sums.total_length += length;
      if (o == kInvalid) continue;
      const EdgeSides s = edge_sides(e, o);
      if (same_uv(corner_uv, s.fa, s.ga) && same_uv(corner_uv, s.fb, s.gb)) continue;
      if (add_seam(mesh, corner_uv, options, sharp_cos, s, o / 3, length, false, sums)) visible[e] = 1;
    }
    seam_sums[chunk] = sums;
  });
  // Edges that two faces share running the same way (a face wound against its neighbours): the
  // topology leaves both unpaired, as boundary, yet the surface goes on across them and the texture
  // breaks there when the faces' UVs disagree. They are seams like paired edges (and one edge, not
  // two, in the total), so faces wound the wrong way cannot hide their seams.
  seam_sums.emplace_back();
  for (const auto& [e, g_edge] : internal::same_way_edge_pairs(mesh, topology)) {
    const size_t f = e / 3, k = e % 3, g = g_edge / 3, j = g_edge % 3;
    const double length =
        norm(sub(position(mesh, mesh.indices[3 * f + (k + 1) % 3]), position(mesh, mesh.indices[3 * f + k])));
    seam_sums.back().total_length -= length;  // counted once for each face above
    const EdgeSides s{e, 3 * f + (k + 1) % 3, g_edge, 3 * g + (j + 1) % 3};
    if (!same_uv(corner_uv, s.fa, s.ga) || !same_uv(corner_uv, s.fb, s.gb))
      add_seam(mesh, corner_uv, options, sharp_cos, s, g, length, true, seam_sums.back());
  }
  double total_length = 0, seam_length = 0, gap_weighted = 0, gap_plain = 0, invisible_length = 0;
  double visible_length = 0, visible_off_sharp = 0;
  size_t invisible_count = 0;
  for (const SeamSums& sums : seam_sums) {
    total_length += sums.total_length;
    seam_length += sums.seam_length;
    gap_weighted += sums.gap_weighted;
    gap_plain += sums.gap_plain;
    invisible_length += sums.invisible_length;
    visible_length += sums.visible_length;
    visible_off_sharp += sums.visible_off_sharp;
    invisible_count += sums.invisible_count;
    metrics.seam_edges += sums.seam_edges;
  }
  if (total_length > 0) {
    metrics.seam_length_ratio = seam_length / total_length;
    metrics.visible_seam_ratio = visible_length / total_length;
    metrics.visible_off_sharp_ratio = visible_off_sharp / total_length;
  }
  if (metrics.seam_edges == 0) {
    metrics.seam_invisible_ratio = 1.0;
  } else if (seam_length > 0) {
    metrics.seam_gap_px = gap_weighted / seam_length;
    metrics.seam_invisible_ratio = invisible_length / seam_length;
  } else {  // only zero-length seam edges: plain means
    const double n = static_cast<double>(metrics.seam_edges);
    metrics.seam_gap_px = gap_plain / n;
    metrics.seam_invisible_ratio = static_cast<double>(invisible_count) / n;
  }

  // Ends and branches of the visible seams: visible edges per vertex, at interior vertices (no
  // boundary edge around them). Sequential: two byte-sized counters per vertex.
  const size_t nv = mesh.vertex_count();
  std::vector<uint8_t> visible_at(nv, 0), on_boundary(nv, 0);
  for (size_t e = 0; e < corners; ++e) {
    const uint32_t a = mesh.indices[e], b = mesh.indices[3 * (e / 3) + (e % 3 + 1) % 3];
    if (topology.opposite[e] == kInvalid) {
      on_boundary[a] = on_boundary[b] = 1;
    } else if (visible[e]) {
      visible_at[a] = static_cast<uint8_t>(std::min(visible_at[a] + 1, 255));
      visible_at[b] = static_cast<uint8_t>(std::min(visible_at[b] + 1, 255));
    }
  }
  for (size_t v = 0; v < nv; ++v) {
    if (on_boundary[v]) continue;
    if (visible_at[v] == 1) ++metrics.visible_dangling_ends;
    if (visible_at[v] >= 3) ++metrics.visible_branch_points;
  }
  metrics.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::ok();
}

namespace {

// True when two vertices have bit-identical positions (-0 and +0 alike), the vertices
// weld_identical_positions would join. One open-addressing pass, 4 bytes per table slot.
bool has_identical_positions(const Mesh& mesh, uint32_t threads) {
  const size_t nv = mesh.vertex_count();
  // Each thread keeps the vertices of its share of the hash values (a vertex and its twin hash
  // alike), in a table of its own: none writes another's table.
  const size_t parts = internal::parallel_parts(nv, threads);
  auto bits = [](float x) { return std::bit_cast<uint32_t>(x + 0.0f); };
  auto hash = [&](size_t v) {
    const float* p = &mesh.positions[3 * v];
    uint64_t h = ((uint64_t{bits(p[0])} << 32) | bits(p[1])) * 0x9e3779b97f4a7c15ULL;
    h = (h ^ (h >> 29) ^ bits(p[2])) * 0xbf58476d1ce4e5b9ULL;
    return h ^ (h >> 32);
  };
  // Each vertex's share, hashed once (parts <= 64 fit a byte), and each range's count per share.
  std::vector<uint8_t> share_of(nv);
  std::vector<size_t> count(parts * parts, 0);
  internal::for_each_part(nv, parts, [&](size_t r, size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
      share_of[v] = static_cast<uint8_t>((hash(v) >> 40) % parts);
      ++count[r * parts + share_of[v]];
    }
  });
  std::vector<uint8_t> found(parts, 0);
  internal::for_each_part(nv, parts, [&](size_t t, size_t, size_t) {
    size_t share = 0;  // this thread's vertices: the table holds twice as many slots, never fills
    for (size_t r = 0; r < parts; ++r) share += count[r * parts + t];
    size_t table_size = 16;
    while (table_size < 2 * share) table_size *= 2;
    const size_t mask = table_size - 1;
    std::vector<uint32_t> table(table_size, kInvalid);
    for (size_t v = 0; v < nv; ++v) {
      if (share_of[v] != t) continue;
      const float* p = &mesh.positions[3 * v];
      size_t slot = static_cast<size_t>(hash(v)) & mask;
      for (; table[slot] != kInvalid; slot = (slot + 1) & mask) {
        const float* q = &mesh.positions[3 * size_t{table[slot]}];
        if (bits(q[0]) == bits(p[0]) && bits(q[1]) == bits(p[1]) && bits(q[2]) == bits(p[2])) {
          found[t] = 1;
          return;
        }
      }
      table[slot] = static_cast<uint32_t>(v);
    }
  });
  return std::find(found.begin(), found.end(), 1) != found.end();
}

}  // namespace

void uv_repeats_from_px(std::span<const float> uv_px, double width, double height, std::vector<float>& uv_repeats) {
  const double su = 1.0 / width, sv = 1.0 / height;
  uv_repeats.resize(uv_px.size());
  for (size_t i = 0; i + 1 < uv_px.size(); i += 2) {
    uv_repeats[i] = static_cast<float>(uv_px[i] * su) + 0.0f;
    uv_repeats[i + 1] = static_cast<float>(uv_px[i + 1] * sv) + 0.0f;
  }
}

Status compute_stored_uv_metrics(const Mesh& mesh, const Topology* topology, std::vector<float> corner_uv,
                                 const MetricsOptions& options, UvMetrics& metrics, StoredSurface* surface) {
  // Repeats -> pixels in place (the float product, as a reader of the file scales them).
  const float width = options.texture_width_px, height = options.texture_height_px;
  for (size_t i = 0; i < corner_uv.size(); i += 2) {
    const bool finite = std::isfinite(corner_uv[i]) && std::isfinite(corner_uv[i + 1]);
    corner_uv[i] *= width;
    corner_uv[i + 1] *= height;
    if (finite && !(std::isfinite(corner_uv[i]) && std::isfinite(corner_uv[i + 1])))
      return Status::error(ErrorCode::kInvalidMesh, "", "UV is too large to scale to the texture's pixels",
                           "corner " + std::to_string(i / 2));
  }
  return internal::compute_stored_uv_metrics_px(mesh, topology, corner_uv, options, metrics, surface);
}

bool internal::stored_round_trip_exact(std::span<const float> uv_px, float width, float height) {
  const double su = 1.0 / width, sv = 1.0 / height;
  bool exact = true;
  for (size_t i = 0; i + 1 < uv_px.size(); i += 2) {
    const float u = (static_cast<float>(uv_px[i] * su) + 0.0f) * width;
    const float v = (static_cast<float>(uv_px[i + 1] * sv) + 0.0f) * height;
    exact &= std::bit_cast<uint32_t>(u) == std::bit_cast<uint32_t>(uv_px[i]) &&
             std::bit_cast<uint32_t>(v) == std::bit_cast<uint32_t>(uv_px[i + 1]);
  }
  return exact;
}

namespace {

// Joining bit-identical positions lays two sheets at one place (a double-sided leaf, both sides of
// a cloth) on edges of four faces, which the joined topology leaves unpaired: every face there
// would be a patch of its own. Where the file's own vertex ids pair an edge, that pair stands (the
// joined topology leaves an edge unpaired when the own ids pair it only if it has more than two
// faces, so the pairs stay mutual).
void keep_own_pairs(const Mesh& mesh, const Topology* own, uint32_t threads, Topology& joined) {
  Topology built;
  if (!own || own->opposite.size() != joined.opposite.size()) {
    built = build_topology(mesh, {}, threads);
    own = &built;
  }
  for (size_t e = 0; e < joined.opposite.size(); ++e)
    if (joined.opposite[e] == kInvalid) joined.opposite[e] = own->opposite[e];
}

}  // namespace

Status internal::compute_stored_uv_metrics_px(const Mesh& mesh, const Topology* topology,
                                              std::span<const float> corner_uv, const MetricsOptions& options,
                                              UvMetrics& metrics, StoredSurface* surface) {
  metrics = UvMetrics{};
  if (surface) *surface = StoredSurface{};
  if (corner_uv.size() != 6 * mesh.face_count())
    return Status::error(
        ErrorCode::kInvalidArgument, "", "corner UVs do not match the mesh",
        std::to_string(corner_uv.size()) + " floats for " + std::to_string(mesh.face_count()) + " faces");
  // The surface a reader of a split file (.glb, .ply) sees: vertices at bit-identical positions joined.
  Mesh welded;
  const Mesh* measured = &mesh;
  const Topology* own = topology;
  if (has_identical_positions(mesh, options.threads)) {
    welded.positions = mesh.positions;
    welded.indices = mesh.indices;
    const size_t joined = weld_identical_positions(welded);
    if (surface) surface->welded_vertices = joined;
    measured = &welded;
    topology = nullptr;
  }
  Topology built;
  if (!topology || topology->opposite.size() != 3 * measured->face_count()) {
    built = build_topology(*measured, {}, options.threads);
    if (measured == &welded && built.nonmanifold_edges > 0) keep_own_pairs(mesh, own, options.threads, built);
    topology = &built;
  }
  if (surface) {
    surface->boundary_edges = topology->boundary_edges;
    surface->nonmanifold_edges = topology->nonmanifold_edges;
  }
  return compute_uv_metrics(*measured, *topology, corner_uv, {}, options, metrics);
}

}  // namespace tailor
