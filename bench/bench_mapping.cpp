// Orientation and mapping throughput (M faces/s) with the quality of the result on the same line,
// on the 1.55 M face subdivided horse (bench_meshes.h) and on every mesh of the shared data set
// (TAILOR_SHARED_DATA/meshes, skipped when absent), in both mapping modes, and the patches mode's
// growth without its crack closing. Wall-clock time: the orientation and the crack closing run on
// threads (the mapping's own time, MappingStats::seconds, without the orientation map_texture
// computes first).
// Targets (docs/mapping.md): mapping >= 10 M faces/s single-threaded; on every shared mesh
// 0 flipped, Sander L2 <= 1.02, Linf <= 3, thesis stretch <= 0.08, no single-face patches.
//
// Run: tailor_bench --benchmark_filter='Orientation|Mapping'
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "bench_meshes.h"
#include "tailor/chunks.h"
#include "tailor/io.h"
#include "tailor/mapping.h"
#include "tailor/metrics.h"
#include "tailor/orientation.h"
#include "tailor/texture_direction.h"
#include "tailor/topology.h"

namespace {

struct Prepared {
  tailor::Mesh mesh;
  tailor::Topology topology;
  bool ok = false;
  std::string error;
};

// Loaded once per process and mesh (the registry owns them; benchmarks run one at a time).
const Prepared& prepared(const std::string& key) {
  static std::map<std::string, std::unique_ptr<Prepared>> cache;
  auto it = cache.find(key);
  if (it != cache.end()) return *it->second;
  auto p = std::make_unique<Prepared>();
  if (key == "horse_x16") {
    p->mesh = subdivided_horse();
  } else {
    const tailor::Status s = tailor::load_mesh(key, p->mesh);
    if (!s.is_ok()) p->error = s.message();
  }
  if (p->error.empty()) p->topology = tailor::build_topology(p->mesh);
  p->ok = p->error.empty();
  return *cache.emplace(key, std::move(p)).first->second;
}

void BM_Orientation(benchmark::State& state, const std::string& key) {
  const Prepared& p = prepared(key);
  if (!p.ok) {
    state.SkipWithError(p.error.c_str());
    return;
  }
  tailor::FaceFrames frames;
  for (auto _ : state) {
    if (!tailor::compute_orientation(p.mesh, p.topology, {}, frames).is_ok()) {
      state.SkipWithError("orientation failed");
      return;
    }
    benchmark::DoNotOptimize(frames.local.data());
  }
  const double faces = static_cast<double>(p.mesh.face_count());
  state.counters["faces"] = faces;
  set_faces_rate(state, p.mesh.face_count());
}

void BM_Mapping(benchmark::State& state, const std::string& key, const tailor::MappingOptions& options,
                tailor::ChunkMode chunks) {
  const Prepared& p = prepared(key);
  if (!p.ok) {
    state.SkipWithError(p.error.c_str());
    return;
  }
  // map_texture without its metrics; timed: the growth, seam shortening and crack closing (the
  // orientation is BM_Orientation's); chunked (ChunkMode::kOn): every chunk's whole pipeline, its
  // orientation included.
  tailor::MapTextureOptions pipeline;
  pipeline.mapping = options;
  pipeline.chunks.mode = chunks;
  pipeline.measure = false;
  tailor::TextureMap map;
  const tailor::Atlas& atlas = map.atlas;
  const tailor::MappingStats& stats = map.stats;
  for (auto _ : state) {
    if (!tailor::map_texture(p.mesh, p.topology, pipeline, map).is_ok()) {
      state.SkipWithError("mapping failed");
      return;
    }
    benchmark::DoNotOptimize(atlas.corner_uv.data());
    state.SetIterationTime(stats.seconds);
  }
  const double faces = static_cast<double>(p.mesh.face_count());
  state.counters["faces"] = faces;
  set_faces_rate(state, p.mesh.face_count());
  tailor::UvMetrics m;
  tailor::MetricsOptions metrics;
  metrics.symmetry = options.symmetry;  // symmetry 4: quarter turns across a seam count as invisible
  if (!tailor::compute_uv_metrics(p.mesh, p.topology, atlas.corner_uv, atlas.patch, metrics, m).is_ok()) {
    state.SkipWithError("metrics failed");
    return;
  }
  state.counters["patches"] = m.patches;
  state.counters["single"] = static_cast<double>(m.single_face_patches);
  state.counters["seam%"] = 100.0 * m.seam_length_ratio;
  state.counters["gap_px"] = m.seam_gap_px;
  state.counters["visible%"] = 100.0 * m.visible_seam_ratio;      // issue 14: seams the texture breaks at
  state.counters["invisible%"] = 100.0 * m.seam_invisible_ratio;  // share of seam length on the lattice
  state.counters["dangling"] = static_cast<double>(m.visible_dangling_ends);
  state.counters["flipped"] = static_cast<double>(m.flipped);
  state.counters["stretch"] = m.stretch;
  state.counters["angle_deg"] = m.distortion_deg;
  state.counters["L2"] = m.l2_stretch;
  state.counters["Linf"] = m.linf_stretch;
  if (options.mode == tailor::MappingMode::kThesis) state.counters["thr_px"] = stats.final_threshold_px;
  state.counters["chunks"] = stats.chunks;
}

// Thread scaling: the whole map_texture (orientation, mapping; no metrics) on horse_x16 with
// state.range(0) threads, and whether its UVs are bit-identical to the 1-thread run's (the
// project's determinism rule; the 1-thread row runs first and keeps its UVs per mode). The
// stages' shares of the last run, from the last progress report of each (orientation, mapping:
// the growth or the grid map and the seam shortening, closing, relaxing), show which of them keep
// the others waiting.
void BM_MappingThreads(benchmark::State& state, const std::string& key, const std::string& mode,
                       tailor::MappingOptions options, tailor::ChunkMode chunks) {
  const Prepared& p = prepared(key);
  if (!p.ok) {
    state.SkipWithError(p.error.c_str());
    return;
  }
  static std::map<std::string, std::vector<float>> one_thread_uv;  // per mode
  options.threads = static_cast<uint32_t>(state.range(0));
  tailor::MapTextureOptions pipeline;
  pipeline.mapping = options;
  pipeline.orientation.threads = options.threads;
  pipeline.chunks.mode = chunks;
  pipeline.measure = false;
  using Clock = std::chrono::steady_clock;
  const std::array<std::string_view, 4> stages = {"orientation", "mapping", "closing", "relaxing"};
  std::array<Clock::time_point, 4> last_report{};
  pipeline.stage_progress = [&](std::string_view stage, float) {
    for (size_t s = 0; s < stages.size(); ++s)
      if (stage == stages[s]) last_report[s] = Clock::now();
    return true;
  };
  tailor::TextureMap map;
  Clock::time_point start, end;
  for (auto _ : state) {
    last_report = {};
    start = Clock::now();
    if (!tailor::map_texture(p.mesh, p.topology, pipeline, map).is_ok()) {
      state.SkipWithError("mapping failed");
      return;
    }
    end = Clock::now();
    benchmark::DoNotOptimize(map.atlas.corner_uv.data());
  }
  // In chunks the stages run inside every chunk, side by side: their thread time summed over the
  // chunks (MappingStats), whose sum over the wall time is how busy the threads were.
  const tailor::MappingStats& stats = map.stats;
  if (stats.chunks > 0) {
    const double wall = std::chrono::duration<double>(end - start).count();
    const double busy =
        stats.orientation_seconds + stats.growth_seconds + stats.closing_seconds + stats.relaxing_seconds;
    state.counters["orientation_thread_s"] = stats.orientation_seconds;
    state.counters["growth_thread_s"] = stats.growth_seconds;
    state.counters["closing_thread_s"] = stats.closing_seconds;
    state.counters["relaxing_thread_s"] = stats.relaxing_seconds;
    state.counters["busy_threads"] = wall > 0 ? busy / wall : 0;
  }
  Clock::time_point previous = start;
  for (size_t s = 0; s < stages.size() && stats.chunks == 0; ++s) {
    const Clock::time_point until = s + 1 == stages.size() ? end : last_report[s];
    if (until == Clock::time_point{}) continue;  // a stage this mode has not (closing with symmetry 4 has)
    state.counters[std::string(stages[s]) + "_s"] = std::chrono::duration<double>(until - previous).count();
    previous = until;
  }
  const std::string run = mode + (chunks == tailor::ChunkMode::kOff ? "" : "/chunked");
  if (options.threads == 1) one_thread_uv[run] = map.atlas.corner_uv;
  auto reference = one_thread_uv.find(run);
  if (reference == one_thread_uv.end()) {  // a row of more threads ran first (random interleaving): map it once
    tailor::MapTextureOptions single = pipeline;
    single.mapping.threads = single.orientation.threads = 1;
    single.stage_progress = nullptr;
    tailor::TextureMap one;
    if (!tailor::map_texture(p.mesh, p.topology, single, one).is_ok()) {
      state.SkipWithError("mapping with one thread failed");
      return;
    }
    reference = one_thread_uv.emplace(run, std::move(one.atlas.corner_uv)).first;
  }
  state.counters["threads"] = options.threads;
  state.counters["same_bits"] = reference->second == map.atlas.corner_uv;
  set_faces_rate(state, p.mesh.face_count());
}

// The chunk rule alone (plan_chunks: edge lengths and their median, each face's cell, the cells cut
// into octants) on horse_x16 with state.range(0) threads, the automatic cell (range(1) = 1) or the
// cell it gives (0): serial work at the start of every chunked map.
void BM_ChunkPlan(benchmark::State& state) {
  const Prepared& p = prepared("horse_x16");
  if (!p.ok) {
    state.SkipWithError(p.error.c_str());
    return;
  }
  tailor::ChunkOptions options;
  options.mode = tailor::ChunkMode::kOn;
  tailor::ChunkPlan plan;
  if (state.range(1) == 0) {
    if (!tailor::plan_chunks(p.mesh, options, plan).is_ok()) return state.SkipWithError("plan failed");
    options.cell_exponent = plan.cell_exponent;
  }
  for (auto _ : state) {
    if (!tailor::plan_chunks(p.mesh, options, plan, static_cast<uint32_t>(state.range(0))).is_ok())
      return state.SkipWithError("plan failed");
    benchmark::DoNotOptimize(plan.faces.data());
  }
  state.counters["chunks"] = static_cast<double>(plan.chunk_count());
  set_faces_rate(state, p.mesh.face_count());
}
BENCHMARK(BM_ChunkPlan)
    ->Name("ChunkPlan/horse_x16")
    ->ArgNames({"threads", "auto_cell"})
    ->ArgsProduct({{1, 2, 4}, {1, 0}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Registers one orientation and nine mapping benchmarks per mesh at static initialisation:
// patches mode with a texture that has a direction, or none (default options, and ten times the
// texture scale), with a texture without direction (`tailor map`'s default for gravel, grass:
// adapt_mapping_to_texture, rigid unfolding with 32 crack rings; both scales), the integer-grid
// map for a 4-fold symmetric 512 px tile (`--symmetry 4`, experimental; both scales), the growth
// alone (no crack closing), thesis mode.
[[maybe_unused]] const bool registered = [] {
  std::vector<std::pair<std::string, std::string>> meshes = {{"horse_x16", "horse_x16"}};
  const std::filesystem::path dir = std::filesystem::path(TAILOR_SHARED_DATA) / "meshes";
  std::error_code ec;
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".ply" || ext == ".obj" || ext == ".off" || ext == ".stl") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  for (const auto& f : files) meshes.emplace_back(f.stem().string(), f.string());
  tailor::MappingOptions patches, patches_x10, growth, undirected, thesis;
  patches_x10.scale = 10 * patches.scale;  // `--scale 8000`: the texture repeats ~15 times across a mesh
  growth.close_cracks = false;
  growth.relax_iterations = 0;
  undirected.field_following = 0.f;  // what adapt_mapping_to_texture sets for a texture without direction
  undirected.crack_rings = tailor::kUndirectedCrackRings;
  tailor::MappingOptions undirected_x10 = undirected;
  undirected_x10.scale = patches_x10.scale;
  tailor::MappingOptions fourfold;
  fourfold.symmetry = 4;  // texture_period_px: the default 512 px
  tailor::MappingOptions fourfold_x10 = fourfold;
  fourfold_x10.scale = patches_x10.scale;
  thesis.mode = tailor::MappingMode::kThesis;
  for (const auto& [name, key] : meshes) {
    benchmark::RegisterBenchmark(("Orientation/" + name).c_str(), BM_Orientation, key)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.2)
        ->UseRealTime();
    benchmark::RegisterBenchmark(("Mapping/patches/" + name).c_str(), BM_Mapping, key, patches, tailor::ChunkMode::kOff)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.2)
        ->UseManualTime();
    benchmark::RegisterBenchmark(("Mapping/patches-x10/" + name).c_str(), BM_Mapping, key, patches_x10,
                                 tailor::ChunkMode::kOff)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.2)
        ->UseManualTime();
    benchmark::RegisterBenchmark(("Mapping/symmetry4/" + name).c_str(), BM_Mapping, key, fourfold,
                                 tailor::ChunkMode::kOff)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.2)
        ->UseManualTime();
    benchmark::RegisterBenchmark(("Mapping/symmetry4-x10/" + name).c_str(), BM_Mapping, key, fourfold_x10,
                                 tailor::ChunkMode::kOff)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.2)
        ->UseManualTime();
    benchmark::RegisterBenchmark(("Mapping/growth/" + name).c_str(), BM_Mapping, key, growth, tailor::ChunkMode::kOff)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.2)
        ->UseManualTime();
    benchmark::RegisterBenchmark(("Mapping/undirected/" + name).c_str(), BM_Mapping, key, undirected,
                                 tailor::ChunkMode::kOff)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.2)
        ->UseManualTime();
    benchmark::RegisterBenchmark(("Mapping/undirected-x10/" + name).c_str(), BM_Mapping, key, undirected_x10,
                                 tailor::ChunkMode::kOff)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.2)
        ->UseManualTime();
    benchmark::RegisterBenchmark(("Mapping/thesis/" + name).c_str(), BM_Mapping, key, thesis, tailor::ChunkMode::kOff)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.2)
        ->UseManualTime();
    // The same, cut into chunks by the chunk rule (its automatic cell; the mesh spans up to a few
    // cells): what the chunk borders cost beside the one-chunk rows above.
    for (const auto& [mode, options] :
         {std::pair{std::string("patches"), patches}, std::pair{std::string("patches-x10"), patches_x10},
          std::pair{std::string("undirected"), undirected}, std::pair{std::string("undirected-x10"), undirected_x10}})
      benchmark::RegisterBenchmark(("Mapping/" + mode + "-chunked/" + name).c_str(), BM_Mapping, key, options,
                                   tailor::ChunkMode::kOn)
          ->Unit(benchmark::kMillisecond)
          ->MinTime(0.2)
          ->UseManualTime();
  }
  // Thread scaling on the large mesh: the texture-aware default for an isotropic tile (undirected),
  // field following, and the 4-fold map, 1 to 16 threads; mapped whole and by chunks (the default
  // from 131072 faces on).
  for (const auto& [mode, options] :
       {std::pair{std::string("undirected"), undirected}, std::pair{std::string("patches"), patches},
        std::pair{std::string("symmetry4"), fourfold}})
    for (const tailor::ChunkMode chunks : {tailor::ChunkMode::kOff, tailor::ChunkMode::kOn})
      benchmark::RegisterBenchmark(
          ("MappingThreads/" + mode + (chunks == tailor::ChunkMode::kOn ? "-chunked" : "") + "/horse_x16").c_str(),
          BM_MappingThreads, "horse_x16", mode, options, chunks)
          ->ArgName("threads")
          ->Arg(1)
          ->Arg(2)
          ->Arg(4)
          ->Arg(8)
          ->Arg(16)
          ->Unit(benchmark::kMillisecond)
          ->MinTime(0.2)
          ->UseRealTime();
  return true;
}();

}  // namespace
