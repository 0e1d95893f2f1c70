// End to end: binary PLY -> topology -> orientation -> mapping -> .glb, on the 1.55 M face mesh,
// the path a user runs with `tailor map big.ply -o big.glb`. Target: >= 3 M faces/s on 2 cores.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <filesystem>

#include "bench_meshes.h"
#include "tailor/export.h"
#include "tailor/io.h"
#include "tailor/mapping.h"
#include "tailor/topology.h"

namespace {

// close_cracks: the default; without it, the growth alone (`tailor map --no-crack-closing`).
void BM_EndToEndPlyToGlb(benchmark::State& state, bool close_cracks) {
  tailor::MapTextureOptions options;
  options.mapping.close_cracks = close_cracks;
  options.measure = false;
  const std::string& input = subdivided_horse_ply_path();
  const std::string output = (std::filesystem::temp_directory_path() / "tailor_bench_pipeline.glb").string();
  size_t faces = 0;
  for (auto _ : state) {
    tailor::Mesh mesh;
    if (!tailor::load_mesh(input, mesh).is_ok()) {
      state.SkipWithError("load failed");
      return;
    }
    const tailor::Topology topology = tailor::build_topology(mesh);
    tailor::TextureMap map;
    if (!tailor::map_texture(mesh, topology, options, map).is_ok() ||
        !tailor::export_mesh(output, mesh, map.atlas, {}).is_ok()) {
      state.SkipWithError("pipeline failed");
      return;
    }
    faces = mesh.face_count();
  }
  std::remove(output.c_str());
  state.counters["faces"] = static_cast<double>(faces);
  set_faces_rate(state, faces);
}
BENCHMARK_CAPTURE(BM_EndToEndPlyToGlb, default, true)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();
BENCHMARK_CAPTURE(BM_EndToEndPlyToGlb, no_crack_closing, false)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();

}  // namespace
