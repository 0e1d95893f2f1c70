// Writes the benchmarks' 1.55 M face horse (bench_meshes.h: tests/data/meshes/horse.ply subdivided
// twice) as binary PLY, for benchmarks that run outside this process (scripts/bench_edit_browser.sh).
// Usage: write_bench_mesh OUT.ply
#include <cstdio>

#include "bench_meshes.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: write_bench_mesh OUT.ply\n");
    return 2;
  }
  const tailor::Status s = write_subdivided_horse_ply(argv[1]);
  if (!s.is_ok()) {
    std::fprintf(stderr, "write_bench_mesh: %s\n", s.message().c_str());
    return 1;
  }
  return 0;
}
