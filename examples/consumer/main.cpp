// Texture-maps a mesh with tailor's C++ library and writes a .glb: the `tailor map` pipeline in a
// few calls. Build it against an installed tailor with CMakeLists.txt here, or with pkg-config:
//   g++ -std=c++20 main.cpp $(pkg-config --cflags --libs --static tailor) -o consumer
// Usage: consumer IN.ply|obj|off|stl|glb OUT.glb [TEXTURE.png]
#include <cstdio>

#include "tailor/tailor.h"  // the whole API; or only io.h topology.h mapping.h export.h

// Every call that can fail returns a tailor::Status; message() says what and where.
static int fail(const tailor::Status& status) {
  std::fprintf(stderr, "consumer: %s\n", status.message().c_str());
  return 1;
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s IN OUT.glb [TEXTURE.png]   (tailor %s)\n", argv[0], TAILOR_VERSION_STRING);
    return 2;
  }
  tailor::Mesh mesh;  // positions and triangles as flat arrays
  if (tailor::Status s = tailor::load_mesh(argv[1], mesh); !s) return fail(s);
  const tailor::Topology topology = tailor::build_topology(mesh);  // which faces share an edge

  // The texture, if any, first: its size is the UVs' pixel unit, and one without a direction
  // (gravel, grass) is mapped with rigid unfolding, the fewest seams (as `tailor map` does).
  tailor::ExportOptions output;  // the texture to embed and its size (pixels per texture repeat)
  tailor::MapTextureOptions options;
  if (argc > 3) {
    tailor::Image texture;
    if (tailor::Status s = tailor::load_image(argv[3], texture); !s) return fail(s);
    output = {.texture_path = argv[3], .texture_width = texture.width, .texture_height = texture.height};
    tailor::adapt_mapping_to_texture(texture, options.mapping);
  }

  // The pipeline: orientation field, growth, seam shortening, crack closing, relaxation and metrics,
  // with the default options of every stage otherwise (as `tailor map` uses them).
  tailor::TextureMap map;  // per-face frames, the atlas (a UV per face corner, in texture pixels,
                           // and a patch per face), what each stage did, and the quality metrics
  if (tailor::Status s = tailor::map_texture(mesh, topology, options, map); !s) return fail(s);
  const tailor::Atlas& atlas = map.atlas;

  if (tailor::Status s = tailor::export_mesh(argv[2], mesh, atlas, output); !s) return fail(s);
  std::printf("%s: %zu faces in %u patches\n", argv[2], mesh.face_count(), atlas.patch_count);
  return 0;
}
