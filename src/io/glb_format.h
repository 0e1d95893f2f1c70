// The glTF enumerations, the binary container's (.glb) framing and the rule for the files a glTF
// names, shared by the reader (gltf_document.cpp), the writers (write_glb.cpp,
// write_glb_compressed.cpp) and `tailor view`.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <string>

namespace tailor::internal {

// glTF enumerations (spec section 5).
inline constexpr int kGltfByte = 5120, kGltfUnsignedByte = 5121, kGltfShort = 5122, kGltfUnsignedShort = 5123,
                     kGltfUnsignedInt = 5125, kGltfFloat = 5126;
inline constexpr int kGltfArrayBuffer = 34962, kGltfElementArrayBuffer = 34963;
inline constexpr int kGltfTriangles = 4;

// A .glb: a 12-byte header (magic, version 2, total length), then chunks (length, type, bytes).
inline constexpr uint32_t kGlbMagic = 0x46546C67;   // "glTF"
inline constexpr uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
inline constexpr uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

//! Appends `value` as 4 little-endian bytes.
inline void append_u32(std::string& out, uint32_t value) {
  static_assert(std::endian::native == std::endian::little, "glb writer assumes a little-endian host");
  char bytes[4];
  std::memcpy(bytes, &value, 4);
  out.append(bytes, 4);
}

//! The 4 little-endian bytes at `p` (append_u32's reverse).
inline uint32_t load_u32(const unsigned char* p) {
  return uint32_t{p[0]} | uint32_t{p[1]} << 8 | uint32_t{p[2]} << 16 | uint32_t{p[3]} << 24;
}

//! A relative URI's path with %XX decoded, or false when it names anything but a file in or below
//! the glTF's folder (a scheme, an absolute path, a '..' segment, a backslash, a NUL): the files
//! the reader opens beside a .gltf, and those `tailor view` serves beside a .glb.
bool relative_file_uri(const std::string& uri, std::string& path);

//! Pads `out` with `fill` to a multiple of 4 bytes (glb chunks and buffer views are 4-aligned).
inline void pad_to_4(std::string& out, char fill = '\0') {
  while (out.size() % 4 != 0) out.push_back(fill);
}

}  // namespace tailor::internal
