// Stability of the mapping under another file order and under removal of part of the mesh
// (thesis 2.6, Table 2.1; tailor/stability.h).
//
// This work is based on:
//   V. Singh, A. M. Namboodiri, "Efficient texture mapping by homogeneous patch discovery",
//   ICVGIP 2012 (thesis section 2.6).
#include "tailor/stability.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <span>
#include <utility>
#include <vector>

#include "tailor/mapping.h"
#include "tailor/topology.h"
#include "util/mesh_bounds.h"
#include "util/zero_area.h"

namespace tailor {
namespace {

void face_centroid(const Mesh& mesh, size_t f, double out[3]) {
  for (int i = 0; i < 3; ++i) {
    out[i] = (static_cast<double>(mesh.positions[3 * mesh.indices[3 * f] + i]) +
              mesh.positions[3 * mesh.indices[3 * f + 1] + i] + mesh.positions[3 * mesh.indices[3 * f + 2] + i]) /
             3.0;
  }
}

double distance2(const double a[3], const double b[3]) {
  return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
}

// The mesh written in another order: faces, vertices and each face's corners permuted by a fixed
// hash (the surface and its connectivity unchanged). face_of[j] is the original face of face j,
// whose corner k is the original's corner (j + k) % 3.
Mesh reordered_copy(const Mesh& mesh, std::span<const uint8_t> seams, std::vector<uint32_t>& face_of,
                    std::vector<uint8_t>& reordered_seams) {
  auto mix = [](uint64_t x) {  // splitmix64's finaliser
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
  };
  auto shuffled = [&](size_t n, uint64_t salt) {
    std::vector<std::pair<uint64_t, uint32_t>> keys(n);
    for (size_t i = 0; i < n; ++i) keys[i] = {mix(i ^ salt), static_cast<uint32_t>(i)};
    std::sort(keys.begin(), keys.end());
    std::vector<uint32_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = keys[i].second;
    return order;
  };
  const std::vector<uint32_t> vertex_of = shuffled(mesh.vertex_count(), 0x5EED);
  std::vector<uint32_t> new_vertex(mesh.vertex_count());
  for (size_t i = 0; i < vertex_of.size(); ++i) new_vertex[vertex_of[i]] = static_cast<uint32_t>(i);
  face_of = shuffled(mesh.face_count(), 0xFACE);
  Mesh out;
  out.positions.resize(mesh.positions.size());
  for (size_t i = 0; i < vertex_of.size(); ++i)
    for (size_t k = 0; k < 3; ++k) out.positions[3 * i + k] = mesh.positions[3 * size_t{vertex_of[i]} + k];
  out.indices.resize(mesh.indices.size());
  reordered_seams.clear();
  for (size_t j = 0; j < face_of.size(); ++j) {
    for (size_t k = 0; k < 3; ++k)
      out.indices[3 * j + k] = new_vertex[mesh.indices[3 * size_t{face_of[j]} + (j + k) % 3]];
    if (!seams.empty()) reordered_seams.push_back(seams[face_of[j]]);
  }
  return out;
}

}  // namespace

Status measure_stability(const Mesh& mesh, const MapTextureOptions& options, StabilityReport& report,
                         const StabilityOptions& stability) {
  const auto start = std::chrono::steady_clock::now();
  report = StabilityReport{};
  const size_t face_count = mesh.face_count();
  if (face_count < 10) return Status::error(ErrorCode::kInvalidMesh, "", "stability needs at least 10 faces");
  if (!(stability.remove_fraction > 0.f && stability.remove_fraction <= 0.9f))
    return Status::error(ErrorCode::kInvalidArgument, "", "remove fraction must be in (0, 0.9]");
  // As the metrics of a map refuse it: a surface without area has no UVs to keep.
  bool has_area = false;
  for (size_t f = 0; f < face_count && !has_area; ++f)
    has_area = !internal::is_zero_area(mesh.positions.data(), mesh.indices[3 * f], mesh.indices[3 * f + 1],
                                       mesh.indices[3 * f + 2]);
  if (!has_area) return Status::error(ErrorCode::kInvalidMesh, "", "every face has zero 3D area");

  const Topology topology = build_topology(mesh);
  MapTextureOptions run = options;  // every run: no progress, no metrics
  MappingOptions& map_options = run.mapping;
  map_options.progress = nullptr;
  run.stage_progress = nullptr;
  run.measure = false;
  // The ball's centre: the face farthest from the seed point (pin_frame) or from the centre of the
  // bounding box of the referenced vertices (fresh runs: nothing but the geometry decides).
  double seed[3];
  if (stability.pin_frame) {
    // The frame (axis and unit-cube normalisation) is resolved once on the full mesh and then
    // given explicitly to both runs, as a client that keeps them would.
    FaceFrames frames;
    TAILOR_RETURN_IF_ERROR(compute_orientation(mesh, topology, options.orientation, frames));
    OrientationOptions& fixed = run.orientation;
    fixed.axis = AxisSource::kUser;
    fixed.user_axis = frames.axis;
    fixed.user_axis2 = frames.axis2;
    fixed.fixed_origin = frames.origin;
    fixed.fixed_unit_scale = frames.unit_scale;
    if (!map_options.use_seed_point) {
      // Pin the default seed (nearest the bbox centre) so that the cut mesh starts at the same face.
      const std::vector<uint32_t> seeds = component_seed_faces(mesh, topology, frames, map_options);
      double c[3];
      face_centroid(mesh, seeds.front(), c);
      map_options.use_seed_point = true;
      map_options.seed_point = {static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(c[2])};
    }
    for (int i = 0; i < 3; ++i) seed[i] = map_options.seed_point[static_cast<size_t>(i)];
  } else {
    const internal::Bounds box = internal::referenced_bounds(mesh);
    for (size_t k = 0; k < 3; ++k) seed[k] = 0.5 * (box.lo[k] + box.hi[k]);
  }
  // === The ball: centred on the face farthest from that point, holding remove_fraction of faces ===
  size_t far_face = 0;
  double far_d2 = -1;
  std::vector<std::pair<double, uint32_t>> by_distance(face_count);
  std::vector<double> to_seed(face_count);  // squared distance of each centroid to the seed point
  for (size_t f = 0; f < face_count; ++f) {
    double c[3];
    face_centroid(mesh, f, c);
    const double d2 = to_seed[f] = distance2(c, seed);
    if (d2 > far_d2) {
      far_d2 = d2;
      far_face = f;
    }
  }
  double centre[3];
  face_centroid(mesh, far_face, centre);
  for (size_t f = 0; f < face_count; ++f) {
    double c[3];
    face_centroid(mesh, f, c);
    by_distance[f] = {distance2(c, centre), static_cast<uint32_t>(f)};
  }
  const size_t removed = std::clamp<size_t>(
      static_cast<size_t>(std::lround(stability.remove_fraction * static_cast<double>(face_count))), 1, face_count - 1);
  std::nth_element(by_distance.begin(), by_distance.begin() + static_cast<std::ptrdiff_t>(removed - 1),
                   by_distance.end());
  std::vector<uint8_t> gone(face_count, 0);
  for (size_t i = 0; i < removed; ++i) gone[by_distance[i].second] = 1;
  if (stability.pin_frame) {
    // On meshes whose face density varies a lot (CAD parts) the ball can reach the seed; both runs
    // then start at the surviving face nearest to it, or the experiment would measure a new seed.
    uint32_t nearest = kInvalid;
    double nearest_d2 = 0;
    for (size_t f = 0; f < face_count; ++f) {
      if (gone[f] || (nearest != kInvalid && to_seed[f] >= nearest_d2)) continue;
      nearest = static_cast<uint32_t>(f);
      nearest_d2 = to_seed[f];
    }
    double c[3];
    face_centroid(mesh, nearest, c);
    map_options.seed_point = {static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(c[2])};
  }
  TextureMap full_map;
  TAILOR_RETURN_IF_ERROR(map_texture(mesh, topology, run, full_map));
  const Atlas& full = full_map.atlas;
  report.locality_radius = full_map.stats.locality_radius;

  // === Order: the same surface written in another order, mapped afresh ===
  if (!stability.pin_frame) {
    std::vector<uint32_t> face_of;
    std::vector<uint8_t> seams;
    const Mesh shuffled = reordered_copy(mesh, options.mapping.seam_faces, face_of, seams);
    MapTextureOptions shuffled_run = run;
    shuffled_run.mapping.seam_faces = seams;
    TextureMap shuffled_map;
    TAILOR_RETURN_IF_ERROR(map_texture(shuffled, build_topology(shuffled), shuffled_run, shuffled_map));
    size_t same = 0;
    for (size_t j = 0; j < face_of.size(); ++j)
      for (size_t k = 0; k < 3; ++k) {
        const float* a = &full.corner_uv[2 * (3 * size_t{face_of[j]} + (j + k) % 3)];
        const float* b = &shuffled_map.atlas.corner_uv[2 * (3 * j + k)];
        same += (a[0] == b[0] && a[1] == b[1]) ? 1 : 0;
      }
    report.order_identical_ratio = static_cast<double>(same) / static_cast<double>(3 * face_count);
  }

  // === The cut mesh: same vertices (ids kept), surviving faces in their original order ===
  Mesh cut;
  cut.positions = mesh.positions;
  std::vector<uint32_t> original;  // cut face -> full face
  original.reserve(face_count - removed);
  double reach2 = 0;  // squared distance from the centre to the farthest corner of a removed face
  for (size_t f = 0; f < face_count; ++f) {
    if (gone[f]) {
      for (size_t k = 0; k < 3; ++k) {
        const float* p = &mesh.positions[3 * size_t{mesh.indices[3 * f + k]}];
        const double q[3] = {p[0], p[1], p[2]};
        reach2 = std::max(reach2, distance2(q, centre));
      }
      continue;
    }
    original.push_back(static_cast<uint32_t>(f));
    cut.indices.insert(cut.indices.end(), mesh.indices.begin() + static_cast<std::ptrdiff_t>(3 * f),
                       mesh.indices.begin() + static_cast<std::ptrdiff_t>(3 * f + 3));
  }
  std::vector<uint8_t> cut_seams;
  if (!options.mapping.seam_faces.empty()) {
    for (const uint32_t f : original) cut_seams.push_back(options.mapping.seam_faces[f]);
    map_options.seam_faces = cut_seams;
  }
  const Topology cut_topology = build_topology(cut);
  TextureMap cut_map;
  TAILOR_RETURN_IF_ERROR(map_texture(cut, cut_topology, run, cut_map));
  const Atlas& cut_atlas = cut_map.atlas;

  // === Compare surviving corners ===
  // Beyond the radius: a corner whose distance to the ball's centre, less the reach of the removed
  // faces, exceeds it (a lower bound of its distance to every removed face).
  const double reach = std::sqrt(reach2);
  double sum = 0, worst = 0;
  size_t identical = 0, close = 0, beyond = 0, beyond_identical = 0;
  std::vector<double> differences;
  differences.reserve(3 * original.size());
  for (size_t i = 0; i < original.size(); ++i) {
    const float* a = &full.corner_uv[6 * original[i]];
    const float* b = &cut_atlas.corner_uv[6 * i];
    for (int k = 0; k < 3; ++k) {
      const double du = static_cast<double>(a[2 * k]) - b[2 * k];
      const double dv = static_cast<double>(a[2 * k + 1]) - b[2 * k + 1];
      const double d = std::sqrt(du * du + dv * dv);
      sum += d;
      worst = std::max(worst, d);
      differences.push_back(d);
      const bool same = a[2 * k] == b[2 * k] && a[2 * k + 1] == b[2 * k + 1];
      identical += same ? 1 : 0;
      close += d < 1.0 ? 1 : 0;
      if (report.locality_radius > 0) {
        const float* p = &mesh.positions[3 * size_t{mesh.indices[3 * size_t{original[i]} + static_cast<size_t>(k)]}];
        const double q[3] = {p[0], p[1], p[2]};
        if (std::sqrt(distance2(q, centre)) - reach > report.locality_radius) {
          ++beyond;
          beyond_identical += same ? 1 : 0;
        }
      }
    }
  }
  const size_t corners = 3 * original.size();
  report.faces = face_count;
  report.removed_faces = removed;
  report.compared_corners = corners;
  report.mean_difference_px = sum / static_cast<double>(corners);
  report.max_difference_px = worst;
  std::nth_element(differences.begin(), differences.begin() + static_cast<std::ptrdiff_t>(differences.size() / 2),
                   differences.end());
  report.median_difference_px = differences[differences.size() / 2];
  report.identical_ratio = static_cast<double>(identical) / static_cast<double>(corners);
  report.within_1px_ratio = static_cast<double>(close) / static_cast<double>(corners);
  report.corners_beyond_radius = beyond;
  if (beyond > 0)
    report.identical_beyond_radius_ratio = static_cast<double>(beyond_identical) / static_cast<double>(beyond);
  report.patches_full = full.patch_count;
  report.patches_cut = cut_atlas.patch_count;
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::ok();
}

}  // namespace tailor
