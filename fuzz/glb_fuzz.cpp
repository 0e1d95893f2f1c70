// libFuzzer target: the glTF binary reader (read_glb_memory) on arbitrary bytes, texture decoding
// included. It must return a Status for every input: no crash, no out-of-bounds read, no hang.
#include <cstddef>
#include <cstdint>
#include <span>

#include "tailor/gltf.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  tailor::Mesh mesh;
  tailor::Image image;
  (void)tailor::read_glb_memory(std::span<const char>(reinterpret_cast<const char*>(data), size), "fuzz.glb", mesh,
                                &image);
  return 0;
}
