// Writes the benchmarks' 1.55 M face horse (bench_meshes.h: tests/data/meshes/horse.ply subdivided
// twice) as binary PLY, for benchmarks that run outside this process (scripts/bench_edit_browser.sh),
// or any mesh file subdivided LEVELS times (1-to-4 midpoint: 4^LEVELS times its faces).
// Usage: write_bench_mesh OUT.ply [IN LEVELS]
#include <cstdio>
#include <cstdlib>
#include <string>

#include "bench_meshes.h"

int main(int argc, char** argv) {
  // An option (--help) is not a file name: the usage, not a mesh written under that name.
  if ((argc != 2 && argc != 4) || argv[1][0] == '-') {
    std::fprintf(stderr,
                 "usage: write_bench_mesh OUT.ply [IN LEVELS]\n"
                 "  writes tests/data/meshes/horse.ply subdivided twice (1,551,456 faces), or IN subdivided\n"
                 "  LEVELS times (0..6, each 1-to-4), as a binary PLY\n");
    return 2;
  }
  int levels = 0;
  if (argc == 4) {
    char* end = nullptr;
    const long n = std::strtol(argv[3], &end, 10);
    if (*argv[3] == '\0' || *end != '\0' || n < 0 || n > 6) {
      std::fprintf(stderr, "write_bench_mesh: LEVELS must be a whole number in 0..6, got '%s'\n", argv[3]);
      return 2;
    }
    levels = static_cast<int>(n);
  }
  const tailor::Status s =
      argc == 2 ? write_subdivided_horse_ply(argv[1]) : write_subdivided_ply(argv[1], argv[2], levels);
  if (!s.is_ok()) {
    std::fprintf(stderr, "write_bench_mesh: %s%s%s\n", s.file().c_str(), s.file().empty() ? "" : ": ",
                 s.message().c_str());
    return 1;
  }
  return 0;
}
