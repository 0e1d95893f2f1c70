// Binary glTF 2.0 (.glb) reader: triangle primitives, TEXCOORD_0 and the base colour texture.
//
// The container and its JSON are parsed here with nlohmann::json rather than with tinygltf:
// tinygltf 2.7 hands an image's buffer view to the image loader without checking it against the
// buffer's size (an out-of-bounds read on a crafted file) and fetches external URIs from disk.
// Here every index is range-checked and every accessor is checked against its buffer view and
// the BIN chunk before a byte is read; only the BIN chunk is ever used (no URI is opened).
// Reference: glTF 2.0 specification, sections 3.6 (buffers, accessors), 3.7 (meshes), 4.4 (GLB).
#include <stb/stb_image.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstring>
#include <new>
#include <nlohmann/json.hpp>

#include "io/readers.h"
#include "tailor/export.h"
#include "tailor/gltf.h"
#include "tailor/io.h"
#include "util/atomic_file.h"

namespace tailor {
namespace {

using Json = nlohmann::json;

constexpr uint32_t kGlbMagic = 0x46546C67;   // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;   // "BIN\0"
constexpr int kByte = 5120, kUnsignedByte = 5121, kShort = 5122, kUnsignedShort = 5123, kUnsignedInt = 5125,
              kFloat = 5126;
constexpr uint64_t kTriangles = 4;

uint32_t load_u32(const unsigned char* p) {
  return uint32_t{p[0]} | uint32_t{p[1]} << 8 | uint32_t{p[2]} << 16 | uint32_t{p[3]} << 24;
}

Status parse_error(const std::string& name, const std::string& what, const std::string& where = {}) {
  return Status::error(ErrorCode::kParse, name, what, where);
}

// A non-negative integer member, or false when absent or of another type.
bool get_uint(const Json& object, const char* key, uint64_t& out) {
  if (!object.is_object()) return false;
  const auto it = object.find(key);
  if (it == object.end() || !it->is_number_integer() ||
      (it->is_number_integer() && !it->is_number_unsigned() && it->get<int64_t>() < 0))
    return false;
  out = it->get<uint64_t>();
  return true;
}

// The element `index` of the top-level array `key`, or null when out of range / not an object.
const Json* get_element(const Json& doc, const char* key, uint64_t index) {
  const auto it = doc.find(key);
  if (it == doc.end() || !it->is_array() || index >= it->size()) return nullptr;
  const Json& element = (*it)[static_cast<size_t>(index)];
  return element.is_object() ? &element : nullptr;
}

struct Glb {
  std::span<const unsigned char> json;
  std::span<const unsigned char> bin;  // empty when there is no BIN chunk
};

Status split_glb(std::span<const char> data, const std::string& name, Glb& glb) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  if (data.size() < 20 || load_u32(bytes) != kGlbMagic) return parse_error(name, "not a binary glTF file (bad magic)");
  if (load_u32(bytes + 4) != 2)
    return Status::error(ErrorCode::kUnsupported, name,
                         "unsupported glTF container version " + std::to_string(load_u32(bytes + 4)));
  const size_t total = load_u32(bytes + 8);
  if (total > data.size() || total < 20) return parse_error(name, "glb length field does not match the file", "byte 8");
  const size_t json_length = load_u32(bytes + 12);
  if (load_u32(bytes + 16) != kChunkJson) return parse_error(name, "first chunk is not JSON", "byte 16");
  if (json_length > total - 20) return parse_error(name, "JSON chunk runs past the end of the file", "byte 12");
  glb.json = {bytes + 20, json_length};
  size_t offset = 20 + json_length;
  offset += (4 - offset % 4) % 4;  // chunks are 4-byte aligned (tolerate a missing pad at the end)
  glb.bin = {};
  if (offset + 8 <= total) {
    const size_t bin_length = load_u32(bytes + offset);
    if (load_u32(bytes + offset + 4) == kChunkBin) {
      if (bin_length > total - offset - 8)
        return parse_error(name, "BIN chunk runs past the end of the file", "byte " + std::to_string(offset));
      glb.bin = {bytes + offset + 8, bin_length};
    }
  }
  return Status::ok();
}

// The bytes of buffer view `index`, checked against the BIN chunk. Only buffer 0 without a URI
// (the GLB-stored buffer) is supported.
Status buffer_view_bytes(const Json& doc, const Glb& glb, uint64_t index, const std::string& name,
                         std::span<const unsigned char>& bytes, uint64_t& stride) {
  const std::string where = "bufferView " + std::to_string(index);
  const Json* view = get_element(doc, "bufferViews", index);
  if (!view) return parse_error(name, "missing buffer view", where);
  uint64_t buffer = 0, offset = 0, length = 0;
  if (!get_uint(*view, "buffer", buffer) || !get_uint(*view, "byteLength", length))
    return parse_error(name, "buffer view without buffer or byteLength", where);
  if (view->contains("byteOffset") && !get_uint(*view, "byteOffset", offset))
    return parse_error(name, "bad byteOffset", where);
  stride = 0;
  if (view->contains("byteStride") && !get_uint(*view, "byteStride", stride))
    return parse_error(name, "bad byteStride", where);
  const Json* buf = get_element(doc, "buffers", buffer);
  if (!buf) return parse_error(name, "missing buffer", where);
  if (buffer != 0 || buf->contains("uri"))
    return Status::error(ErrorCode::kUnsupported, name, "only the embedded BIN buffer is supported (no URIs)", where);
  if (offset > glb.bin.size() || length > glb.bin.size() - offset)
    return parse_error(name, "buffer view runs past the end of the BIN chunk", where);
  bytes = glb.bin.subspan(static_cast<size_t>(offset), static_cast<size_t>(length));
  return Status::ok();
}

struct AccessorView {
  const unsigned char* data = nullptr;
  size_t stride = 0;
  size_t count = 0;
  int component_type = 0;
  int components = 0;
  bool normalized = false;
};

int component_size(int type) {
  switch (type) {
    case kByte:
    case kUnsignedByte: return 1;
    case kShort:
    case kUnsignedShort: return 2;
    case kUnsignedInt:
    case kFloat: return 4;
    default: return 0;
  }
}

int component_count(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4" || type == "MAT2") return 4;
  if (type == "MAT3") return 9;
  if (type == "MAT4") return 16;
  return 0;
}

Status accessor_view(const Json& doc, const Glb& glb, uint64_t index, const std::string& name, AccessorView& out) {
  const std::string where = "accessor " + std::to_string(index);
  const Json* accessor = get_element(doc, "accessors", index);
  if (!accessor) return parse_error(name, "missing accessor", where);
  if (accessor->contains("sparse"))
    return Status::error(ErrorCode::kUnsupported, name, "sparse accessors are not supported", where);
  uint64_t view_index = 0, offset = 0, count = 0, component_type = 0;
  if (!get_uint(*accessor, "bufferView", view_index))
    return Status::error(ErrorCode::kUnsupported, name, "accessor without buffer view", where);
  if (!get_uint(*accessor, "count", count) || !get_uint(*accessor, "componentType", component_type))
    return parse_error(name, "accessor without count or componentType", where);
  if (accessor->contains("byteOffset") && !get_uint(*accessor, "byteOffset", offset))
    return parse_error(name, "bad accessor byteOffset", where);
  const auto type_it = accessor->find("type");
  if (type_it == accessor->end() || !type_it->is_string()) return parse_error(name, "accessor without type", where);
  const int components = component_count(type_it->get<std::string>());
  const int size = component_type <= INT_MAX ? component_size(static_cast<int>(component_type)) : 0;
  if (components == 0 || size == 0) return parse_error(name, "bad accessor type or componentType", where);
  const auto normalized_it = accessor->find("normalized");
  out.normalized = normalized_it != accessor->end() && normalized_it->is_boolean() && normalized_it->get<bool>();

  std::span<const unsigned char> bytes;
  uint64_t stride = 0;
  TAILOR_RETURN_IF_ERROR(buffer_view_bytes(doc, glb, view_index, name, bytes, stride));
  const uint64_t element = uint64_t(size) * uint64_t(components);
  if (stride == 0) stride = element;
  if (stride < element || stride > 252) return parse_error(name, "bad byteStride", where);
  if (count > 0) {
    // offset + stride * (count - 1) + element <= view length, without overflow.
    if (offset > bytes.size() || element > bytes.size() - offset ||
        count - 1 > (bytes.size() - offset - element) / stride)
      return parse_error(name, "accessor runs past the end of its buffer view", where);
  }
  out.data = bytes.data() + offset;
  out.stride = static_cast<size_t>(stride);
  out.count = static_cast<size_t>(count);
  out.component_type = static_cast<int>(component_type);
  out.components = components;
  return Status::ok();
}

// Component c of element i as a float (normalized integers scaled to [0, 1] / [-1, 1]).
float read_float(const AccessorView& a, size_t i, int c) {
  const unsigned char* p = a.data + i * a.stride + size_t(c) * size_t(component_size(a.component_type));
  switch (a.component_type) {
    case kFloat: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case kUnsignedByte: return a.normalized ? p[0] / 255.0f : p[0];
    case kUnsignedShort: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return a.normalized ? v / 65535.0f : v;
    }
    case kByte: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return a.normalized ? std::max(v / 127.0f, -1.0f) : v;
    }
    case kShort: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return a.normalized ? std::max(v / 32767.0f, -1.0f) : v;
    }
    default: return 0;
  }
}

uint32_t read_index(const AccessorView& a, size_t i) {
  const unsigned char* p = a.data + i * a.stride;
  switch (a.component_type) {
    case kUnsignedByte: return p[0];
    case kUnsignedShort: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    default: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

// The base colour image of the first textured material used by a triangle primitive: its bytes.
void find_texture(const Json& doc, const Glb& glb, uint64_t material, std::span<const unsigned char>& bytes) {
  bytes = {};
  const Json* m = get_element(doc, "materials", material);
  if (!m) return;
  const auto pbr = m->find("pbrMetallicRoughness");
  if (pbr == m->end() || !pbr->is_object()) return;
  const auto base = pbr->find("baseColorTexture");
  if (base == pbr->end()) return;
  uint64_t texture = 0, source = 0, view = 0, stride = 0;
  if (!get_uint(*base, "index", texture)) return;
  const Json* t = get_element(doc, "textures", texture);
  if (!t || !get_uint(*t, "source", source)) return;
  const Json* image = get_element(doc, "images", source);
  if (!image || !get_uint(*image, "bufferView", view)) return;  // URIs are never opened
  std::span<const unsigned char> view_bytes;
  if (!buffer_view_bytes(doc, glb, view, "", view_bytes, stride).is_ok()) return;
  bytes = view_bytes;
}

Status decode_texture(std::span<const unsigned char> bytes, const std::string& name, Image& image) {
  image = Image{};
  if (bytes.size() > size_t{INT_MAX})
    return Status::error(ErrorCode::kInvalidImage, name, "embedded texture too large");
  const int length = static_cast<int>(bytes.size());
  int width = 0, height = 0, channels = 0;
  if (!stbi_info_from_memory(bytes.data(), length, &width, &height, &channels))
    return Status::error(ErrorCode::kInvalidImage, name, "embedded texture cannot be decoded");
  if (Status s = internal::check_image_header(bytes, width, height, ImageLoadOptions{}, name); !s)
    return Status::error(ErrorCode::kInvalidImage, name, "embedded texture: " + s.what(), s.where());
  unsigned char* pixels = stbi_load_from_memory(bytes.data(), length, &width, &height, &channels, 0);
  if (!pixels) return Status::error(ErrorCode::kInvalidImage, name, "embedded texture cannot be decoded");
  image.width = width;
  image.height = height;
  image.channels = channels;
  image.pixels.assign(pixels, pixels + size_t(width) * size_t(height) * size_t(channels));
  stbi_image_free(pixels);
  return Status::ok();
}

// Parses the glb into mesh (not finalized); the base colour texture bytes go to `texture_bytes`.
Status parse_glb(std::span<const char> data, const std::string& name, Mesh& mesh, LoadReport& report,
                 std::span<const unsigned char>* texture_bytes) {
  report.format = "glTF binary";
  Glb glb;
  TAILOR_RETURN_IF_ERROR(split_glb(data, name, glb));
  const Json doc = Json::parse(glb.json.begin(), glb.json.end(), nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object()) return parse_error(name, "JSON chunk is not a valid JSON object");
  const auto meshes = doc.find("meshes");
  if (meshes == doc.end() || !meshes->is_array())
    return Status::error(ErrorCode::kUnsupported, name, "no mesh in the file");

  // Output size is bounded by a multiple of the input, so repeated references to one large
  // accessor cannot blow up memory.
  const size_t budget_floats = 16 * data.size() + (size_t{1} << 20);
  size_t triangle_primitives = 0, with_uv = 0;
  bool texture_found = false;
  for (size_t mi = 0; mi < meshes->size(); ++mi) {
    const Json& m = (*meshes)[mi];
    const auto primitives = m.is_object() ? m.find("primitives") : m.end();
    if (!m.is_object() || primitives == m.end() || !primitives->is_array()) continue;
    for (size_t pi = 0; pi < primitives->size(); ++pi) {
      const Json& prim = (*primitives)[pi];
      const std::string where = "mesh " + std::to_string(mi) + " primitive " + std::to_string(pi);
      if (!prim.is_object()) return parse_error(name, "primitive is not an object", where);
      uint64_t mode = kTriangles;
      if (prim.contains("mode") && !get_uint(prim, "mode", mode)) return parse_error(name, "bad primitive mode", where);
      if (mode != kTriangles) continue;  // points, lines, strips and fans are skipped
      const auto attributes = prim.find("attributes");
      uint64_t position_index = 0;
      if (attributes == prim.end() || !get_uint(*attributes, "POSITION", position_index))
        return parse_error(name, "triangle primitive without POSITION", where);
      AccessorView positions;
      TAILOR_RETURN_IF_ERROR(accessor_view(doc, glb, position_index, name, positions));
      if (positions.component_type != kFloat || positions.components != 3)
        return Status::error(ErrorCode::kUnsupported, name, "POSITION must be float VEC3", where);
      AccessorView uvs;
      uint64_t uv_index = 0;
      const bool has_uv = get_uint(*attributes, "TEXCOORD_0", uv_index);
      if (has_uv) {
        TAILOR_RETURN_IF_ERROR(accessor_view(doc, glb, uv_index, name, uvs));
        const bool ok_type =
            uvs.component_type == kFloat ||
            ((uvs.component_type == kUnsignedByte || uvs.component_type == kUnsignedShort) && uvs.normalized);
        if (!ok_type || uvs.components != 2)
          return Status::error(ErrorCode::kUnsupported, name, "TEXCOORD_0 must be float or normalized VEC2", where);
        if (uvs.count != positions.count) return parse_error(name, "TEXCOORD_0 and POSITION counts differ", where);
      }
      AccessorView indices;
      uint64_t indices_index = 0;
      const bool indexed = get_uint(prim, "indices", indices_index);
      if (indexed) {
        TAILOR_RETURN_IF_ERROR(accessor_view(doc, glb, indices_index, name, indices));
        const int t = indices.component_type;
        if ((t != kUnsignedByte && t != kUnsignedShort && t != kUnsignedInt) || indices.components != 1)
          return parse_error(name, "indices must be unsigned integer scalars", where);
      }
      const size_t corner_count = indexed ? indices.count : positions.count;
      if (corner_count % 3 != 0) return parse_error(name, "triangle index count is not a multiple of 3", where);

      const size_t base = mesh.vertex_count();
      if (base + positions.count > kMaxVertices || mesh.face_count() + corner_count / 3 > kMaxFaces)
        return Status::error(ErrorCode::kLimit, name, "too many vertices or faces", where);
      if (mesh.positions.size() + 3 * positions.count + 3 * (mesh.indices.size() + corner_count) > budget_floats)
        return Status::error(ErrorCode::kLimit, name, "accessors referenced too often for the file size", where);
      const size_t first_corner = mesh.indices.size();
      mesh.positions.resize(mesh.positions.size() + 3 * positions.count);
      for (size_t i = 0; i < positions.count; ++i)
        for (int c = 0; c < 3; ++c) mesh.positions[3 * (base + i) + size_t(c)] = read_float(positions, i, c);
      mesh.indices.resize(first_corner + corner_count);
      for (size_t i = 0; i < corner_count; ++i) {
        const size_t local = indexed ? read_index(indices, i) : i;
        if (local >= positions.count)
          return Status::error(ErrorCode::kInvalidMesh, name, "index out of range",
                               where + " index " + std::to_string(i));
        mesh.indices[first_corner + i] = static_cast<uint32_t>(base + local);
      }
      // UVs per corner, OBJ convention up to a whole repeat (t = -v_gltf, see export.h).
      mesh.corner_uvs.resize(2 * mesh.indices.size(), 0.0f);
      if (has_uv) {
        ++with_uv;
        for (size_t i = 0; i < corner_count; ++i) {
          const size_t local = mesh.indices[first_corner + i] - base;
          mesh.corner_uvs[2 * (first_corner + i)] = read_float(uvs, local, 0);
          mesh.corner_uvs[2 * (first_corner + i) + 1] = -read_float(uvs, local, 1);
        }
      }
      ++triangle_primitives;
      report.source_faces += corner_count / 3;
      uint64_t material = 0;
      if (texture_bytes && !texture_found && get_uint(prim, "material", material)) {
        find_texture(doc, glb, material, *texture_bytes);
        texture_found = !texture_bytes->empty();
      }
    }
  }
  if (triangle_primitives == 0)
    return Status::error(ErrorCode::kUnsupported, name, "no triangle primitive in the file");
  // All or nothing: UVs are only meaningful when every primitive has them.
  if (with_uv != triangle_primitives) mesh.corner_uvs.clear();
  // glTF splits vertices on UV seams; weld them so that seams are edges between faces again.
  report.welded_vertices = weld_identical_positions(mesh);
  return Status::ok();
}

}  // namespace

namespace internal {

Status read_glb(std::span<const char> data, const std::string& name, Mesh& mesh, LoadReport& report) {
  return parse_glb(data, name, mesh, report, nullptr);
}

}  // namespace internal

Status read_glb_memory(std::span<const char> data, const std::string& name, Mesh& mesh, Image* texture,
                       LoadReport* report) {
  mesh = Mesh{};
  if (texture) *texture = Image{};
  LoadReport local;
  LoadReport& r = report ? *report : local;
  r = LoadReport{};
  r.file_bytes = data.size();
  Status s;
  try {
    std::span<const unsigned char> texture_bytes;
    s = parse_glb(data, name, mesh, r, &texture_bytes);
    if (s.is_ok()) s = finalize_mesh(name, mesh, r);
    int width = 0, height = 0, channels = 0;  // the texture's size from its header only
    if (s.is_ok() && !texture_bytes.empty() && texture_bytes.size() <= size_t{INT_MAX} &&
        stbi_info_from_memory(texture_bytes.data(), static_cast<int>(texture_bytes.size()), &width, &height,
                              &channels) != 0 &&
        width > 0 && height > 0) {
      r.texture_width = width;
      r.texture_height = height;
    }
    if (s.is_ok() && texture && !texture_bytes.empty()) s = decode_texture(texture_bytes, name, *texture);
  } catch (const std::bad_alloc&) {
    s = Status::error(ErrorCode::kLimit, name, "not enough memory to load the mesh");
  } catch (...) {
    s = Status::error(ErrorCode::kParse, name, "unexpected failure while parsing");
  }
  if (!s.is_ok()) {
    mesh = Mesh{};
    if (texture) *texture = Image{};
    return s.with_file(name);
  }
  return s;
}

Status read_glb_file(const std::string& path, Mesh& mesh, Image* texture, LoadReport* report) {
  const auto start = std::chrono::steady_clock::now();
  mesh = Mesh{};
  std::string bytes;
  TAILOR_RETURN_IF_ERROR(internal::read_file(path, bytes));
  LoadReport local;
  LoadReport& r = report ? *report : local;
  const Status s = read_glb_memory(bytes, path, mesh, texture, &r);
  r.load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return s;
}

}  // namespace tailor
