// The `tailor map IN -o OUT.ply` pipeline with a scalar build of the mapping stage: CMake compiles
// TAILOR_MAPPING_SOURCES (src/mapping/) into this executable with TAILOR_NO_SIMD (src/util/simd.h),
// so its symbols take the place of the library's SIMD ones. tests/simd_test.sh compares its output
// with the tailor binary's byte for byte: the SIMD paths must give the scalar paths' bits.
// Usage: map_scalar IN OUT.ply [--field-following F] [--crack-rings N]
#include <cstdio>
#include <cstdlib>
#include <string>

#include "tailor/export.h"
#include "tailor/io.h"
#include "tailor/mapping.h"
#include "tailor/topology.h"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: map_scalar IN OUT.ply [--field-following F] [--crack-rings N]\n");
    return 2;
  }
  tailor::MapTextureOptions options;
  options.measure = false;
  for (int i = 3; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--field-following")
      options.mapping.field_following = std::strtof(argv[i + 1], nullptr);
    else if (flag == "--crack-rings")
      options.mapping.crack_rings = static_cast<uint32_t>(std::strtoul(argv[i + 1], nullptr, 10));
    else {
      std::fprintf(stderr, "map_scalar: unknown option %s\n", argv[i]);
      return 2;
    }
  }
  tailor::Mesh mesh;
  tailor::Status s = tailor::load_mesh(argv[1], mesh);
  const tailor::Topology topology = tailor::build_topology(mesh);
  tailor::TextureMap map;
  if (s.is_ok()) s = tailor::map_texture(mesh, topology, options, map);
  if (s.is_ok()) s = tailor::export_mesh(argv[2], mesh, map.atlas, {});
  if (!s.is_ok()) {
    std::fprintf(stderr, "map_scalar: %s\n", s.message().c_str());
    return 1;
  }
  return 0;
}
