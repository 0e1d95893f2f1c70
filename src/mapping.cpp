// Texture mapping entry point: validates the inputs, orders the components' seeds and dispatches
// to the patches mode (mapping_patches.cpp) or the thesis reference (mapping_thesis.cpp).
//
// This work is based on:
//   V. Singh, A. M. Namboodiri, "Efficient texture mapping by homogeneous patch discovery",
//   ICVGIP 2012 (thesis chapter 2).
#include "tailor/mapping.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "internal/mapping_common.h"

namespace tailor {

float face_stretch_error(std::span<const float, 6> local, float scale, std::span<const float, 6> uv) {
  // Q: the face's edges in its frame (pixels); U: the UV edges. J = U * Q^-1 maps face to UV.
  const float q1x = (local[2] - local[0]) * scale, q1y = (local[3] - local[1]) * scale;
  const float q2x = (local[4] - local[0]) * scale, q2y = (local[5] - local[1]) * scale;
  const float det_q = q1x * q2y - q2x * q1y;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  if (!(det_q > 0.f)) return kInf;
  const float u1x = uv[2] - uv[0], u1y = uv[3] - uv[1];
  const float u2x = uv[4] - uv[0], u2y = uv[5] - uv[1];
  const float inv = 1.f / det_q;
  const float a = (u1x * q2y - u2x * q1y) * inv;
  const float b = (u2x * q1x - u1x * q2x) * inv;
  const float c = (u1y * q2y - u2y * q1y) * inv;
  const float d = (u2y * q1x - u1y * q2x) * inv;
  // Closed-form singular values of a 2x2 matrix: sigma = |q| +- |r| with q, r its conformal and
  // anti-conformal parts; sigma_min is signed (negative when J reverses orientation).
  const float e = 0.5f * (a + d), h = 0.5f * (c - b);
  const float f = 0.5f * (a - d), g = 0.5f * (c + b);
  const float qn = std::sqrt(e * e + h * h), rn = std::sqrt(f * f + g * g);
  const float sigma_max = qn + rn, sigma_min = qn - rn;
  if (!(sigma_min > 1e-6f) || !(a * d - b * c > 0.f)) return kInf;
  return std::max(sigma_max - 1.f, 1.f / sigma_min - 1.f);
}

namespace internal {

std::vector<uint32_t> component_seed_faces(const Mesh& mesh, const Topology& topology, const FaceFrames& frames,
                                           const MappingOptions& options) {
  const size_t face_count = mesh.face_count();
  const float* pos = mesh.positions.data();
  const uint32_t* idx = mesh.indices.data();
  double target[3];
  if (options.use_seed_point) {
    for (int i = 0; i < 3; ++i) target[i] = options.seed_point[i];
  } else {
    // Centre of the bounding box of the referenced vertices (mesh coordinates).
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t c = 0; c < 3 * face_count; ++c) {
      const float* p = pos + 3 * idx[c];
      for (int i = 0; i < 3; ++i) {
        lo[i] = std::min(lo[i], static_cast<double>(p[i]));
        hi[i] = std::max(hi[i], static_cast<double>(p[i]));
      }
    }
    for (int i = 0; i < 3; ++i) target[i] = 0.5 * (lo[i] + hi[i]);
  }
  (void)frames;
  const uint32_t components = topology.edge_components;
  std::vector<double> best_distance(components, INFINITY);
  std::vector<uint32_t> best_face(components, kInvalid);
  for (size_t f = 0; f < face_count; ++f) {
    double d2 = 0;
    for (int i = 0; i < 3; ++i) {
      const double centroid =
          (static_cast<double>(pos[3 * idx[3 * f] + i]) + pos[3 * idx[3 * f + 1] + i] + pos[3 * idx[3 * f + 2] + i]) /
          3.0;
      d2 += (centroid - target[i]) * (centroid - target[i]);
    }
    const uint32_t comp = topology.face_component[f];
    if (d2 < best_distance[comp]) {  // strict: the lowest face id wins ties
      best_distance[comp] = d2;
      best_face[comp] = static_cast<uint32_t>(f);
    }
  }
  std::vector<uint32_t> order;
  order.reserve(components);
  for (uint32_t c = 0; c < components; ++c)
    if (best_face[c] != kInvalid) order.push_back(c);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    if (best_distance[a] != best_distance[b]) return best_distance[a] < best_distance[b];
    return best_face[a] < best_face[b];
  });
  std::vector<uint32_t> seeds(order.size());
  for (size_t i = 0; i < order.size(); ++i) seeds[i] = best_face[order[i]];
  return seeds;
}

}  // namespace internal

Status map_texture(const Mesh& mesh, const Topology& topology, const FaceFrames& frames,
                   const MappingOptions& options, Atlas& atlas, MappingStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  // Cleared, not freed: a caller mapping again reuses the memory (no page faults on 37 MB).
  atlas.corner_uv.clear();
  atlas.patch.clear();
  atlas.patch_count = 0;
  const size_t face_count = mesh.face_count();
  if (face_count == 0) return Status::error(ErrorCode::kInvalidMesh, "", "mesh has no face");
  if (topology.opposite.size() != 3 * face_count || topology.face_component.size() != face_count)
    return Status::error(ErrorCode::kInvalidMesh, "", "topology does not match the mesh");
  if (frames.face_count() != face_count || frames.local.size() != 6 * face_count ||
      frames.variation.size() != face_count || frames.anchor.size() != 2 * face_count)
    return Status::error(ErrorCode::kInvalidMesh, "", "face frames do not match the mesh");
  if (!(options.scale > 0.f) || !std::isfinite(options.scale) || options.scale > 1e7f)
    return Status::error(ErrorCode::kInvalidArgument, "", "scale must be a positive finite number of pixels (<= 1e7)");
  if (!(options.max_stretch >= 0.01f && options.max_stretch <= 4.f))
    return Status::error(ErrorCode::kInvalidArgument, "", "max stretch must be in [0.01, 4]");
  if (!(options.field_following >= 0.f && options.field_following <= 1.f))
    return Status::error(ErrorCode::kInvalidArgument, "", "field following must be in [0, 1]");
  if (!(options.max_seed_rotation_deg >= 0.f && options.max_seed_rotation_deg <= 180.f))
    return Status::error(ErrorCode::kInvalidArgument, "", "max seed rotation must be in [0, 180] degrees");
  if (!(options.threshold_px > 0.f) || !std::isfinite(options.threshold_px) || !(options.threshold_step_px > 0.f) ||
      !std::isfinite(options.threshold_step_px))
    return Status::error(ErrorCode::kInvalidArgument, "", "threshold and its step must be positive pixels");
  if (!std::isfinite(options.factor_step) || options.factor_step > 1.0)
    return Status::error(ErrorCode::kInvalidArgument, "", "factor step must be finite and at most 1");
  if (!options.seam_faces.empty() && options.seam_faces.size() != face_count)
    return Status::error(ErrorCode::kInvalidArgument, "", "seam face flags must hold one entry per face");
  if (options.use_seed_point && !(std::isfinite(options.seed_point[0]) && std::isfinite(options.seed_point[1]) &&
                                  std::isfinite(options.seed_point[2])))
    return Status::error(ErrorCode::kInvalidArgument, "", "seed point must be finite");

  const bool thesis = options.mode == MappingMode::kThesis;
  double factor_step = options.factor_step;
  if (factor_step < 0) factor_step = thesis ? 1.0 / static_cast<double>(face_count) : 1e-4;
  internal::MappingInput input{mesh, topology, frames, options, factor_step,
                               internal::component_seed_faces(mesh, topology, frames, options)};
  MappingStats local_stats;
  local_stats.components = static_cast<uint32_t>(input.component_seeds.size());
  Status status = thesis ? internal::map_thesis(input, atlas, local_stats)
                         : internal::map_patches(input, atlas, local_stats);
  if (!status.is_ok()) {
    atlas.corner_uv.clear();
    atlas.patch.clear();
    atlas.patch_count = 0;
    return status;
  }
  local_stats.patches = atlas.patch_count;
  local_stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (stats) *stats = local_stats;
  return Status::ok();
}

}  // namespace tailor
