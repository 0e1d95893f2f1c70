// upsample_texture IN SIZE OUT.png: resamples a texture to SIZE x SIZE (bicubic, OpenCV) for the
// tiling size benchmark (scripts/bench_tile_sizes.sh): the shared photos are 128-512 px, the
// benchmark wants 2048 and 4096 px materials.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "tailor/image.h"
#include "tailor/image_ops.h"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: upsample_texture IN SIZE OUT.png\n");
    return 2;
  }
  const int size = std::atoi(argv[2]);
  tailor::Image in, out;
  tailor::Status s = tailor::load_image(argv[1], in);
  if (s.is_ok()) s = tailor::resize_image(in, size, size, out);
  if (s.is_ok()) s = tailor::write_png(argv[3], out);
  if (!s.is_ok()) {
    std::fprintf(stderr, "upsample_texture: %s: %s\n", argv[1], s.message().c_str());
    return 1;
  }
  return 0;
}
