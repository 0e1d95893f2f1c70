// Crack closing, the last step of the patches mode: cracks (seams inside one patch) are zipped
// shut vertex by vertex from their tips, each zip relaxing the UVs of the faces around it.
//
// Why: the growth places every face isometrically (zero distortion) and so spends the whole
// curvature of the surface at the front: where two arms of the front meet with a gap wider than
// one face can absorb, it cuts, and the gap grows along the cut as the front goes on. The
// distortion budget (max_stretch) is left unused almost everywhere (Sander L2 ~1.004). Spreading
// the gap over the faces around a crack's tip, as-rigidly-as-possible, closes most of each crack
// within the same per-face bound.
//
// Zips go nearest to the component's seed first, band by band of seed distance, so removing part
// of a mesh changes only zips near or after the first one it touches (stability, as the hop rule);
// bands far enough apart not to share a vertex are zipped on several threads, with the same result
// for any thread count (close_cracks at the end).
//
// This file is the scheduling: the seed distances that order the zips and cut them into bands,
// each band's queue, the phases of bands zipped on several threads, progress and cancelling.
// One zip is crack_closer.h, its relaxation's kernels arap_kernels.h.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

#include "mapping/crack_closer.h"
#include "mapping/face_stretch.h"
#include "mapping/mapping_common.h"
#include "util/huge_pages.h"
#include "util/parallel_chunks.h"

namespace tailor::internal {
namespace {

// Faces per closing worker: below this, starting threads costs more than it saves.
constexpr size_t kFacesPerClosingThread = 10000;

// A zip at a crack edge reads and writes only what belongs to vertices within crack_rings + 1
// edges of the edge's own: the merged vertices' fans (1 edge), one more edge per ring, the faces
// across the last ring (their corners' wedges and UVs), and the crack edges around the merged
// vertices. A band is crack_rings + kZoneSteps wide, so bands three apart stay 2 edges clear.
constexpr uint32_t kZoneSteps = 3;
constexpr uint32_t kBandPhases = 3;

}  // namespace

void CrackCloser::build_shared(size_t threads) {
  const size_t face_count = in_.mesh.face_count();
  build_vertex_corners();
  run_beside(
      threads > 1, [this] { shared_.vertex_distance = vertex_seed_distances(); },
      [&] {
        build_wedges();
        fresh(zero_area_, face_count, uint8_t{0});
        for (size_t f = 0; f < face_count; ++f) zero_area_[f] = is_zero_area_frame(local_ + 6 * f);
        fresh(face_stamp_, face_count, 0u);
        fresh(wedge_stamp_, 3 * face_count, 0u);
        fresh(wedge_local_, 3 * face_count, 0u);
        fresh(shared_.queued, 3 * face_count, uint8_t{0});
        shared_.face_distance = face_seed_distances();
      });
}

std::vector<uint32_t> CrackCloser::face_seed_distances() const {
  const size_t face_count = in_.mesh.face_count();
  std::vector<uint32_t> distance, fifo;
  fresh(distance, face_count, kInvalid);
  reserve_huge(fifo, face_count);
  for (const uint32_t seed : in_.component_seeds) {
    distance[seed] = 0;
    fifo.push_back(seed);
  }
  for (size_t head = 0; head < fifo.size(); ++head) {
    const uint32_t f = fifo[head];
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t o = opposite_[3 * size_t{f} + k];
      if (o == kInvalid || distance[o / 3] != kInvalid) continue;
      distance[o / 3] = distance[f] + 1;
      fifo.push_back(o / 3);
    }
  }
  return distance;
}

std::vector<uint32_t> CrackCloser::vertex_seed_distances() const {
  const size_t vertex_count = in_.mesh.vertex_count();
  std::vector<uint32_t> distance, fifo;
  fresh(distance, vertex_count, kInvalid);
  reserve_huge(fifo, vertex_count);
  auto reach = [&](uint32_t v, uint32_t d) {
    if (distance[v] != kInvalid) return;
    distance[v] = d;
    fifo.push_back(v);
  };
  auto search = [&](size_t head) {
    for (; head < fifo.size(); ++head) {
      const uint32_t v = fifo[head], d = distance[v] + 1;
      for (uint32_t i = vertex_start_[v]; i < vertex_start_[v + 1]; ++i) {
        const uint32_t c = vertex_corners_[i], f = c / 3, k = c - 3 * f;
        reach(indices_[3 * size_t{f} + static_cast<uint32_t>(kNext[k])], d);
        reach(indices_[3 * size_t{f} + static_cast<uint32_t>(kPrev[k])], d);
      }
    }
  };
  for (const uint32_t seed : in_.component_seeds)
    for (size_t k = 0; k < 3; ++k) reach(indices_[3 * size_t{seed} + k], 0);
  search(0);
  for (uint32_t v = 0; v < vertex_count; ++v) {
    if (distance[v] != kInvalid) continue;
    const size_t head = fifo.size();
    reach(v, 0);
    search(head);
  }
  return distance;
}

uint64_t CrackCloser::key(uint32_t e) const {
  const uint32_t d = std::min(shared_.face_distance[e / 3], shared_.face_distance[opposite_[e] / 3]);
  return (uint64_t{d} << 32) | e;
}

uint32_t CrackCloser::band_of(uint32_t e, uint32_t band_steps) const {
  const EdgeCorners c = edge_corners(e);
  return std::min(shared_.vertex_distance[indices_[c.fa]], shared_.vertex_distance[indices_[c.fb]]) / band_steps;
}

void CrackCloser::close_band(std::vector<uint64_t>& heap, uint32_t band, uint32_t band_steps,
                             std::vector<uint64_t>& outbox, const ProgressCallback* report, size_t initial) {
  std::make_heap(heap.begin(), heap.end(), std::greater<>());
  uint8_t* const queued = shared_.queued.data();
  while (!heap.empty()) {
    if (shared_.cancelled.load(std::memory_order_relaxed)) return;
    const uint64_t popped = shared_.popped.fetch_add(1, std::memory_order_relaxed);
    // Every 256 pops (kProgressInterval counts placements; a pop here costs up to two
    // relaxations): the closing is most of the mapping's time, so it reports and can be cancelled.
    if (report && ++own_pops_ % 256 == 0 &&
        !(*report)(std::min(1.f, static_cast<float>(popped) / static_cast<float>(initial + 1)))) {
      shared_.cancelled.store(true, std::memory_order_relaxed);
      return;
    }
    std::pop_heap(heap.begin(), heap.end(), std::greater<>());
    const uint32_t e = static_cast<uint32_t>(heap.back());
    heap.pop_back();
    queued[e] = 0;
    if (!is_crack(e)) continue;
    const int merged = zip(e);
    if (merged == 0) continue;
    zipped_ += static_cast<uint64_t>(merged);
    for (int m = 0; m < merged; ++m) {
      const uint32_t v = merges_[static_cast<size_t>(m)].vertex;
      for (uint32_t i = vertex_start_[v]; i < vertex_start_[v + 1]; ++i) {
        const uint32_t c = vertex_corners_[i], f = c / 3, k = c - 3 * f;
        for (const uint32_t h : {c, 3 * f + static_cast<uint32_t>(kPrev[k])}) {  // f's two edges at v
          const uint32_t o = opposite_[h];
          if (o == kInvalid) continue;
          const uint32_t canonical = std::min(h, o);
          if (queued[canonical] || !is_crack(canonical)) continue;
          queued[canonical] = 1;
          const uint64_t k2 = key(canonical);
          const uint32_t b = band_of(canonical, band_steps);
          if (b == band) {
            heap.push_back(k2);
            std::push_heap(heap.begin(), heap.end(), std::greater<>());
          } else {
            outbox.push_back(k2);
          }
        }
      }
    }
  }
}

// Threads: the crack edges are cut into bands of seed distance crack_rings + kZoneSteps wide. A
// zip reaches only vertices within crack_rings + 1 edges of its own (kZoneSteps), so bands three
// apart never touch the same vertex, face, corner or wedge: the bands 0, 3, 6... are zipped at
// once (each in key order, largest first, each by the next free worker), then 1, 4, 7... and
// 2, 5, 8..., and again while zips queue edges into bands already done. The result depends on the
// bands only, not on which worker zipped which band nor on how many workers there were.
// Stability: where removing part of a mesh lengthens the seed distances (behind the hole), the
// band boundaries move with them and the zips beside a boundary change order. That, not the
// phase order, cost the stability test's bit-identical share 9 points on fertility and the bunny
// (measured before the sweeps were over-relaxed; bands in seed order without phases lost the
// same; bands 2x / 4x wider lost 5 / 2 on the bunny, with less parallelism). Cubes fixed in space
// (coloured modulo 3) kept the bunny's share but, run colour by colour, lost 55 points on spot;
// and any Lipschitz bound in space comes from the longest edge, an outlier on scans (the bunny
// would be one band). docs/mapping.md, section 2.
Status close_cracks(const MappingInput& input, const ProgressCallback& progress, Atlas& atlas, uint64_t& zipped,
                    std::span<const uint8_t> locked) {
  zipped = 0;
  const size_t face_count = input.mesh.face_count();
  CrackShared shared;
  shared.locked = locked.empty() ? nullptr : locked.data();
  const size_t threads = parallel_threads(face_count, input.options.threads, kFacesPerClosingThread);
  std::vector<std::unique_ptr<CrackCloser>> workers;  // one allocation per worker, not per element
  for (size_t t = 0; t < threads; ++t) workers.push_back(std::make_unique<CrackCloser>(input, atlas, shared));
  CrackCloser& first = *workers[0];
  first.build_shared(threads);

  const uint32_t band_steps = std::max<uint32_t>(input.options.crack_rings, kMinRings) + kZoneSteps;
  const uint32_t* opposite = input.topology.opposite.data();
  std::vector<std::vector<uint64_t>> heaps;  // per band: keys (the edge in the low 32 bits)
  auto add_to_band = [&](uint64_t key) {
    const uint32_t band = first.band_of(static_cast<uint32_t>(key), band_steps);
    if (band >= heaps.size()) heaps.resize(band + 1);
    heaps[band].push_back(key);
  };
  size_t initial = 0;
  for (uint32_t e = 0; e < 3 * face_count; ++e) {
    if (!(e < opposite[e] && first.is_crack(e))) continue;  // each crack edge once
    add_to_band(first.key(e));
    shared.queued[e] = 1;
    ++initial;
  }
  std::vector<std::vector<uint64_t>> outboxes(threads);
  for (bool any = true; any;) {
    any = false;
    for (uint32_t parity = 0; parity < kBandPhases; ++parity) {
      std::vector<uint32_t> bands;
      for (uint32_t b = parity; b < heaps.size(); b += kBandPhases)
        if (!heaps[b].empty()) bands.push_back(b);
      if (bands.empty()) continue;
      any = true;
      // Relaxation marks are 32-bit: reset between phases once half are used (a phase would need
      // 2^31 relaxations, ~10^10 faces, to wrap).
      if (shared.stamp.load() > (uint32_t{1} << 31)) {
        std::fill(shared.face_stamp.begin(), shared.face_stamp.end(), 0);
        std::fill(shared.wedge_stamp.begin(), shared.wedge_stamp.end(), 0);
        shared.stamp.store(0);
      }
      // Largest first, each to the next free worker: the phase ends with its largest band.
      std::stable_sort(bands.begin(), bands.end(),
                       [&](uint32_t a, uint32_t b) { return heaps[a].size() > heaps[b].size(); });
      const size_t used = std::min(threads, bands.size());
      std::atomic<size_t> next_band{0}, helpers_done{0};
      std::exception_ptr failure;  // the first exception of a helper (out of memory), rethrown here
      std::mutex failure_mutex;
      auto work = [&](size_t w) {
        try {
          for (size_t i; (i = next_band.fetch_add(1)) < bands.size();)
            workers[w]->close_band(heaps[bands[i]], bands[i], band_steps, outboxes[w],
                                   w == 0 && progress ? &progress : nullptr, initial);
        } catch (...) {
          if (w == 0) throw;
          const std::lock_guard<std::mutex> lock(failure_mutex);
          if (!failure) failure = std::current_exception();
          shared.cancelled.store(true);
        }
        if (w != 0) helpers_done.fetch_add(1);
      };
      std::vector<std::thread> helpers;
      try {
        helpers.reserve(used - 1);
        for (size_t w = 1; w < used; ++w) helpers.emplace_back(work, w);
      } catch (...) {  // no thread to be had: fewer workers, same result
      }
      try {
        work(0);
      } catch (...) {
        shared.cancelled.store(true);
        for (std::thread& h : helpers) h.join();
        throw;
      }
      // The calling thread, out of bands, keeps reporting (and may cancel) until the others finish.
      while (helpers_done.load() < helpers.size()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        if (progress && !shared.cancelled.load() &&
            !progress(std::min(1.f, static_cast<float>(shared.popped.load()) / static_cast<float>(initial + 1))))
          shared.cancelled.store(true);
      }
      for (std::thread& h : helpers) h.join();
      if (failure) std::rethrow_exception(failure);
      if (shared.cancelled.load()) return Status::error(ErrorCode::kCancelled, "", "mapping cancelled");
      // Edges queued into other bands: a heap's pops depend only on its set of (unique) keys.
      for (std::vector<uint64_t>& outbox : outboxes) {
        for (const uint64_t key : outbox) add_to_band(key);
        outbox.clear();
      }
    }
  }
  for (const auto& worker : workers) zipped += worker->zipped();
  if (progress && !progress(1.f)) return Status::error(ErrorCode::kCancelled, "", "mapping cancelled");
  return Status::ok();
}

}  // namespace tailor::internal
