// libFuzzer target for the OBJ reader: read_mesh on arbitrary bytes must return a Status and, when
// it succeeds, a valid mesh; never crash, hang or touch memory outside the input (ASan/UBSan).
// Built by scripts/fuzz.sh (clang, -DTAILOR_FUZZ=ON -DTAILOR_SANITIZE=ON).
#include <cstddef>
#include <cstdint>

#include "mesh_invariants.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz_read_mesh(data, size, tailor::MeshFormat::kObj);
}
