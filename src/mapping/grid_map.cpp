// Integer-grid mapping (symmetry 4): extraction of per-corner UVs from the fields (grid_map.h).
#include "mapping/grid_map.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "mapping/face_stretch.h"
#include "mapping/grid_cones.h"
#include "mapping/grid_relax.h"
#include "surface/rosy_field.h"
#include "util/parallel_chunks.h"

namespace tailor::internal {
namespace {

// Rounds of relaxing the coordinates and rounding the lattice maps again, and relaxation
// iterations per round. Measured over the 16 shared meshes (median visible seam length at scale
// 800 / 8000, before the seam shortening, robust scale 0.3, lattice bound 1): 3 of 30: 6.3 / 3.7 %;
// 6 of 15: 6.3 / 3.7 % (10 % more time); 2 of 20: 6.7 / 4.0 % for 30 % less time. With the steps
// after it (seam shortening, crack closing, relaxation): 3 of 30: 4.42 / 2.16 %, 3 of 20: 4.47 /
// 2.25 % for 20 % less mapping time (the relaxation is most of it on large meshes).
constexpr uint32_t kRelaxRounds = 3;
constexpr uint32_t kRelaxIterations = 20;
// Faces per thread of the relaxation: its 80 sweeps make it worth a thread from far fewer faces
// than a single pass over them (util/parallel_chunks.h's 100k).
constexpr size_t kRelaxFacesPerThread = 20000;

//! Places face g from its placed neighbour across g's edge `k` (corners k, k+1 take the
//! neighbour's UVs at those vertices: ua, ub), the third corner by the similarity that maps g's
//! edge onto (ua, ub). rigid: the face keeps its shape at `scale`, centred on the edge's middle
//! (then the edge itself is a seam). Writes 6 floats in g's corner order; returns the stretch error.
float unfold(const float* local, float scale, uint32_t k, const float* ua, const float* ub, bool rigid, float* uv) {
  const uint32_t ia = k, ib = (k + 1) % 3, ic = (k + 2) % 3;
  const float lx = local[2 * ib] - local[2 * ia], ly = local[2 * ib + 1] - local[2 * ia + 1];
  const float cx = local[2 * ic] - local[2 * ia], cy = local[2 * ic + 1] - local[2 * ia + 1];
  const float ex = ub[0] - ua[0], ey = ub[1] - ua[1];
  const float l2 = lx * lx + ly * ly;
  float zx = scale, zy = 0.f;  // degenerate edge: the face's own frame
  if (l2 > 0.f) {
    zx = (ex * lx + ey * ly) / l2;  // z = E / L (complex)
    zy = (ey * lx - ex * ly) / l2;
  }
  float ax = ua[0], ay = ua[1];
  if (rigid) {
    const float zl = std::sqrt(zx * zx + zy * zy);
    if (zl > 0.f) {
      zx *= scale / zl;
      zy *= scale / zl;
    } else {
      zx = scale;
      zy = 0.f;
    }
    const float mx = 0.5f * (ua[0] + ub[0]), my = 0.5f * (ua[1] + ub[1]);
    ax = mx - 0.5f * (zx * lx - zy * ly);
    ay = my - 0.5f * (zx * ly + zy * lx);
  }
  uv[2 * ia] = ax;
  uv[2 * ia + 1] = ay;
  uv[2 * ib] = rigid ? ax + zx * lx - zy * ly : ub[0];
  uv[2 * ib + 1] = rigid ? ay + zx * ly + zy * lx : ub[1];
  uv[2 * ic] = ax + zx * cx - zy * cy;
  uv[2 * ic + 1] = ay + zx * cy + zy * cx;
  return stretch_error(stretch_frame(local, scale), uv);
}

// The fields and the relaxation hold lattice coordinates in pixels modulo the period, in floats
// (24 bits): a face a few millionths of the period wide has no precision left. Measured: spot at
// scale 0.02 (faces 3e-4 px wide) came out with Sander L2 1.06, at 0.001 with 859 flipped faces;
// the horse at 0.1 (3e-4 px) with 5 flipped. A mean side under 2^-18 of the period (0.002 px for
// 512 px) is refused with what to change rather than mapped badly. O(F).
Status check_lattice_precision(const FaceFrames& frames, float scale, float period) {
  double side = 0.0;
  size_t faces = 0;
  for (size_t f = 0; f < frames.face_count(); ++f) {
    const float* l = &frames.local[6 * f];
    const double twice = (static_cast<double>(l[2]) - l[0]) * (static_cast<double>(l[5]) - l[1]) -
                         (static_cast<double>(l[3]) - l[1]) * (static_cast<double>(l[4]) - l[0]);
    if (twice > 0.0) {
      side += std::sqrt(0.5 * twice);
      ++faces;
    }
  }
  const double mean_side_px = faces > 0 ? scale * side / static_cast<double>(faces) : 0.0;
  const double least_px = std::ldexp(static_cast<double>(period), -18);
  if (faces == 0 || mean_side_px >= least_px) return Status::ok();
  char text[200];
  std::snprintf(text, sizeof text,
                "symmetry 4 needs faces at least %.2g px wide at this scale (1/262144 of the %.0f px texture); "
                "they are %.2g px",
                least_px, static_cast<double>(period), mean_side_px);
  return Status::error(ErrorCode::kInvalidArgument, "", text,
                       "raise --scale or lower --tile-size: the lattice coordinates, floats modulo the texture, "
                       "hold no finer faces");
}

// Sander's L2 (docs/metrics.md), which the issue bounds at 1.02 on every mesh, estimated from the
// lattice charts before the faces beyond them are cut (those counted as isometric, as the
// unfolding nearly makes them): the area-weighted mean of (1/s1^2 + 1/s2^2) / 2 times the UV area
// over the 3D area, as the metric normalises. Within 0.003 of the final figure on the shared
// meshes (chinese-dragon at scale 8000: 1.0204 / 1.021, featuretype 1.0230 / 1.020, horse 1.0098 /
// 1.011). When the charts would pass kL2Budget, the most squashed faces are cut (unfolded
// instead) until they do not: with the relaxation's over-relaxation at 1.9, visible seams fell
// 3.27 -> 2.88 % (median, scale 800) and 1.80 -> 1.60 % (8000), but the dragon's L2 reached
// 1.0207 at 8000; with this bound it is 1.0172 at most, the medians unchanged.
constexpr double kL2Budget = 1.017;

//! A face's 3D area (scaled, pixels^2) and, for a chart (null: the face to be cut), its UV area and
//! its L2 term (1/s1^2 + 1/s2^2) / 2 = |J^-1|_F^2 / 2 of the chart's Jacobian J; without a chart,
//! or when either triangle has no positive area, the UV area is the 3D area and the term 1.
void sander_term(const float* local, float scale, const float* chart, float& area_3d, float& area_uv, float& term) {
  const double lx1 = scale * (static_cast<double>(local[2]) - local[0]);
  const double ly1 = scale * (static_cast<double>(local[3]) - local[1]);
  const double lx2 = scale * (static_cast<double>(local[4]) - local[0]);
  const double ly2 = scale * (static_cast<double>(local[5]) - local[1]);
  const double det_l = lx1 * ly2 - lx2 * ly1;
  area_3d = static_cast<float>(0.5 * std::abs(det_l));
  area_uv = area_3d;
  term = 1.f;
  if (!chart || !(det_l > 0.0)) return;
  const double ux1 = static_cast<double>(chart[2]) - chart[0], uy1 = static_cast<double>(chart[3]) - chart[1];
  const double ux2 = static_cast<double>(chart[4]) - chart[0], uy2 = static_cast<double>(chart[5]) - chart[1];
  const double det_u = ux1 * uy2 - ux2 * uy1;
  if (!(det_u > 0.0)) return;
  // J = U L^-1, so J^-1 = L U^-1 = L adj(U) / det_u.
  const double a00 = lx1 * uy2 - lx2 * uy1, a01 = lx2 * ux1 - lx1 * ux2;
  const double a10 = ly1 * uy2 - ly2 * uy1, a11 = ly2 * ux1 - ly1 * ux2;
  area_uv = static_cast<float>(0.5 * det_u);
  term = static_cast<float>(0.5 * (a00 * a00 + a01 * a01 + a10 * a10 + a11 * a11) / (det_u * det_u));
}

//! Cuts good faces, the largest L2 term first (ties: lower index), until the L2 estimate is within
//! kL2Budget. O(F), plus O(F log F) only when the estimate is over.
void keep_l2_within_budget(const std::vector<float>& area_3d, const std::vector<float>& area_uv,
                           const std::vector<float>& term, std::vector<uint8_t>& good) {
  double sum_3d = 0.0, sum_uv = 0.0, sum_term = 0.0;
  for (size_t f = 0; f < good.size(); ++f) {
    sum_3d += area_3d[f];
    sum_uv += area_uv[f];
    sum_term += static_cast<double>(area_3d[f]) * term[f];
  }
  const auto over = [&] { return sum_term * sum_uv > kL2Budget * kL2Budget * sum_3d * sum_3d; };
  if (!over()) return;
  std::vector<uint32_t> order;
  for (uint32_t f = 0; f < good.size(); ++f)
    if (good[f] && term[f] > 1.f) order.push_back(f);
  std::sort(order.begin(), order.end(),
            [&](uint32_t a, uint32_t b) { return term[a] != term[b] ? term[a] > term[b] : a < b; });
  for (const uint32_t f : order) {
    if (!over()) break;
    sum_term -= static_cast<double>(area_3d[f]) * (term[f] - 1.0);
    sum_uv -= static_cast<double>(area_uv[f]) - area_3d[f];
    good[f] = 0;
  }
}

}  // namespace

Status map_grid(const MappingInput& input, Atlas& atlas, MappingStats& stats, std::vector<uint8_t>& on_seam) {
  const Mesh& mesh = input.mesh;
  const Topology& topology = input.topology;
  const FaceFrames& frames = input.frames;
  const MappingOptions& options = input.options;
  const size_t nf = mesh.face_count();
  const uint32_t* idx = mesh.indices.data();
  const float scale = options.scale, period = options.texture_period_px;
  TAILOR_RETURN_IF_ERROR(check_lattice_precision(frames, scale, period));

  RosyFieldOptions field_options;
  field_options.scale = scale;
  field_options.period = period;
  field_options.threads = options.threads;
  RosyField field;
  compute_rosy_field(mesh, topology, frames, field_options, field);
  if (options.progress && !options.progress(0.8f)) return Status::error(ErrorCode::kCancelled, "", "cancelled");

  // Per face: the lattice maps of its corners into corner 0's chart and whether they close around
  // the face (no singularity).
  std::vector<LatticeMap> corner_map(3 * nf);
  std::vector<uint8_t> flat(nf, 0), good(nf, 0);
  atlas.corner_uv.resize(6 * nf);
  atlas.patch.assign(nf, kInvalid);
  float* uv = atlas.corner_uv.data();
  const size_t threads = parallel_threads(nf, options.threads);
  // The lattice map of every half-edge (from its end's chart to its start's), rounded from the
  // fields as they are.
  std::vector<LatticeMap> edge_map(3 * nf);
  const auto find_maps = [&] {
    for_each_chunk(nf, threads, [&](size_t begin, size_t end, size_t) {
      for (size_t e = 3 * begin; e < 3 * end; ++e)
        edge_map[e] = lattice_map(field, idx[e], idx[e - e % 3 + (e % 3 + 1) % 3]);
    });
    maps_from_edges(nf, threads, edge_map, corner_map, flat);
  };
  // The coordinates relaxed with the maps held (grid_relax.h), the maps rounded again from the
  // relaxed coordinates (a strip whose whole-repeat jumps the relaxation showed wrong gets the
  // jumps the surface asks for), and again.
  // After the first round only the vertices still moving and those of faces whose maps changed
  // start.
  std::vector<LatticeMap> previous_map;
  std::vector<uint8_t> previous_flat, moving;
  const auto remember = [&] {
    previous_map = corner_map;
    previous_flat = flat;
  };
  const auto mark_changed = [&] {
    for (size_t f = 0; f < nf; ++f) {
      bool changed = flat[f] != previous_flat[f];
      for (size_t k = 0; k < 3; ++k) changed |= !(corner_map[3 * f + k] == previous_map[3 * f + k]);
      if (changed && !moving.empty())  // empty: the relaxation has not run, every vertex starts
        for (size_t k = 0; k < 3; ++k) moving[idx[3 * f + k]] = 1;
    }
  };
  const LatticeRelaxation relaxation(mesh, frames, scale, period,
                                     parallel_threads(nf, options.threads, kRelaxFacesPerThread));
  const auto relax = [&] { relaxation.run(corner_map, flat, kRelaxIterations, &moving, field.uv); };
  for (uint32_t round = 0; round < kRelaxRounds; ++round) {
    if (round > 0) remember();
    find_maps();
    if (round > 0) mark_changed();
    relax();
    if (options.progress && !options.progress(0.8f + 0.15f * static_cast<float>(round + 1) / kRelaxRounds))
      return Status::error(ErrorCode::kCancelled, "", "cancelled");
  }
  // The mixed-integer step, locally (grid_cones.h): cone pairs of opposite turns cancelled,
  // dislocations handed to their nearest singular face, cones moved into the faces that hold their
  // fixed points; then relaxed once more. Over the 16 shared meshes at scale 8000, dislocations and
  // cones moved: median visible seams 2.24 -> 2.05 % of edge length (14 meshes lower, blobby 1.55
  // -> 0.63 %), invisible share 45 -> 48 %, at scale 800 unchanged (4.45 / 4.49 %); then cone pairs
  // cancelled (after the coarse position levels were settled): 1.85 -> 1.73 %, 3.19 -> 3.16 %.
  // Cones held on their nearest vertex (an integer-grid map's cone) and dislocations relaxed over a
  // band of faces were both worse (1.47 -> 1.55 and 1.53-1.57 % at 8000; docs/mapping.md section 7).
  remember();
  find_maps();
  cancel_cone_pairs(mesh, topology, edge_map);
  merge_dislocations(mesh, topology, edge_map);
  move_cones(mesh, topology, field.uv, period, edge_map);
  maps_from_edges(nf, threads, edge_map, corner_map, flat);
  mark_changed();
  relax();
  // Per face whether its chart triangle is within the lattice bound, and its part of Sander's L2.
  const float bound = lattice_max_stretch(options.max_stretch);
  std::vector<float> area_3d(nf, 0.f), area_uv(nf, 0.f), l2_term(nf, 1.f);
  for_each_chunk(nf, threads, [&](size_t begin, size_t end, size_t) {
    for (size_t f = begin; f < end; ++f) {
      const float* local = &frames.local[6 * f];
      float chart[6];
      for (size_t k = 0; k < 3; ++k) apply(corner_map[3 * f + k], period, &field.uv[2 * idx[3 * f + k]], chart + 2 * k);
      if (flat[f]) good[f] = is_zero_area_frame(local) || stretch_error(stretch_frame(local, scale), chart) <= bound;
      sander_term(local, scale, good[f] ? chart : nullptr, area_3d[f], area_uv[f], l2_term[f]);
    }
  });
  keep_l2_within_budget(area_3d, area_uv, l2_term, good);
  // Patches: breadth-first over good faces, chaining the lattice maps so that a face reached
  // across an edge copies that edge's UVs exactly.
  std::vector<LatticeMap> face_map(nf);
  std::vector<uint32_t> queue;
  queue.reserve(nf);
  uint32_t patches = 0;
  uint64_t good_faces = 0;
  auto grow = [&](uint32_t seed) {
    if (!good[seed] || atlas.patch[seed] != kInvalid) return;
    atlas.patch[seed] = patches;
    face_map[seed] = LatticeMap{};
    queue.assign(1, seed);
    for (size_t head = 0; head < queue.size(); ++head) {
      const uint32_t f = queue[head];
      for (uint32_t k = 0; k < 3; ++k) {
        const uint32_t o = topology.opposite[3 * f + k];
        if (o == kInvalid) continue;
        const uint32_t g = o / 3;
        if (!good[g] || atlas.patch[g] != kInvalid) continue;
        // Vertex idx[3f + k] is g's corner (o % 3 + 1) % 3 (the opposite edge runs backwards).
        const uint32_t j = (o % 3 + 1) % 3;
        face_map[g] = compose(compose(face_map[f], corner_map[3 * f + k]), inverse(corner_map[3 * g + j]));
        atlas.patch[g] = patches;
        queue.push_back(g);
      }
    }
    good_faces += queue.size();
    ++patches;
  };
  for (const uint32_t seed : input.component_seeds) grow(seed);
  for (uint32_t f = 0; f < nf; ++f) grow(f);
  for_each_chunk(nf, threads, [&](size_t begin, size_t end, size_t) {
    for (size_t f = begin; f < end; ++f) {
      if (!good[f]) continue;
      for (size_t k = 0; k < 3; ++k)
        apply(compose(face_map[f], corner_map[3 * f + k]), period, &field.uv[2 * idx[3 * f + k]], uv + 6 * f + 2 * k);
    }
  });

  // The rest (singular or over-stretched faces): unfolded from placed neighbours, nearest first.
  std::vector<uint8_t> placed(good);
  queue.clear();
  auto push_neighbours = [&](uint32_t f) {
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t o = topology.opposite[3 * f + k];
      if (o != kInvalid && !placed[o / 3]) queue.push_back(o / 3);
    }
  };
  for (uint32_t f = 0; f < nf; ++f)
    if (placed[f])
      continue;
    else
      for (uint32_t k = 0; k < 3; ++k) {
        const uint32_t o = topology.opposite[3 * f + k];
        if (o != kInvalid && placed[o / 3]) {
          queue.push_back(f);
          break;
        }
      }
  uint64_t unfolded = 0, rigid = 0;
  uint32_t next_unplaced = 0;
  size_t head = 0;
  while (true) {
    if (head == queue.size()) {
      // A component without any placed face: its first face sits at its anchor, in its frame.
      while (next_unplaced < nf && placed[next_unplaced]) ++next_unplaced;
      if (next_unplaced == nf) break;
      const uint32_t f = next_unplaced;
      const float* local = &frames.local[6 * f];
      for (size_t k = 0; k < 3; ++k) {
        uv[6 * f + 2 * k] = scale * (frames.anchor[2 * f] + local[2 * k]);
        uv[6 * f + 2 * k + 1] = scale * (frames.anchor[2 * f + 1] + local[2 * k + 1]);
      }
      placed[f] = 1;
      atlas.patch[f] = patches++;
      ++rigid;
      push_neighbours(f);
      continue;
    }
    const uint32_t f = queue[head++];
    if (placed[f]) continue;
    const float* local = &frames.local[6 * f];
    float best_uv[6], trial[6];
    float best = std::numeric_limits<float>::infinity();
    uint32_t best_k = kInvalid;
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t o = topology.opposite[3 * f + k];
      if (o == kInvalid || !placed[o / 3]) continue;
      const uint32_t g = o / 3;
      // f's corner k is g's corner (o % 3 + 1) % 3; f's corner k + 1 is g's corner o % 3.
      const float* ua = uv + 6 * g + 2 * ((o % 3 + 1) % 3);
      const float* ub = uv + 6 * g + 2 * (o % 3);
      float err = unfold(local, scale, k, ua, ub, false, trial);
      if (is_zero_area_frame(local)) err = 0.f;
      if (err < best || best_k == kInvalid) {
        best = err;
        best_k = k;
        std::copy(trial, trial + 6, best_uv);
      }
    }
    const uint32_t o = topology.opposite[3 * f + best_k];
    if (!(best <= options.max_stretch)) {
      const uint32_t g = o / 3;
      unfold(local, scale, best_k, uv + 6 * g + 2 * ((o % 3 + 1) % 3), uv + 6 * g + 2 * (o % 3), true, best_uv);
      ++rigid;
    } else {
      ++unfolded;
    }
    std::copy(best_uv, best_uv + 6, uv + 6 * f);
    placed[f] = 1;
    atlas.patch[f] = atlas.patch[o / 3];
    push_neighbours(f);
  }
  on_seam.assign(nf, 1);  // the seam shortening looks everywhere: patches meet along invisible seams too
  atlas.patch_count = patches;
  stats.patches_before_absorb = patches;
  stats.faces_unfolded = good_faces + unfolded;
  stats.faces_rigid = rigid;
  stats.faces_cut = nf - good_faces;
  if (options.progress && !options.progress(1.f)) return Status::error(ErrorCode::kCancelled, "", "cancelled");
  return Status::ok();
}

}  // namespace tailor::internal
