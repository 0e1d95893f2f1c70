// Loading, adjacency and export benchmarks on the subdivided horse (1,551,456 faces, bench_meshes.h).
// Targets: binary PLY >= 50 M faces/s for the whole load_mesh (read + parse + finalize_mesh); the
// .glb export <= 100 ms (its share of the end-to-end 3 M faces/s, bench_pipeline.cpp).
// Rates use wall-clock time (UseRealTime): finalize_mesh runs part of its work on a second thread.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "bench_meshes.h"
#include "tailor/export.h"
#include "tailor/io.h"
#include "tailor/mapping.h"
#include "tailor/topology.h"

namespace {

void load_file(benchmark::State& state, const std::string& path) {
  const double bytes = static_cast<double>(std::filesystem::file_size(path));
  size_t faces = 0;
  for (auto _ : state) {
    tailor::Mesh mesh;
    const tailor::Status s = tailor::load_mesh(path, mesh);
    if (!s.is_ok()) {
      state.SkipWithError(s.message().c_str());
      return;
    }
    faces = mesh.face_count();
    benchmark::DoNotOptimize(mesh.indices.data());
  }
  const double n = static_cast<double>(state.iterations());
  set_faces_rate(state, faces);
  state.counters["MB/s"] = benchmark::Counter(n * bytes * 1e-6, benchmark::Counter::kIsRate);
}

void BM_LoadBinaryPly(benchmark::State& state) { load_file(state, subdivided_horse_ply_path()); }
BENCHMARK(BM_LoadBinaryPly)->Unit(benchmark::kMillisecond)->MinTime(1.0)->UseRealTime();

void BM_LoadAsciiObj(benchmark::State& state) { load_file(state, subdivided_horse_obj_path()); }
BENCHMARK(BM_LoadAsciiObj)->Unit(benchmark::kMillisecond)->MinTime(1.0)->UseRealTime();

void BM_Topology(benchmark::State& state) {
  const tailor::Mesh& mesh = subdivided_horse();
  const auto threads = static_cast<uint32_t>(state.range(0));
  for (auto _ : state) {
    tailor::Topology t = tailor::build_topology(mesh, {}, threads);
    benchmark::DoNotOptimize(t.opposite.data());
  }
  set_faces_rate(state, mesh.face_count());
}
BENCHMARK(BM_Topology)->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->MinTime(1.0)->UseRealTime();

// The atlas of `tailor map --no-crack-closing` (seams on about 5% of the edges), mapped once.
const tailor::Atlas& subdivided_horse_atlas() {
  static const tailor::Atlas atlas = [] {
    const tailor::Mesh& mesh = subdivided_horse();
    const tailor::Topology topology = tailor::build_topology(mesh);
    tailor::MapTextureOptions options;
    options.mapping.close_cracks = false;
    options.measure = false;
    tailor::TextureMap result;
    if (!tailor::map_texture(mesh, topology, options, result).is_ok()) result = {};
    return result.atlas;
  }();
  return atlas;
}

// export_mesh to .glb with normals and no texture: validation, vertex split, normals, the write.
// The previous output is removed untimed: renaming over an existing 45 MB file costs ext4 another
// ~30 ms (it flushes the new file first, auto_da_alloc), which is the file system's, not ours.
void BM_ExportGlb(benchmark::State& state) {
  const tailor::Mesh& mesh = subdivided_horse();
  const tailor::Atlas& atlas = subdivided_horse_atlas();
  const std::string output = (std::filesystem::temp_directory_path() / "tailor_bench_export.glb").string();
  for (auto _ : state) {
    state.PauseTiming();
    std::remove(output.c_str());
    state.ResumeTiming();
    const tailor::Status s = tailor::export_mesh(output, mesh, atlas, {});
    if (!s.is_ok()) {
      state.SkipWithError(s.message().c_str());
      return;
    }
  }
  std::remove(output.c_str());
  set_faces_rate(state, mesh.face_count());
}
BENCHMARK(BM_ExportGlb)->Unit(benchmark::kMillisecond)->MinTime(1.0)->UseRealTime();

// Compressed glTF next to PLY (issue 18): export_mesh of the same mapping to .ply and to .glb with
// each compression, the file's size as a counter ("MB"), then load_mesh of each file.
std::string bench_output(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("tailor_bench_" + name)).string();
}

void export_as(benchmark::State& state, const std::string& name, tailor::MeshCompression compression) {
  const tailor::Mesh& mesh = subdivided_horse();
  const tailor::Atlas& atlas = subdivided_horse_atlas();
  const std::string output = bench_output(name);
  tailor::ExportOptions options;
  options.compression = compression;
  for (auto _ : state) {
    state.PauseTiming();
    std::remove(output.c_str());
    state.ResumeTiming();
    const tailor::Status s = tailor::export_mesh(output, mesh, atlas, options);
    if (!s.is_ok()) {
      state.SkipWithError(s.message().c_str());
      return;
    }
  }
  state.counters["MB"] = static_cast<double>(std::filesystem::file_size(output)) * 1e-6;
  set_faces_rate(state, mesh.face_count());
}
BENCHMARK_CAPTURE(export_as, ply, std::string("out.ply"), tailor::MeshCompression::kNone)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();
BENCHMARK_CAPTURE(export_as, glb, std::string("out.glb"), tailor::MeshCompression::kNone)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();
BENCHMARK_CAPTURE(export_as, glb_quantize, std::string("quantize.glb"), tailor::MeshCompression::kQuantize)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();
BENCHMARK_CAPTURE(export_as, glb_meshopt, std::string("meshopt.glb"), tailor::MeshCompression::kMeshopt)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();
BENCHMARK_CAPTURE(export_as, glb_draco, std::string("draco.glb"), tailor::MeshCompression::kDraco)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();

// Loads what export_as wrote (registered after it, so the files exist).
void load_output(benchmark::State& state, const std::string& name) {
  const std::string path = bench_output(name);
  if (!std::filesystem::exists(path)) {
    state.SkipWithError("run the export_as benchmarks first (same filter)");
    return;
  }
  load_file(state, path);
}
BENCHMARK_CAPTURE(load_output, ply, std::string("out.ply"))->Unit(benchmark::kMillisecond)->MinTime(1.0)->UseRealTime();
BENCHMARK_CAPTURE(load_output, glb, std::string("out.glb"))->Unit(benchmark::kMillisecond)->MinTime(1.0)->UseRealTime();
BENCHMARK_CAPTURE(load_output, glb_quantize, std::string("quantize.glb"))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();
BENCHMARK_CAPTURE(load_output, glb_meshopt, std::string("meshopt.glb"))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();
BENCHMARK_CAPTURE(load_output, glb_draco, std::string("draco.glb"))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();

}  // namespace

// The one main() of tailor_bench (CMake links benchmark::benchmark, not benchmark_main).
BENCHMARK_MAIN();
