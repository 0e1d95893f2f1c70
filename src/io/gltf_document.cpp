// The glTF document: container, buffers, buffer views (meshopt), accessors (sparse). See gltf_document.h.
#include "io/gltf_document.h"

#include <meshoptimizer.h>
#include <sys/stat.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <filesystem>
#include <type_traits>

#include "util/atomic_file.h"
#include "util/bounded_json.h"
#include "util/text_scan.h"

namespace tailor::internal {
namespace {

int component_size(int type) {
  switch (type) {
    case kGltfByte:
    case kGltfUnsignedByte: return 1;
    case kGltfShort:
    case kGltfUnsignedShort: return 2;
    case kGltfUnsignedInt:
    case kGltfFloat: return 4;
    default: return 0;
  }
}

int component_count(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4") return 4;
  return 0;
}

// Component at p as a float (normalized integers scaled to [0, 1] / [-1, 1], as the spec says).
float component_float(const unsigned char* p, int type, bool normalized) {
  switch (type) {
    case kGltfFloat: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case kGltfUnsignedByte: return normalized ? p[0] / 255.0f : p[0];
    case kGltfUnsignedShort: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0f : v;
    }
    case kGltfByte: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0f, -1.0f) : v;
    }
    case kGltfShort: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0f, -1.0f) : v;
    }
    case kGltfUnsignedInt: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return static_cast<float>(v);
    }
    default: return 0;
  }
}

uint32_t component_uint(const unsigned char* p, int type) {
  switch (type) {
    case kGltfUnsignedByte: return p[0];
    case kGltfUnsignedShort: {
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

template <class T>
T convert(const unsigned char* p, int type, bool normalized) {
  if constexpr (std::is_same_v<T, float>)
    return component_float(p, type, normalized);
  else
    return component_uint(p, type);
}

int base64_value(unsigned char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+' || c == '-') return 62;
  if (c == '/' || c == '_') return 63;
  return -1;
}

// Decodes standard (or URL-safe) base64, padding optional; false on any other character.
bool decode_base64(std::string_view text, std::string& out) {
  while (!text.empty() && text.back() == '=') text.remove_suffix(1);
  out.clear();
  out.reserve(text.size() / 4 * 3 + 3);
  uint32_t bits = 0;
  int held = 0;
  for (const char ch : text) {
    const int v = base64_value(static_cast<unsigned char>(ch));
    if (v < 0) return false;
    bits = (bits << 6) | static_cast<uint32_t>(v);
    held += 6;
    if (held >= 8) {
      held -= 8;
      out.push_back(static_cast<char>((bits >> held) & 0xff));
    }
  }
  return true;
}

}  // namespace

// A relative URI's path with %XX decoded, or false when it names anything but a file in or below
// the .gltf's folder (a scheme, an absolute path, a '..' segment, a backslash, a NUL).
bool relative_file_uri(const std::string& uri, std::string& path) {
  path.clear();
  for (size_t i = 0; i < uri.size(); ++i) {
    char c = uri[i];
    if (c == '%') {
      if (i + 2 >= uri.size()) return false;
      const auto hex = [](char h) {
        return h >= '0' && h <= '9'   ? h - '0'
               : h >= 'a' && h <= 'f' ? h - 'a' + 10
               : h >= 'A' && h <= 'F' ? h - 'A' + 10
                                      : -1;
      };
      const int hi = hex(uri[i + 1]), lo = hex(uri[i + 2]);
      if (hi < 0 || lo < 0) return false;
      c = static_cast<char>(hi * 16 + lo);
      i += 2;
    } else if (c == ':' && path.find('/') == std::string::npos) {
      return false;  // a scheme (http:, file:, C:)
    }
    if (c == '\\' || c == '\0') return false;
    path.push_back(c);
  }
  if (path.empty() || path.front() == '/') return false;
  for (const auto& part : std::filesystem::path(path))
    if (part == "..") return false;
  return true;
}

bool get_uint(const Json& object, const char* key, uint64_t& out) {
  if (!object.is_object()) return false;
  const auto it = object.find(key);
  if (it == object.end() || !it->is_number_integer() || (!it->is_number_unsigned() && it->get<int64_t>() < 0))
    return false;
  out = it->get<uint64_t>();
  return true;
}

const Json* get_element(const Json& doc, const char* key, uint64_t index) {
  if (!doc.is_object()) return nullptr;
  const auto it = doc.find(key);
  if (it == doc.end() || !it->is_array() || index >= it->size()) return nullptr;
  const Json& element = (*it)[static_cast<size_t>(index)];
  return element.is_object() ? &element : nullptr;
}

Status GltfDocument::parse_error(const std::string& what, const std::string& where) const {
  return Status::error(ErrorCode::kParse, name_, what, where);
}

Status GltfDocument::unsupported(const std::string& what, const std::string& where) const {
  return Status::error(ErrorCode::kUnsupported, name_, what, where);
}

Status GltfDocument::charge(size_t bytes, const std::string& where) {
  if (bytes > budget_)
    return Status::error(ErrorCode::kLimit, name_, "the file asks for more decoded data than its size allows", where);
  budget_ -= bytes;
  return Status::ok();
}

Status GltfDocument::open(std::span<const char> data, const std::string& name, const std::string& base_dir) {
  name_ = name;
  base_dir_ = base_dir;
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  std::span<const unsigned char> json_text, bin;
  binary_ = data.size() >= 4 && load_u32(bytes) == kGlbMagic;
  if (binary_) {
    if (data.size() < 20) return parse_error("not a binary glTF file (shorter than its header)");
    if (load_u32(bytes + 4) != 2)
      return unsupported("unsupported glTF container version " + std::to_string(load_u32(bytes + 4)));
    const size_t total = load_u32(bytes + 8);
    if (total > data.size() || total < 20) return parse_error("glb length field does not match the file", "byte 8");
    const size_t json_length = load_u32(bytes + 12);
    if (load_u32(bytes + 16) != kChunkJson) return parse_error("first chunk is not JSON", "byte 16");
    if (json_length > total - 20) return parse_error("JSON chunk runs past the end of the file", "byte 12");
    json_text = {bytes + 20, json_length};
    size_t offset = 20 + json_length;
    offset += (4 - offset % 4) % 4;  // chunks are 4-byte aligned (tolerate a missing pad at the end)
    if (offset + 8 <= total) {
      const size_t bin_length = load_u32(bytes + offset);
      if (load_u32(bytes + offset + 4) == kChunkBin) {
        if (bin_length > total - offset - 8)
          return parse_error("BIN chunk runs past the end of the file", "byte " + std::to_string(offset));
        bin = {bytes + offset + 8, bin_length};
      }
    }
  } else {
    json_text = {bytes, data.size()};
  }
  const std::string_view json_chars(reinterpret_cast<const char*>(json_text.data()), json_text.size());
  if (internal::parse_json_bounded(json_chars, json_) == internal::JsonParse::kTooDeep)
    return parse_error(internal::json_problem(internal::JsonParse::kTooDeep));
  if (json_.is_discarded()) {
    const size_t at = internal::json_error_byte(json_chars);
    return parse_error(binary_ ? "JSON chunk is not valid JSON" : "not a glTF file (not valid JSON)",
                       at == SIZE_MAX ? "" : "byte " + std::to_string(at + (binary_ ? 20 : 0)));
  }
  if (!json_.is_object())
    return parse_error(binary_ ? "JSON chunk is not a valid JSON object" : "not a glTF file (not a JSON object)");
  const auto asset = json_.find("asset");
  if (asset != json_.end() && asset->is_object()) {
    const auto version = asset->find("version");
    if (version != asset->end() && version->is_string() && !version->get<std::string>().starts_with("2."))
      return unsupported("unsupported glTF version " + quote_input(version->get<std::string>()));
  }
  // Output is bounded by a multiple of the input (each external buffer file added once, as it is read), so
  // repeated references to one large accessor or a meshopt stream of zeros cannot exhaust memory.
  budget_ = 64 * data.size() + (size_t{64} << 20);
  return load_buffers(bin);
}

bool GltfDocument::image_uri_bytes(uint64_t index, size_t max_file_bytes, std::string& bytes, bool& file) const {
  bytes.clear();
  file = false;
  const Json* image = get_element(json_, "images", index);
  if (!image) return false;
  const auto uri_it = image->find("uri");
  if (uri_it == image->end() || !uri_it->is_string()) return false;
  const std::string& uri = uri_it->get_ref<const std::string&>();
  if (uri.starts_with("data:")) {
    const size_t comma = uri.find(',');
    return comma != std::string::npos && comma >= 7 && uri.compare(comma - 7, 7, ";base64") == 0 &&
           decode_base64(std::string_view(uri).substr(comma + 1), bytes);
  }
  const std::string path = image_file(index);
  if (path.empty()) return false;
  file = true;
  return read_file_head(path, max_file_bytes, bytes).is_ok();
}

std::string GltfDocument::image_file(uint64_t index) const {
  const Json* image = get_element(json_, "images", index);
  if (!image) return {};
  const auto uri_it = image->find("uri");
  std::string relative;
  if (uri_it == image->end() || !uri_it->is_string() || base_dir_.empty() ||
      !relative_file_uri(uri_it->get_ref<const std::string&>(), relative))
    return {};
  return (std::filesystem::path(base_dir_) / relative).string();
}

Status GltfDocument::external_buffer(const std::string& uri, const std::string& where, const std::string*& content) {
  std::string relative;
  if (!relative_file_uri(uri, relative))
    return unsupported("buffer URI " + quote_input(uri) + " is not a file next to the .gltf", where);
  if (base_dir_.empty())
    return unsupported("external buffer " + quote_input(uri) + " needs the file's path (read from memory)", where);
  const std::string path = (std::filesystem::path(base_dir_) / relative).string();
  // The same file under any name (repeated, "./x.bin", a link) is read once and its bytes shared:
  // a .gltf listing one large .bin a thousand times would otherwise hold a thousand copies.
  struct stat st;
  const bool known = ::stat(path.c_str(), &st) == 0;
  if (known)
    for (const ExternalFile& f : external_files_)
      if (f.device == st.st_dev && f.inode == st.st_ino) {
        content = &owned_[f.owned];
        return Status::ok();
      }
  std::string& bytes = owned_.emplace_back();
  if (Status s = read_file(path, bytes); !s)
    return Status::error(s.code(), name_, "buffer " + quote_input(uri) + ": " + s.what(), where);
  // The file is input as the .gltf is, so it widens the budget as the .gltf's own bytes do, once;
  // its bytes, held in memory, are charged against it like any decoded data.
  budget_ += 64 * bytes.size();
  TAILOR_RETURN_IF_ERROR(charge(bytes.size(), where));
  if (known) external_files_.push_back({st.st_dev, st.st_ino, owned_.size() - 1});
  content = &bytes;
  return Status::ok();
}

Status GltfDocument::load_buffers(std::span<const unsigned char> bin) {
  const auto buffers = json_.find("buffers");
  if (buffers == json_.end()) return Status::ok();
  if (!buffers->is_array()) return parse_error("'buffers' is not an array");
  buffers_.assign(buffers->size(), {});
  owned_.reserve(buffers->size());  // spans point into these strings: no reallocation
  for (size_t i = 0; i < buffers->size(); ++i) {
    const std::string where = "buffer " + std::to_string(i);
    const Json& buffer = (*buffers)[i];
    uint64_t length = 0;
    if (!get_uint(buffer, "byteLength", length)) return parse_error("buffer without byteLength", where);
    const auto uri_it = buffer.find("uri");
    if (uri_it == buffer.end()) {
      // The GLB's own buffer; any other buffer without a URI has no data (EXT_meshopt_compression's
      // fallback buffers): reading from it is an error at the view that does.
      if (binary_ && i == 0) {
        if (length > bin.size()) return parse_error("buffer 0 is longer than the BIN chunk", where);
        buffers_[i] = bin.first(static_cast<size_t>(length));
      }
      continue;
    }
    if (!uri_it->is_string()) return parse_error("buffer uri is not a string", where);
    const std::string& uri = uri_it->get_ref<const std::string&>();
    const std::string* held = nullptr;
    if (uri.starts_with("data:")) {
      std::string& content = owned_.emplace_back();
      const size_t comma = uri.find(',');
      if (comma == std::string::npos || comma < 12 || uri.compare(comma - 7, 7, ";base64") != 0)
        return unsupported("data URI is not base64", where);
      if (!decode_base64(std::string_view(uri).substr(comma + 1), content))
        return parse_error("data URI is not valid base64", where);
      TAILOR_RETURN_IF_ERROR(charge(content.size(), where));
      held = &content;
    } else {
      TAILOR_RETURN_IF_ERROR(external_buffer(uri, where, held));
    }
    const std::string& content = *held;
    if (length > content.size())
      return parse_error(
          "buffer holds " + std::to_string(content.size()) + " bytes, byteLength says " + std::to_string(length),
          where);
    buffers_[i] = {reinterpret_cast<const unsigned char*>(content.data()), static_cast<size_t>(length)};
  }
  return Status::ok();
}

Status GltfDocument::decode_meshopt(uint64_t index, const Json& extension, std::span<const unsigned char>& bytes) {
  const std::string where = "bufferView " + std::to_string(index) + " (EXT_meshopt_compression)";
  if (view_decoded_.empty()) {
    const size_t views = json_["bufferViews"].size();
    view_decoded_.assign(views, 0);
    decoded_views_.resize(views);
  }
  std::vector<unsigned char>& decoded = decoded_views_[static_cast<size_t>(index)];
  if (view_decoded_[static_cast<size_t>(index)]) {
    bytes = decoded;
    return Status::ok();
  }
  uint64_t buffer = 0, offset = 0, length = 0, stride = 0, count = 0;
  if (!get_uint(extension, "buffer", buffer) || !get_uint(extension, "byteLength", length) ||
      !get_uint(extension, "byteStride", stride) || !get_uint(extension, "count", count))
    return parse_error("missing buffer, byteLength, byteStride or count", where);
  if (extension.contains("byteOffset") && !get_uint(extension, "byteOffset", offset))
    return parse_error("bad byteOffset", where);
  if (buffer >= buffers_.size()) return parse_error("missing buffer", where);
  const std::span<const unsigned char> source = buffers_[static_cast<size_t>(buffer)];
  if (offset > source.size() || length > source.size() - offset)
    return parse_error("compressed data runs past the end of its buffer", where);
  const auto mode_it = extension.find("mode");
  const auto filter_it = extension.find("filter");
  if (mode_it == extension.end() || !mode_it->is_string()) return parse_error("missing mode", where);
  const std::string mode = mode_it->get<std::string>();
  const std::string filter =
      filter_it != extension.end() && filter_it->is_string() ? filter_it->get<std::string>() : "NONE";
  const bool attributes = mode == "ATTRIBUTES";
  if (!attributes && mode != "TRIANGLES" && mode != "INDICES")
    return unsupported("unknown mode " + quote_input(mode), where);
  if (attributes ? (stride == 0 || stride > 256 || stride % 4 != 0) : (stride != 2 && stride != 4))
    return parse_error("bad byteStride " + std::to_string(stride), where);
  if (mode == "TRIANGLES" && count % 3 != 0) return parse_error("triangle count is not a multiple of 3", where);
  if (count > SIZE_MAX / 256) return Status::error(ErrorCode::kLimit, name_, "count too large", where);
  const size_t size = static_cast<size_t>(count * stride);
  TAILOR_RETURN_IF_ERROR(charge(size, where));
  decoded.assign(size, 0);
  const unsigned char* src = source.data() + offset;
  const size_t n = static_cast<size_t>(count), s = static_cast<size_t>(stride), len = static_cast<size_t>(length);
  const int failed = attributes            ? meshopt_decodeVertexBuffer(decoded.data(), n, s, src, len)
                     : mode == "TRIANGLES" ? meshopt_decodeIndexBuffer(decoded.data(), n, s, src, len)
                                           : meshopt_decodeIndexSequence(decoded.data(), n, s, src, len);
  if (failed != 0)
    return parse_error("compressed data cannot be decoded (meshopt error " + std::to_string(failed) + ")", where);
  if (filter == "OCTAHEDRAL" && attributes && (s == 4 || s == 8))
    meshopt_decodeFilterOct(decoded.data(), n, s);
  else if (filter == "QUATERNION" && attributes && s == 8)
    meshopt_decodeFilterQuat(decoded.data(), n, s);
  else if (filter == "EXPONENTIAL" && attributes)
    meshopt_decodeFilterExp(decoded.data(), n, s);
  else if (filter != "NONE")
    return parse_error(
        "filter " + quote_input(filter) + " does not fit mode " + mode + " and stride " + std::to_string(s), where);
  view_decoded_[static_cast<size_t>(index)] = 1;
  bytes = decoded;
  return Status::ok();
}

Status GltfDocument::view_bytes(uint64_t index, std::span<const unsigned char>& bytes, uint64_t& stride) {
  const std::string where = "bufferView " + std::to_string(index);
  const Json* view = get_element(json_, "bufferViews", index);
  if (!view) return parse_error("missing buffer view", where);
  stride = 0;
  if (view->contains("byteStride") && !get_uint(*view, "byteStride", stride))
    return parse_error("bad byteStride", where);
  const auto extensions = view->find("extensions");
  if (extensions != view->end() && extensions->is_object()) {
    const auto meshopt = extensions->find("EXT_meshopt_compression");
    if (meshopt != extensions->end() && meshopt->is_object()) return decode_meshopt(index, *meshopt, bytes);
  }
  uint64_t buffer = 0, offset = 0, length = 0;
  if (!get_uint(*view, "buffer", buffer) || !get_uint(*view, "byteLength", length))
    return parse_error("buffer view without buffer or byteLength", where);
  if (view->contains("byteOffset") && !get_uint(*view, "byteOffset", offset))
    return parse_error("bad byteOffset", where);
  if (buffer >= buffers_.size()) return parse_error("missing buffer " + std::to_string(buffer), where);
  const std::span<const unsigned char> data = buffers_[static_cast<size_t>(buffer)];
  if (data.empty() && length > 0) return parse_error("buffer " + std::to_string(buffer) + " holds no data", where);
  if (offset > data.size() || length > data.size() - offset)
    return parse_error("buffer view runs past the end of its buffer", where);
  bytes = data.subspan(static_cast<size_t>(offset), static_cast<size_t>(length));
  return Status::ok();
}

Status GltfDocument::accessor_info(uint64_t index, AccessorInfo& info) {
  const std::string where = "accessor " + std::to_string(index);
  const Json* accessor = get_element(json_, "accessors", index);
  if (!accessor) return parse_error("missing accessor", where);
  uint64_t count = 0, component_type = 0;
  if (!get_uint(*accessor, "count", count) || !get_uint(*accessor, "componentType", component_type))
    return parse_error("accessor without count or componentType", where);
  const auto type_it = accessor->find("type");
  if (type_it == accessor->end() || !type_it->is_string()) return parse_error("accessor without type", where);
  info.components = component_count(type_it->get<std::string>());
  info.component_type = component_type <= INT_MAX ? static_cast<int>(component_type) : 0;
  if (info.components == 0 || component_size(info.component_type) == 0)
    return parse_error("bad accessor type or componentType", where);
  if (count > kMaxAccessorCount) return Status::error(ErrorCode::kLimit, name_, "accessor count too large", where);
  info.count = static_cast<size_t>(count);
  const auto normalized_it = accessor->find("normalized");
  info.normalized = normalized_it != accessor->end() && normalized_it->is_boolean() && normalized_it->get<bool>();
  return Status::ok();
}

template <class T>
Status GltfDocument::read_accessor(uint64_t index, std::vector<T>& out, AccessorInfo& info) {
  const std::string where = "accessor " + std::to_string(index);
  TAILOR_RETURN_IF_ERROR(accessor_info(index, info));
  const Json& accessor = *get_element(json_, "accessors", index);
  const size_t values = info.count * size_t(info.components);
  const size_t size = size_t(component_size(info.component_type));
  const size_t element = size * size_t(info.components);
  // The bytes are checked first (a count that lies is a parse error), then the output is charged.
  const unsigned char* base = nullptr;
  uint64_t view_index = 0, stride = 0;
  if (get_uint(accessor, "bufferView", view_index)) {
    uint64_t offset = 0;
    if (accessor.contains("byteOffset") && !get_uint(accessor, "byteOffset", offset))
      return parse_error("bad accessor byteOffset", where);
    std::span<const unsigned char> bytes;
    TAILOR_RETURN_IF_ERROR(view_bytes(view_index, bytes, stride));
    if (stride == 0) stride = element;
    if (stride < element || stride > 256) return parse_error("bad byteStride", where);
    // offset + stride * (count - 1) + element <= view length, without overflow.
    if (info.count > 0 && (offset > bytes.size() || element > bytes.size() - offset ||
                           info.count - 1 > (bytes.size() - offset - element) / stride))
      return parse_error("accessor runs past the end of its buffer view", where);
    base = bytes.data() + offset;
  }
  TAILOR_RETURN_IF_ERROR(charge(values * sizeof(T), where));
  out.assign(values, T{});
  // Floats into floats and uint32 into uint32 (most files' positions, normals, UVs and indices)
  // are copied as they are: the converting loop below costs 4x more.
  constexpr int kSameType = std::is_same_v<T, float> ? kGltfFloat : kGltfUnsignedInt;
  if (base && info.component_type == kSameType && stride == element) {
    if (values > 0) std::memcpy(out.data(), base, values * sizeof(T));
  } else if (base && info.component_type == kSameType) {
    for (size_t i = 0; i < info.count; ++i) std::memcpy(&out[i * size_t(info.components)], base + i * stride, element);
  } else if (base) {  // else zeros (or a sparse accessor's base)
    for (size_t i = 0; i < info.count; ++i)
      for (size_t c = 0; c < size_t(info.components); ++c)
        out[i * size_t(info.components) + c] =
            convert<T>(base + i * stride + c * size, info.component_type, info.normalized);
  }
  decoded_ += values * size;
  if (progress_ && !progress_->at(decoded_)) return progress_->cancelled(name_);
  const auto sparse = accessor.find("sparse");
  if (sparse == accessor.end()) return Status::ok();
  const std::string sparse_where = where + " sparse";
  uint64_t count = 0, index_view = 0, value_view = 0, index_offset = 0, value_offset = 0, index_type = 0;
  const auto indices = sparse->is_object() ? sparse->find("indices") : sparse->end();
  const auto sparse_values = sparse->is_object() ? sparse->find("values") : sparse->end();
  if (!get_uint(*sparse, "count", count) || indices == sparse->end() || sparse_values == sparse->end() ||
      !get_uint(*indices, "bufferView", index_view) || !get_uint(*indices, "componentType", index_type) ||
      !get_uint(*sparse_values, "bufferView", value_view))
    return parse_error("sparse without count, indices or values", sparse_where);
  if ((indices->contains("byteOffset") && !get_uint(*indices, "byteOffset", index_offset)) ||
      (sparse_values->contains("byteOffset") && !get_uint(*sparse_values, "byteOffset", value_offset)))
    return parse_error("bad sparse byteOffset", sparse_where);
  if (count > info.count) return parse_error("more sparse values than elements", sparse_where);
  const int itype = index_type <= INT_MAX ? static_cast<int>(index_type) : 0;
  if (itype != kGltfUnsignedByte && itype != kGltfUnsignedShort && itype != kGltfUnsignedInt)
    return parse_error("sparse indices must be unsigned integers", sparse_where);
  std::span<const unsigned char> index_bytes, value_bytes;
  TAILOR_RETURN_IF_ERROR(view_bytes(index_view, index_bytes, stride));
  TAILOR_RETURN_IF_ERROR(view_bytes(value_view, value_bytes, stride));
  const size_t n = static_cast<size_t>(count), isize = size_t(component_size(itype));
  if (index_offset > index_bytes.size() || n > (index_bytes.size() - index_offset) / isize ||
      value_offset > value_bytes.size() || n > (value_bytes.size() - value_offset) / element)
    return parse_error("sparse data runs past the end of its buffer view", sparse_where);
  for (size_t k = 0; k < n; ++k) {
    const uint32_t target = component_uint(index_bytes.data() + index_offset + k * isize, itype);
    if (target >= info.count)
      return parse_error("sparse index " + std::to_string(target) + " out of range", sparse_where);
    const unsigned char* value = value_bytes.data() + value_offset + k * element;
    for (size_t c = 0; c < size_t(info.components); ++c)
      out[size_t{target} * size_t(info.components) + c] =
          convert<T>(value + c * size, info.component_type, info.normalized);
  }
  return Status::ok();
}

Status GltfDocument::read_floats(uint64_t index, std::vector<float>& out, AccessorInfo& info) {
  return read_accessor(index, out, info);
}

Status GltfDocument::read_indices(uint64_t index, std::vector<uint32_t>& out) {
  AccessorInfo info;
  TAILOR_RETURN_IF_ERROR(accessor_info(index, info));
  const int t = info.component_type;
  if ((t != kGltfUnsignedByte && t != kGltfUnsignedShort && t != kGltfUnsignedInt) || info.components != 1)
    return parse_error("indices must be unsigned integer scalars", "accessor " + std::to_string(index));
  return read_accessor(index, out, info);
}

}  // namespace tailor::internal
