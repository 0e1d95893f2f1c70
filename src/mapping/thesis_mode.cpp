// Mapping mode "thesis": the algorithm of thesis chapter 2 as written, kept as the reference.
//
// One UV per vertex; a face with two textured vertices gets its third as the mean of the two
// predictions when they differ by at most the threshold (pixels at `scale`), else it is deferred
// (the thesis's age + LargeVal: it goes after every face that has not failed); a face with three
// textured vertices is accepted as it is (about half the faces, thesis fig. 2.4); when every
// waiting face has failed, the threshold rises by threshold_step_px and they are all retried.
// Nothing prevents inverted faces: they are counted in MappingStats::inverted_accepted.
//
// This work is based on:
//   V. Singh, A. M. Namboodiri, "Efficient texture mapping by homogeneous patch discovery",
//   ICVGIP 2012 (thesis chapter 2, Algorithm 1).
#include <algorithm>
#include <cmath>

#include "mapping/face_queue.h"
#include "mapping/mapping_common.h"

namespace tailor::internal {

Status map_thesis(const MappingInput& in, Atlas& atlas, MappingStats& stats) {
  const Mesh& mesh = in.mesh;
  const size_t face_count = mesh.face_count();
  const size_t vertex_count = mesh.vertex_count();
  const uint32_t* idx = mesh.indices.data();
  const uint32_t* opposite = in.topology.opposite.data();
  const float* local = in.frames.local.data();
  const float* variation = in.frames.variation.data();
  const float* anchor = in.frames.anchor.data();
  const uint8_t* seam = in.options.seam_faces.empty() ? nullptr : in.options.seam_faces.data();
  const float scale = in.options.scale;
  float threshold = in.options.threshold_px;

  std::vector<float> vertex_uv(2 * vertex_count, 0.f);
  std::vector<uint8_t> textured(vertex_count, 0);
  std::vector<uint8_t> placed(face_count, 0);
  std::vector<uint8_t> placed_neighbours(face_count, 0);
  atlas.patch.assign(face_count, kInvalid);
  FaceQueue queue;
  queue.reset(face_count);
  double factor = 0.0;
  uint64_t placed_count = 0;
  for (size_t f = 0; f < face_count; ++f) stats.faces_seam += seam && seam[f] ? 1 : 0;

  auto frame_x = [&](uint32_t f, int i, int j) { return (local[6 * f + 2 * j] - local[6 * f + 2 * i]) * scale; };
  auto frame_y = [&](uint32_t f, int i, int j) {
    return (local[6 * f + 2 * j + 1] - local[6 * f + 2 * i + 1]) * scale;
  };
  bool cancelled = false;
  auto finish_face = [&](uint32_t f, uint32_t patch) {
    placed[f] = 1;
    atlas.patch[f] = patch;
    const float age_offset = static_cast<float>(factor);
    for (int k = 0; k < 3; ++k) {
      const uint32_t o = opposite[3 * f + k];
      if (o == kInvalid || placed[o / 3]) continue;
      const uint32_t h = o / 3;
      const uint64_t cls = seam && seam[h] ? kSeam : kWaiting;
      queue.set(front_key(cls, ++placed_neighbours[h], variation[h] + age_offset, h));
    }
    factor += in.factor_step;
    if (++placed_count % kProgressInterval == 0 && in.options.progress &&
        !in.options.progress(static_cast<float>(placed_count) / static_cast<float>(face_count)))
      cancelled = true;
  };

  uint32_t patch = 0;
  for (const uint32_t seed : in.component_seeds) {
    if (placed[seed]) continue;
    // The seed's corners at the UV its position gives in its own frame (order independent).
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = idx[3 * seed + k];
      vertex_uv[2 * v] = (anchor[2 * seed] + local[6 * seed + 2 * k]) * scale;
      vertex_uv[2 * v + 1] = (anchor[2 * seed + 1] + local[6 * seed + 2 * k + 1]) * scale;
      textured[v] = 1;
    }
    ++stats.faces_unfolded;
    finish_face(seed, patch);
    while (!queue.empty()) {
      if (cancelled) return Status::error(ErrorCode::kCancelled, "", "mapping cancelled");
      const uint64_t key = queue.top();
      if (front_class(key) == kDeferred) {
        // Every waiting face exceeds the threshold: raise it and retry them all.
        threshold += in.options.threshold_step_px;
        ++stats.threshold_raises;
        queue.transform_keys([](uint64_t k) { return front_class(k) == kDeferred ? with_class(k, kWaiting) : k; });
        continue;
      }
      queue.pop();
      const uint32_t f = FaceQueue::face_of(key);
      int known = 0, missing = -1;
      for (int k = 0; k < 3; ++k) {
        if (textured[idx[3 * f + k]])
          ++known;
        else
          missing = k;
      }
      if (known == 3) {
        ++stats.faces_three_textured;
      } else if (known == 2) {
        const int kc = missing, ka = (missing + 1) % 3, kb = (missing + 2) % 3;
        const uint32_t a = idx[3 * f + ka], b = idx[3 * f + kb], c = idx[3 * f + kc];
        const float pax = vertex_uv[2 * a] + frame_x(f, ka, kc), pay = vertex_uv[2 * a + 1] + frame_y(f, ka, kc);
        const float pbx = vertex_uv[2 * b] + frame_x(f, kb, kc), pby = vertex_uv[2 * b + 1] + frame_y(f, kb, kc);
        const float error = std::sqrt((pax - pbx) * (pax - pbx) + (pay - pby) * (pay - pby));
        if (error > threshold) {
          ++stats.deferrals;
          queue.set(with_class(key, kDeferred));
          continue;
        }
        stats.max_error_px = std::max(stats.max_error_px, error);
        vertex_uv[2 * c] = 0.5f * (pax + pbx);
        vertex_uv[2 * c + 1] = 0.5f * (pay + pby);
        textured[c] = 1;
        ++stats.faces_unfolded;
      } else {
        // One textured vertex (a face touching the patch at a corner only): own frame from it.
        int from = 0;
        while (known == 1 && !textured[idx[3 * f + from]]) ++from;
        const uint32_t v0 = idx[3 * f + from];
        float base[2] = {vertex_uv[2 * v0], vertex_uv[2 * v0 + 1]};
        if (known == 0) {
          base[0] = (anchor[2 * f] + local[6 * f + 2 * from]) * scale;
          base[1] = (anchor[2 * f + 1] + local[6 * f + 2 * from + 1]) * scale;
        }
        for (int k = 0; k < 3; ++k) {
          const uint32_t v = idx[3 * f + k];
          if (textured[v]) continue;
          vertex_uv[2 * v] = base[0] + frame_x(f, from, k);
          vertex_uv[2 * v + 1] = base[1] + frame_y(f, from, k);
          textured[v] = 1;
        }
        ++stats.faces_unfolded;
      }
      finish_face(f, patch);
    }
    ++patch;
  }
  if (cancelled) return Status::error(ErrorCode::kCancelled, "", "mapping cancelled");

  // Corners take their vertex's single UV; count the inverted faces the thesis accepts.
  atlas.corner_uv.resize(6 * face_count);
  for (size_t f = 0; f < face_count; ++f) {
    float* uv = &atlas.corner_uv[6 * f];
    for (int k = 0; k < 3; ++k) {
      uv[2 * k] = vertex_uv[2 * idx[3 * f + k]];
      uv[2 * k + 1] = vertex_uv[2 * idx[3 * f + k] + 1];
    }
    const float signed_area = (uv[2] - uv[0]) * (uv[5] - uv[1]) - (uv[4] - uv[0]) * (uv[3] - uv[1]);
    if (!(signed_area > 0.f)) ++stats.inverted_accepted;
  }
  atlas.patch_count = patch;
  stats.patches_before_absorb = patch;
  stats.final_threshold_px = threshold;
  return Status::ok();
}

}  // namespace tailor::internal
