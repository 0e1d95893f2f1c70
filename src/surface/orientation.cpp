// Per-face frames and the orientation field (thesis 2.2: "the orientation vector of each triangle
// is taken as the projection of the first principal vector onto the triangle").
//
// This work is based on:
//   V. Singh, A. M. Namboodiri, "Efficient texture mapping by homogeneous patch discovery",
//   ICVGIP 2012 (thesis chapter 2).
#include "tailor/orientation.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <string>

#include "surface/orientation_setup.h"
#include "surface/skeleton.h"
#include "surface/stroke_field.h"
#include "util/huge_pages.h"
#include "util/parallel_chunks.h"

namespace tailor {
namespace {

struct Vec3 {
  double x = 0, y = 0, z = 0;
};
inline Vec3 sub(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 add(const Vec3& a, const Vec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 mul(const Vec3& a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

// Sign convention for axes, so that the field does not depend on the eigen solver's sign choice:
// the largest-magnitude component is positive.
Vec3 canonical_sign(Vec3 a) {
  const double ax = std::abs(a.x), ay = std::abs(a.y), az = std::abs(a.z);
  const double c = (ax >= ay && ax >= az) ? a.x : (ay >= az ? a.y : a.z);
  return c < 0 ? mul(a, -1.0) : a;
}

// Any unit vector perpendicular to a (unit).
Vec3 perpendicular(const Vec3& a) {
  const Vec3 helper = std::abs(a.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  Vec3 p = cross(a, helper);
  return mul(p, 1.0 / norm(p));
}

// A face is degenerate when its doubled area is below this fraction of its squared longest edge
// (or the edge itself vanishes): its normal is then numerically meaningless.
constexpr double kDegenerateRatio = 1e-10;

inline Vec3 load(const float* v) { return {v[0], v[1], v[2]}; }
inline void store(float* out, const Vec3& v) {
  out[0] = static_cast<float>(v.x);
  out[1] = static_cast<float>(v.y);
  out[2] = static_cast<float>(v.z);
}

// Projects axis a into the plane of unit normal n; returns false when it nearly vanishes.
bool project(const Vec3& a, const Vec3& n, double degenerate_cos, Vec3& o) {
  const double an = dot(a, n);
  if (std::abs(an) > degenerate_cos) return false;
  o = sub(a, mul(n, an));
  const double len = norm(o);
  if (!(len > 1e-12)) return false;
  o = mul(o, 1.0 / len);
  return true;
}

// Frames one face: the normal, area and orientation (the axis projected, then the strokes
// blended in) and, when `corners` is set, the bitangent, corner coordinates and anchor. Used by
// compute_orientation for every face and by refresh_face_frames for a few: the same arithmetic,
// so the same bits.
struct FaceFramer {
  enum Kind { kNormal, kDegenerate, kFallback };
  const float* pos;
  const uint32_t* idx;
  Vec3 axis, axis2, origin;
  double unit_scale, degenerate_cos;
  const float* face_axis;                // #F by 3 skeleton directions, or nullptr
  const internal::StrokeField* strokes;  // may be empty
  bool corners;                          // write the corner frame (no smoothing follows)
  FaceFrames* frames;
  // OrientationOptions::anchor_period: the world origin's offset from `origin`, projected on a
  // face's (o, p) and reduced modulo the period, is added to its anchor (in double: a cell far from
  // the origin projects to millions of periods).
  std::array<double, 2> anchor_period{0.0, 0.0};

  // Corner k of face f in normalised coordinates.
  Vec3 corner(size_t f, int k) const { return mul(sub(load(pos + 3 * idx[3 * f + k]), origin), unit_scale); }

  // Bitangent, corners in the face frame and anchor, from the stored (float) normal and orientation.
  void write_corner_frame(size_t f, const Vec3& p0, const Vec3& p1, const Vec3& p2) const {
    const Vec3 n = load(&frames->normal[3 * f]);
    const Vec3 o = load(&frames->orientation[3 * f]);
    const Vec3 p = cross(n, o);  // (o, p, n) right-handed: counter-clockwise stays counter-clockwise
    store(&frames->bitangent[3 * f], p);
    float* local = &frames->local[6 * f];
    const Vec3 d1 = sub(p1, p0), d2 = sub(p2, p0);
    local[0] = 0.f;
    local[1] = 0.f;
    local[2] = static_cast<float>(dot(d1, o));
    local[3] = static_cast<float>(dot(d1, p));
    local[4] = static_cast<float>(dot(d2, o));
    local[5] = static_cast<float>(dot(d2, p));
    double anchor_o = dot(p0, o), anchor_p = dot(p0, p);
    if (anchor_period[0] > 0.0 && anchor_period[1] > 0.0) {
      const Vec3 shift = mul(origin, unit_scale);
      anchor_o += std::fmod(dot(shift, o), anchor_period[0]);
      anchor_p += std::fmod(dot(shift, p), anchor_period[1]);
    }
    frames->anchor[2 * f] = static_cast<float>(anchor_o);
    frames->anchor[2 * f + 1] = static_cast<float>(anchor_p);
  }
  void write_corner_frame(size_t f) const { write_corner_frame(f, corner(f, 0), corner(f, 1), corner(f, 2)); }

  // Turns o towards the strokes' direction at the face's centroid by the strokes' weight (a
  // rotation in the face plane: at weight 1, o is the direction projected onto the face).
  void blend_stroke(size_t f, const Vec3& n, Vec3& o) const {
    Vec3 q;
    for (int k = 0; k < 3; ++k) q = add(q, load(pos + 3 * idx[3 * f + k]));
    const double centroid[3] = {q.x / 3, q.y / 3, q.z / 3};
    double d[3];
    const double w = strokes->sample(centroid, d);
    Vec3 t;
    if (!(w > 0) || !project({d[0], d[1], d[2]}, n, degenerate_cos, t)) return;
    const Vec3 p = cross(n, o);
    const double angle = w * std::atan2(dot(t, p), dot(t, o));
    o = add(mul(o, std::cos(angle)), mul(p, std::sin(angle)));
    o = mul(o, 1.0 / norm(o));
  }

  Kind frame(size_t f) const {
    const Vec3 p0 = corner(f, 0), p1 = corner(f, 1), p2 = corner(f, 2);
    const Vec3 e1 = sub(p1, p0), e2 = sub(p2, p0);
    Vec3 n = cross(e1, e2);
    const double twice_area = norm(n);
    const double longest2 = std::max({dot(e1, e1), dot(e2, e2), dot(sub(p2, p1), sub(p2, p1))});
    Vec3 o;
    Kind kind = kNormal;
    if (!(twice_area > kDegenerateRatio * longest2) || !(longest2 > 0)) {
      // Zero-area face: any orthonormal frame; o along its longest edge when there is one.
      kind = kDegenerate;
      n = perpendicular(axis);
      if (!project(axis, n, degenerate_cos, o)) o = perpendicular(n);
    } else {
      n = mul(n, 1.0 / twice_area);
      // With a skeleton, its edge is this face's axis and the PCA axes are the fallbacks.
      const bool own = face_axis && project(load(&face_axis[3 * f]), n, degenerate_cos, o);
      if (!own && !project(axis, n, degenerate_cos, o)) {
        kind = kFallback;
        if (!project(axis2, n, degenerate_cos, o)) o = perpendicular(n);
      }
      if (!strokes->empty()) blend_stroke(f, n, o);
    }
    store(&frames->normal[3 * f], n);
    store(&frames->orientation[3 * f], o);
    frames->area[f] = static_cast<float>(0.5 * twice_area);
    // Without smoothing the frame is final: finish the face while its corners are in cache.
    if (corners) write_corner_frame(f, p0, p1, p2);
    return kind;
  }
};

// Sum of the angles between face f's orientation and its edge neighbours' (the variation).
// Each angle is computed from the half-edge of lower id, as compute_orientation's edge pass does.
double face_variation(const uint32_t* opposite, const float* orientation, size_t f) {
  double sum = 0;
  for (size_t e = 3 * f; e < 3 * f + 3; ++e) {
    if (opposite[e] == kInvalid) continue;
    const size_t low = std::min<size_t>(e, opposite[e]), high = std::max<size_t>(e, opposite[e]);
    const Vec3 o = load(&orientation[3 * (low / 3)]);
    const Vec3 other = load(&orientation[3 * (high / 3)]);
    sum += std::acos(std::clamp(dot(o, other), -1.0, 1.0));
  }
  return sum;
}

}  // namespace

namespace internal {

Status compute_orientation_setup(const Mesh& mesh, const Topology& topology, const OrientationOptions& options,
                                 FaceFrames& frames, OrientationSetup* setup) {
  const auto start = std::chrono::steady_clock::now();
  frames = FaceFrames{};
  const size_t face_count = mesh.face_count();
  const size_t vertex_count = mesh.vertex_count();
  if (face_count == 0) return Status::error(ErrorCode::kInvalidMesh, "", "mesh has no face");
  if (topology.opposite.size() != 3 * face_count)
    return Status::error(ErrorCode::kInvalidMesh, "", "topology does not match the mesh");
  if (options.smooth_passes > OrientationLimits::max_smooth_passes)
    return Status::error(ErrorCode::kInvalidArgument, "",
                         "smoothing passes must be at most " + std::to_string(OrientationLimits::max_smooth_passes));
  if (!(options.degenerate_cos >= 0.5f && options.degenerate_cos <= 1.f))
    return Status::error(ErrorCode::kInvalidArgument, "", "degenerate_cos must be in [0.5, 1]");
  if (!(options.anchor_period[0] >= 0.0) || !(options.anchor_period[1] >= 0.0) ||
      !std::isfinite(options.anchor_period[0]) || !std::isfinite(options.anchor_period[1]))
    return Status::error(ErrorCode::kInvalidArgument, "", "anchor periods must be finite and >= 0");
  if (!(options.fixed_unit_scale >= 0.f) || !std::isfinite(options.fixed_unit_scale))
    return Status::error(ErrorCode::kInvalidArgument, "", "fixed unit scale must be finite and >= 0");
  TAILOR_RETURN_IF_ERROR(internal::check_strokes(options.strokes));
  const float* pos = mesh.positions.data();
  const uint32_t* idx = mesh.indices.data();

  // === Normalisation into the unit cube, PCA over referenced vertices ===
  std::vector<uint8_t> used(vertex_count, 0);
  for (size_t c = 0; c < 3 * face_count; ++c) used[idx[c]] = 1;
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY}, mean{};
  size_t used_count = 0;
  for (size_t v = 0; v < vertex_count; ++v) {
    if (!used[v]) continue;
    const Vec3 p = load(pos + 3 * v);
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    mean = add(mean, p);
    ++used_count;
  }
  mean = mul(mean, 1.0 / static_cast<double>(used_count));
  double unit_scale = 1.0;
  Vec3 origin = lo;
  if (options.fixed_unit_scale > 0.f) {
    unit_scale = options.fixed_unit_scale;
    origin = {options.fixed_origin[0], options.fixed_origin[1], options.fixed_origin[2]};
  } else {
    const double longest = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    unit_scale = longest > 0 ? 1.0 / longest : 1.0;
  }

  Vec3 axis, axis2;
  if (options.axis == AxisSource::kUser) {
    axis = {options.user_axis[0], options.user_axis[1], options.user_axis[2]};
    const double len = norm(axis);
    if (!(len > 0) || !std::isfinite(len))
      return Status::error(ErrorCode::kInvalidArgument, "", "orientation axis must be non-zero and finite");
    axis = mul(axis, 1.0 / len);
    Vec3 second{options.user_axis2[0], options.user_axis2[1], options.user_axis2[2]};
    // Keep only the part of the fallback perpendicular to the axis; derive one if nothing is left.
    second = sub(second, mul(axis, dot(second, axis)));
    const double len2 = norm(second);
    axis2 = (len2 > 1e-6 && std::isfinite(len2)) ? mul(second, 1.0 / len2) : perpendicular(axis);
  } else {
    // Covariance in double about the mean: no catastrophic cancellation for offset meshes.
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (size_t v = 0; v < vertex_count; ++v) {
      if (!used[v]) continue;
      const Vec3 d = sub(load(pos + 3 * v), mean);
      const Eigen::Vector3d e(d.x, d.y, d.z);
      cov += e * e.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
    const Eigen::Matrix3d vecs = solver.eigenvectors();  // eigenvalues ascending
    if (solver.info() != Eigen::Success || !vecs.allFinite()) {
      axis = {1, 0, 0};
      axis2 = {0, 1, 0};
    } else {
      axis = canonical_sign({vecs(0, 2), vecs(1, 2), vecs(2, 2)});
      axis2 = canonical_sign({vecs(0, 1), vecs(1, 1), vecs(2, 1)});
    }
  }

  // Progress at the stage's steps (each a pass over the faces): cheap, and enough for a bar.
  auto reached = [&options](float done) { return !options.progress || options.progress(done); };
  const Status cancelled = Status::error(ErrorCode::kCancelled, "", "orientation cancelled");
  if (!reached(0.05f)) return cancelled;

  // === Skeleton: a per-face axis, the PCA axes kept as the fallbacks ===
  const size_t threads = internal::parallel_threads(face_count, options.threads);
  std::vector<float> face_axis;  // #F by 3; (0,0,0) where the face has no skeleton edge
  if (options.axis == AxisSource::kSkeleton) {
    const auto skeleton_start = std::chrono::steady_clock::now();
    internal::CurveSkeleton skeleton;
    if (Status s = internal::compute_curve_skeleton(mesh, topology, skeleton); !s) return s;
    internal::skeleton_face_directions(mesh, topology, skeleton, {axis.x, axis.y, axis.z}, threads, face_axis);
    frames.skeleton_edges = static_cast<uint32_t>(skeleton.edge_count());
    frames.skeleton_closed_holes = skeleton.closed_holes;
    for (size_t f = 0; f < face_count; ++f)
      if (face_axis[3 * f] == 0.f && face_axis[3 * f + 1] == 0.f && face_axis[3 * f + 2] == 0.f)
        ++frames.skeleton_pca_faces;
    frames.skeleton_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - skeleton_start).count();
  }

  if (!reached(0.1f)) return cancelled;

  // === User strokes: a direction and weight per point near them (surface/stroke_field.cpp) ===
  const internal::StrokeField strokes(options.strokes);

  // === Per-face normal, area, orientation ===
  // ~76 bytes per face of fresh memory: on large meshes, faulting it in 4 KiB pages costs more than
  // the arithmetic, so ask for huge pages first.
  auto allocate = [](std::vector<float>& v, size_t n) {
    internal::reserve_huge(v, n);
    v.resize(n);
  };
  allocate(frames.normal, 3 * face_count);
  allocate(frames.orientation, 3 * face_count);
  allocate(frames.bitangent, 3 * face_count);
  allocate(frames.area, face_count);
  allocate(frames.local, 6 * face_count);
  allocate(frames.variation, face_count);
  allocate(frames.anchor, 2 * face_count);
  std::vector<uint8_t> degenerate(face_count, 0);
  const FaceFramer framer{pos,
                          idx,
                          axis,
                          axis2,
                          origin,
                          unit_scale,
                          options.degenerate_cos,
                          face_axis.empty() ? nullptr : face_axis.data(),
                          &strokes,
                          options.smooth_passes == 0,
                          &frames,
                          options.anchor_period};
  // Faces are independent here: they are cut into fixed chunks shared out among the threads
  // (each writes only its own faces; counters are summed after), so the result is the same
  // bit for bit whatever the thread count.
  std::vector<size_t> degenerate_count(internal::chunk_count(face_count), 0),
      fallback_count(internal::chunk_count(face_count), 0);
  internal::for_each_chunk(face_count, threads, [&](size_t begin, size_t end, size_t chunk) {
    for (size_t f = begin; f < end; ++f) {
      const FaceFramer::Kind kind = framer.frame(f);
      degenerate[f] = kind == FaceFramer::kDegenerate;
      degenerate_count[chunk] += kind == FaceFramer::kDegenerate;
      fallback_count[chunk] += kind == FaceFramer::kFallback;
    }
  });
  for (size_t c = 0; c < degenerate_count.size(); ++c) {
    frames.degenerate_faces += static_cast<uint32_t>(degenerate_count[c]);
    frames.fallback_faces += static_cast<uint32_t>(fallback_count[c]);
  }

  if (!reached(0.5f)) return cancelled;

  // === Optional smoothing: Jacobi passes (double-buffered, so the result is order independent) ===
  if (options.smooth_passes > 0) {
    std::vector<float> next(frames.orientation.size());
    for (uint32_t pass = 0; pass < options.smooth_passes; ++pass) {
      if (!reached(0.5f + 0.2f * static_cast<float>(pass) / static_cast<float>(options.smooth_passes)))
        return cancelled;
      for (size_t f = 0; f < face_count; ++f) {
        Vec3 sum = load(&frames.orientation[3 * f]);
        if (!degenerate[f]) {
          for (int k = 0; k < 3; ++k) {
            const uint32_t g = neighbour_face(topology, static_cast<uint32_t>(3 * f + k));
            if (g == kInvalid || degenerate[g]) continue;
            sum = add(sum, load(&frames.orientation[3 * g]));
          }
          Vec3 o;
          // The sum of neighbours can cancel at a field singularity: keep the face's own value.
          if (project(sum, load(&frames.normal[3 * f]), 1.0, o))
            sum = o;
          else
            sum = load(&frames.orientation[3 * f]);
        }
        store(&next[3 * f], sum);
      }
      frames.orientation.swap(next);
    }
  }

  // === Bitangent, corner coordinates in the face frame, anchor (after smoothing) ===
  if (options.smooth_passes > 0) {
    for (size_t f = 0; f < face_count; ++f) framer.write_corner_frame(f);
  }

  // === Variation: sum of angles to the edge neighbours' orientations (the thesis's age) ===
  // acos dominates this stage, so each interior edge's angle is computed once, at its half-edge
  // of lower id, then each face adds its three in edge order (the same values in the same order
  // as if each face had computed them). Both passes write only their own chunk's half-edges or
  // faces: identical for any thread count.
  if (!reached(0.7f)) return cancelled;
  std::vector<double> edge_angle;
  internal::reserve_huge(edge_angle, 3 * face_count);
  edge_angle.resize(3 * face_count);
  const uint32_t* opposite = topology.opposite.data();
  internal::for_each_chunk(face_count, threads, [&](size_t begin, size_t end, size_t) {
    for (size_t f = begin; f < end; ++f) {
      const Vec3 o = load(&frames.orientation[3 * f]);
      for (size_t e = 3 * f; e < 3 * f + 3; ++e) {
        if (opposite[e] == kInvalid || opposite[e] < e) continue;
        const Vec3 other = load(&frames.orientation[3 * size_t{opposite[e] / 3}]);
        edge_angle[e] = std::acos(std::clamp(dot(o, other), -1.0, 1.0));
      }
    }
  });
  if (!reached(0.9f)) return cancelled;
  internal::for_each_chunk(face_count, threads, [&](size_t begin, size_t end, size_t) {
    for (size_t f = begin; f < end; ++f) {
      double sum = 0;
      for (size_t e = 3 * f; e < 3 * f + 3; ++e) {
        if (opposite[e] == kInvalid) continue;
        sum += edge_angle[std::min<size_t>(e, opposite[e])];
      }
      frames.variation[f] = static_cast<float>(sum);
    }
  });

  if (setup) {
    *setup = OrientationSetup{{axis.x, axis.y, axis.z},
                              {axis2.x, axis2.y, axis2.z},
                              {origin.x, origin.y, origin.z},
                              unit_scale,
                              std::move(face_axis)};
  }
  store(frames.axis.data(), axis);
  store(frames.axis2.data(), axis2);
  store(frames.origin.data(), origin);
  store(frames.bbox_min.data(), lo);
  store(frames.bbox_max.data(), hi);
  frames.unit_scale = static_cast<float>(unit_scale);
  frames.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!reached(1.f)) return cancelled;
  return Status::ok();
}

void refresh_face_frames(const Mesh& mesh, const Topology& topology, const OrientationOptions& options,
                         const OrientationSetup& setup, std::span<const uint32_t> faces, FaceFrames& frames) {
  const StrokeField strokes(options.strokes);
  const FaceFramer framer{mesh.positions.data(),
                          mesh.indices.data(),
                          {setup.axis[0], setup.axis[1], setup.axis[2]},
                          {setup.axis2[0], setup.axis2[1], setup.axis2[2]},
                          {setup.origin[0], setup.origin[1], setup.origin[2]},
                          setup.unit_scale,
                          options.degenerate_cos,
                          setup.face_axis.empty() ? nullptr : setup.face_axis.data(),
                          &strokes,
                          true,
                          &frames,
                          options.anchor_period};
  for (const uint32_t f : faces) framer.frame(f);
  // The variation of every face with an angle that changed (some twice: the same value).
  const uint32_t* opposite = topology.opposite.data();
  for (const uint32_t f : faces) {
    frames.variation[f] = static_cast<float>(face_variation(opposite, frames.orientation.data(), f));
    for (size_t e = 3 * size_t{f}; e < 3 * size_t{f} + 3; ++e)
      if (opposite[e] != kInvalid)
        frames.variation[opposite[e] / 3] =
            static_cast<float>(face_variation(opposite, frames.orientation.data(), opposite[e] / 3));
  }
}

}  // namespace internal

Status compute_orientation(const Mesh& mesh, const Topology& topology, const OrientationOptions& options,
                           FaceFrames& frames) {
  return internal::compute_orientation_setup(mesh, topology, options, frames, nullptr);
}

double mean_neighbour_angle(const Topology& topology, const FaceFrames& frames) {
  double sum = 0;
  size_t count = 0;
  const size_t corners = topology.opposite.size();
  for (size_t e = 0; e < corners; ++e) {
    const uint32_t o = topology.opposite[e];
    if (o == kInvalid || o < e) continue;
    const size_t f = e / 3, g = o / 3;
    const float* a = &frames.orientation[3 * f];
    const float* b = &frames.orientation[3 * g];
    const double d =
        static_cast<double>(a[0]) * b[0] + static_cast<double>(a[1]) * b[1] + static_cast<double>(a[2]) * b[2];
    sum += std::acos(std::clamp(d, -1.0, 1.0));
    ++count;
  }
  return count ? sum / static_cast<double>(count) : 0.0;
}

}  // namespace tailor
