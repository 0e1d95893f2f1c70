// Benchmark inputs shared by every tailor benchmark: a large real mesh built once per process.
//
// subdivided_horse(): tests/data/meshes/horse.ply (96,966 faces) refined twice by 1-to-4 midpoint
// subdivision = 1,551,456 faces, 775,730 vertices. Deterministic (vertex ids in order of first use
// along the face order), so every run and every benchmark sees the same mesh. Built lazily on
// first call (about a second), then cached; not thread-safe on the first call.
//
// The *_path() functions write that mesh once to a per-process temporary directory (removed at
// exit) and return the file name, for benchmarks of whole-file loading.
// Declared in the global namespace, as the other benchmarks expect.
#pragma once

#include <benchmark/benchmark.h>

#include <string>

#include "tailor/mesh.h"
#include "tailor/status.h"

//! horse.ply subdivided twice (1,551,456 faces). Aborts the benchmark run if horse.ply is missing.
const tailor::Mesh& subdivided_horse();

//! subdivided_horse() as binary little-endian PLY (float x y z; uchar int vertex_indices).
const std::string& subdivided_horse_ply_path();

//! Writes subdivided_horse() as binary PLY to `path` (atomically); for tools outside the benchmarks.
tailor::Status write_subdivided_horse_ply(const std::string& path);

//! Writes the mesh file `input` subdivided `levels` times (each 1-to-4: 4^levels times the faces)
//! as binary PLY to `path` (atomically).
tailor::Status write_subdivided_ply(const std::string& path, const std::string& input, int levels);

//! subdivided_horse() as ascii OBJ (`v x y z` with %.9g, `f a b c`).
const std::string& subdivided_horse_obj_path();

//! Sets the "Mfaces/s" rate counter every benchmark reports: `faces` per iteration. A rate divides
//! by the benchmark's time, which is the calling thread's CPU time unless the benchmark is
//! registered with UseRealTime(): every benchmark of code that may start threads must be (without
//! it, the threaded crack closing's rates came out 10-40 % too high).
inline void set_faces_rate(benchmark::State& state, size_t faces) {
  state.counters["Mfaces/s"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * static_cast<double>(faces) * 1e-6, benchmark::Counter::kIsRate);
}
