// The glTF 2.0 document behind the reader: the container (.glb or .gltf JSON), its buffers (the
// GLB's BIN chunk, data: URIs, files next to a .gltf), buffer views (EXT_meshopt_compression
// decoded on first use) and accessors (any component type, normalized, sparse) read into flat
// arrays. Every index is range-checked, every byte range checked against its buffer, and every
// size checked against the document's budget before anything is allocated.
// Reference: glTF 2.0 specification, sections 3.6 (buffers, accessors), 4.4 (GLB);
// EXT_meshopt_compression's specification.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "io/glb_format.h"
#include "io/readers.h"
#include "tailor/status.h"

namespace tailor::internal {

using Json = nlohmann::json;

//! Largest accessor count read (2^32: every id tailor stores is 32-bit).
inline constexpr uint64_t kMaxAccessorCount = uint64_t{1} << 32;

//! A non-negative integer member, or false when absent or of another type.
bool get_uint(const Json& object, const char* key, uint64_t& out);
//! The element `index` of the array member `key` of `doc`, or null when out of range / not an object.
const Json* get_element(const Json& doc, const char* key, uint64_t index);

//! An accessor's description (what it holds, not its data).
struct AccessorInfo {
  size_t count = 0;
  int components = 0;      //!< 1 (SCALAR) .. 4 (VEC4); matrices are refused
  int component_type = 0;  //!< kGltf*
  bool normalized = false;
};

class GltfDocument {
 public:
  //! Opens `data` (.glb container or JSON text, told apart by the magic). `base_dir` is the
  //! folder of the file, where relative buffer URIs are looked up; empty: no file is ever opened
  //! (a buffer with a file URI is then kUnsupported). `name` is used in error messages.
  Status open(std::span<const char> data, const std::string& name, const std::string& base_dir);

  const Json& json() const { return json_; }
  //! Told the bytes of accessor data decoded so far (every few MB); null: none.
  void set_progress(ReadProgress* progress) { progress_ = progress; }
  const std::string& name() const { return name_; }
  bool is_binary() const { return binary_; }

  //! Charges `bytes` of decoded output against the budget (a multiple of the input's size, so
  //! that a small file cannot ask for gigabytes); kLimit naming `where` when it is exceeded.
  Status charge(size_t bytes, const std::string& where);

  //! The bytes of buffer view `index` (decompressed when it uses EXT_meshopt_compression) and its
  //! byteStride (0 when not given).
  Status view_bytes(uint64_t index, std::span<const unsigned char>& bytes, uint64_t& stride);

  //! The bytes of image `index` when it is given by a URI, for reading its header: a data: URI
  //! decoded, or the first `max_file_bytes` of a file its relative URI names in or below the
  //! .gltf's folder (the same rule as buffers; never with an empty base_dir). `file` tells which.
  //! False when the image has no such URI or it cannot be read (the caller then has no size).
  bool image_uri_bytes(uint64_t index, size_t max_file_bytes, std::string& bytes, bool& file) const;
  //! The path of the file that image `index`'s relative URI names (the rule above), or "" when it
  //! names none.
  std::string image_file(uint64_t index) const;

  //! The description of accessor `index`.
  Status accessor_info(uint64_t index, AccessorInfo& info);
  //! Accessor `index` as floats (#count by info.components; normalized integers mapped to [0, 1]
  //! or [-1, 1], others converted), sparse substitution applied.
  Status read_floats(uint64_t index, std::vector<float>& out, AccessorInfo& info);
  //! Accessor `index` as unsigned integers (indices: SCALAR u8/u16/u32), sparse applied.
  Status read_indices(uint64_t index, std::vector<uint32_t>& out);

  Status parse_error(const std::string& what, const std::string& where = {}) const;
  Status unsupported(const std::string& what, const std::string& where = {}) const;

 private:
  Status load_buffers(std::span<const unsigned char> bin);
  //! The bytes of the file a buffer's relative URI names (read once per distinct file), in owned_.
  Status external_buffer(const std::string& uri, const std::string& where, const std::string*& content);
  Status decode_meshopt(uint64_t index, const Json& extension, std::span<const unsigned char>& bytes);
  template <class T>
  Status read_accessor(uint64_t index, std::vector<T>& out, AccessorInfo& info);

  Json json_;
  std::string name_;
  std::string base_dir_;
  bool binary_ = false;
  size_t budget_ = 0;
  std::vector<std::span<const unsigned char>> buffers_;  // per buffer: its bytes (empty: no data)
  std::vector<std::string> owned_;                       // buffers decoded from data: URIs or read from files
  struct ExternalFile {
    uint64_t device = 0, inode = 0;
    size_t owned = 0;  // its bytes: owned_[owned]
  };
  std::vector<ExternalFile> external_files_;               // the files read so far, by identity
  std::vector<std::vector<unsigned char>> decoded_views_;  // per buffer view: its meshopt-decoded bytes
  std::vector<uint8_t> view_decoded_;                      // per buffer view: 1 once decoded
  ReadProgress* progress_ = nullptr;
  size_t decoded_ = 0;  // bytes of accessor data read
};

}  // namespace tailor::internal

namespace tailor::internal {

//! A primitive compressed with KHR_draco_mesh_compression, decoded: its triangles and the
//! attributes asked for (by glTF name), each #points by components floats (empty when the
//! extension does not carry it). The primitive's accessors' counts are charged against the
//! budget before decoding and must match what the Draco stream holds.
struct DracoPrimitive {
  std::vector<uint32_t> indices;
  std::vector<std::vector<float>> values;  //!< per name asked for
  std::vector<int> components;             //!< per name asked for (0: absent)
};

Status decode_draco_primitive(GltfDocument& doc, const Json& primitive, const Json& extension,
                              const std::vector<std::string>& names, const std::string& where, DracoPrimitive& out);

}  // namespace tailor::internal
