// Loading and adjacency benchmarks on the subdivided horse (1,551,456 faces, bench_meshes.h).
// Targets: binary PLY >= 50 M faces/s for the whole load_mesh (read + parse + finalize_mesh).
// Rates use wall-clock time (UseRealTime): finalize_mesh runs part of its work on a second thread.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "bench_meshes.h"
#include "tailor/io.h"
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
  for (auto _ : state) {
    tailor::Topology t = tailor::build_topology(mesh);
    benchmark::DoNotOptimize(t.opposite.data());
  }
  set_faces_rate(state, mesh.face_count());
}
BENCHMARK(BM_Topology)->Unit(benchmark::kMillisecond)->MinTime(1.0)->UseRealTime();

}  // namespace

// The one main() of tailor_bench (CMake links benchmark::benchmark, not benchmark_main).
BENCHMARK_MAIN();
