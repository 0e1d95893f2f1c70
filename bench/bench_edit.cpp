// Interactive editing (tailor/edit_session.h): the time of one EditSession::apply against the full
// map_texture it replaces, on the shared nefertiti (100k faces, when the shared data is present)
// and the 1.55 M face subdivided horse (bench_meshes.h), which the default options cut into chunks.
//   Edit/seams/MESH          a brush of ~60 seam faces marked, then unmarked (alternating iterations)
//   Edit/stroke/MESH         a stroke of 10 points added (radius 2% of the mesh), then undone
//   Edit/stroke-settle/MESH  the settle after that stroke (chunked: the chunks it touched mapped
//                            again; whole: the full map)
//   Edit/stroke-whole/MESH   the stroke on the mesh mapped whole (--chunks off): the local update
//                            over the whole mesh, as before the chunked sessions
//   Edit/full/MESH           map_texture of the whole mesh with the same options
// Targets: apply <= ~60 ms at 100k faces; a stroke <= 100 ms at 1.5 M faces (chunked), on the
// project's 2-core machine.
//
// Run: tailor_bench --benchmark_filter=Edit
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bench_meshes.h"
#include "tailor/edit_session.h"
#include "tailor/io.h"
#include "tailor/mapping.h"
#include "tailor/topology.h"

namespace {

struct EditBench {
  tailor::Mesh mesh;
  std::unique_ptr<tailor::EditSession> session;
  std::vector<uint32_t> brush;  // faces around the brush centre, breadth first
  tailor::OrientationStroke stroke;
  std::string error;
};

tailor::MapTextureOptions bench_options(bool whole = false) {
  tailor::MapTextureOptions options;
  (void)tailor::set_map_texture_size(options, 512, 512);
  if (whole) options.chunks.mode = tailor::ChunkMode::kOff;
  return options;
}

// "KEY" or "KEY#whole" (the session maps the mesh whole).
bool whole_key(const std::string& key) { return key.ends_with("#whole"); }

// The mesh, a session on it, a brush of ~60 faces and a stroke at the face in the middle of the
// face order (a deterministic spot well inside the mesh on the shared scans).
EditBench& edit_bench(const std::string& key) {
  static std::unique_ptr<EditBench> cached;
  static std::string cached_key;
  if (cached && cached_key == key) return *cached;
  cached.reset();  // one mesh in memory at a time
  auto b = std::make_unique<EditBench>();
  const std::string file = whole_key(key) ? key.substr(0, key.size() - 6) : key;
  if (file == "horse_x16") {
    b->mesh = subdivided_horse();
  } else if (tailor::Status s = tailor::load_mesh(file, b->mesh); !s) {
    b->error = s.message();
  }
  if (b->error.empty()) {
    const tailor::Topology topology = tailor::build_topology(b->mesh);
    const uint32_t centre = static_cast<uint32_t>(b->mesh.face_count() / 2);
    std::vector<uint8_t> seen(b->mesh.face_count(), 0);
    b->brush.push_back(centre);
    seen[centre] = 1;
    for (size_t i = 0; i < b->brush.size() && b->brush.size() < 60; ++i)
      for (int k = 0; k < 3; ++k) {
        const uint32_t g = tailor::neighbour_face(topology, 3 * b->brush[i] + k);
        if (g != tailor::kInvalid && !seen[g] && b->brush.size() < 60) seen[g] = 1, b->brush.push_back(g);
      }
    // The stroke: through the brush faces' first corners, radius 2% of the bounding box.
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (size_t v = 0; v < b->mesh.vertex_count(); ++v)
      for (int c = 0; c < 3; ++c) {
        lo[c] = std::min(lo[c], b->mesh.positions[3 * v + c]);
        hi[c] = std::max(hi[c], b->mesh.positions[3 * v + c]);
      }
    for (size_t i = 0; i < b->brush.size() && i < 60; i += 6)
      for (int c = 0; c < 3; ++c)
        b->stroke.points.push_back(b->mesh.positions[3 * b->mesh.indices[3 * b->brush[i]] + c]);
    b->stroke.radius = 0.02f * std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
    if (tailor::Status s = tailor::EditSession::open(b->mesh, bench_options(whole_key(key)), b->session); !s)
      b->error = s.message();
  }
  cached = std::move(b);
  cached_key = key;
  return *cached;
}

void BM_EditSeams(benchmark::State& state, const std::string& key) {
  EditBench& b = edit_bench(key);
  if (!b.error.empty()) return state.SkipWithError(b.error.c_str());
  bool add = true;
  uint64_t changed = 0;
  for (auto _ : state) {
    tailor::EditRequest edit;
    (add ? edit.add_seam_faces : edit.remove_seam_faces) = b.brush;
    add = !add;
    tailor::EditResult result;
    const auto start = std::chrono::steady_clock::now();
    const tailor::Status s = b.session->apply(edit, result);
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (!s) return state.SkipWithError(s.message().c_str());
    changed += result.changed_faces;
  }
  state.counters["changed_faces"] = static_cast<double>(changed) / static_cast<double>(state.iterations());
  set_faces_rate(state, b.mesh.face_count());
}

void BM_EditStroke(benchmark::State& state, const std::string& key) {
  EditBench& b = edit_bench(key);
  if (!b.error.empty()) return state.SkipWithError(b.error.c_str());
  uint64_t changed = 0;
  for (auto _ : state) {
    tailor::EditRequest edit;
    edit.strokes.push_back(b.stroke);
    tailor::EditResult result;
    const auto start = std::chrono::steady_clock::now();
    const tailor::Status s = b.session->apply(edit, result);
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (!s) return state.SkipWithError(s.message().c_str());
    changed += result.changed_faces;
    state.PauseTiming();
    (void)b.session->undo(result);  // the next iteration adds the same stroke to the same state
    state.ResumeTiming();
  }
  state.counters["changed_faces"] = static_cast<double>(changed) / static_cast<double>(state.iterations());
  set_faces_rate(state, b.mesh.face_count());
}

// The settle after a stroke: the stroke applied and the settle timed, then undone (untimed).
void BM_EditStrokeSettle(benchmark::State& state, const std::string& key) {
  EditBench& b = edit_bench(key);
  if (!b.error.empty()) return state.SkipWithError(b.error.c_str());
  for (auto _ : state) {
    state.PauseTiming();
    tailor::EditRequest edit;
    edit.strokes.push_back(b.stroke);
    tailor::EditResult result;
    if (tailor::Status s = b.session->apply(edit, result); !s) return state.SkipWithError(s.message().c_str());
    state.ResumeTiming();
    const auto start = std::chrono::steady_clock::now();
    const tailor::Status s = b.session->settle(result);
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (!s) return state.SkipWithError(s.message().c_str());
    state.PauseTiming();
    (void)b.session->undo(result);
    (void)b.session->settle(result);
    state.ResumeTiming();
  }
  set_faces_rate(state, b.mesh.face_count());
}

void BM_EditFull(benchmark::State& state, const std::string& key) {
  EditBench& b = edit_bench(key);
  if (!b.error.empty()) return state.SkipWithError(b.error.c_str());
  const tailor::Topology topology = tailor::build_topology(b.mesh);
  std::vector<uint8_t> seam(b.mesh.face_count(), 0);
  for (const uint32_t f : b.brush) seam[f] = 1;
  tailor::MapTextureOptions options = bench_options();
  options.mapping.seam_faces = seam;
  options.measure = false;
  tailor::TextureMap map;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const tailor::Status s = tailor::map_texture(b.mesh, topology, options, map);
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (!s) return state.SkipWithError(s.message().c_str());
  }
  set_faces_rate(state, b.mesh.face_count());
}

const bool registered = [] {
  std::vector<std::pair<std::string, std::string>> meshes;
  const std::string nefertiti = std::string(TAILOR_SHARED_DATA) + "/meshes/nefertiti.obj";
  if (std::filesystem::exists(nefertiti)) meshes.emplace_back("nefertiti", nefertiti);
  meshes.emplace_back("horse_x16", "horse_x16");
  for (const auto& [name, key] : meshes) {
    benchmark::RegisterBenchmark(("Edit/seams/" + name).c_str(), BM_EditSeams, key)
        ->Unit(benchmark::kMillisecond)
        ->MinWarmUpTime(2.0)
        ->MinTime(0.5)
        ->UseManualTime();
    benchmark::RegisterBenchmark(("Edit/stroke/" + name).c_str(), BM_EditStroke, key)
        ->Unit(benchmark::kMillisecond)
        ->MinWarmUpTime(2.0)
        ->MinTime(0.5)
        ->UseManualTime();
    benchmark::RegisterBenchmark(("Edit/stroke-settle/" + name).c_str(), BM_EditStrokeSettle, key)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.5)
        ->UseManualTime();
    benchmark::RegisterBenchmark(("Edit/full/" + name).c_str(), BM_EditFull, key)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.5)
        ->UseManualTime();
    if (name == "horse_x16")  // last: it maps the mesh whole (seconds) for a session of its own
      benchmark::RegisterBenchmark(("Edit/stroke-whole/" + name).c_str(), BM_EditStroke, key + "#whole")
          ->Unit(benchmark::kMillisecond)
          ->MinWarmUpTime(2.0)
          ->MinTime(0.5)
          ->UseManualTime();
  }
  return true;
}();

}  // namespace
