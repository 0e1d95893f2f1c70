// Binary glTF 2.0 writer (.glb): one node, one mesh, one triangle primitive with POSITION (with
// min/max), NORMAL (optional), TEXCOORD_0 and uint32 indices, one material whose base colour
// texture is the given PNG/JPEG embedded byte for byte (a JPEG that EXIF turns: upright, as PNG), sampled with REPEAT
// and trilinear filtering. The JSON is built with nlohmann::json (keys sorted, so the output is deterministic) rather
// than through tinygltf's writer, which would decode and re-encode the image. Reference: the glTF 2.0 specification,
// sections 3.6 (buffers), 3.7 (geometry), 4.4 (GLB layout).
#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <span>
#include <vector>

#include "export/writers.h"
#include "io/exif_orientation.h"
#include "io/glb_format.h"
#include "tailor/image.h"
#include "util/atomic_file.h"

namespace tailor::internal {
namespace {

// glTF sampler enumerations (spec section 5).
constexpr int kLinear = 9729;
constexpr int kLinearMipmapLinear = 9987;
constexpr int kRepeat = 10497;
constexpr double kHalfSqrt2 = 0.70710678118654752;  // the node rotation of a Z-up scene: -90 degrees about x

template <typename T>
std::span<const char> bytes_of(const T* data, size_t count) {
  static_assert(std::endian::native == std::endian::little, "glb writer assumes a little-endian host");
  return {reinterpret_cast<const char*>(data), count * sizeof(T)};
}

// Streams `count` items of `floats_per_item` floats, each made by make(item, float* out), through
// one small reusable buffer: the arrays gathered for the file are never held whole in memory.
template <class Make>
Status write_gathered(AtomicFileWriter& file, ExportProgress& progress, size_t count, size_t floats_per_item,
                      Make&& make) {
  constexpr size_t kChunkItems = 16384;
  std::vector<float> chunk(kChunkItems * floats_per_item);
  for (size_t begin = 0; begin < count; begin += kChunkItems) {
    const size_t end = std::min(count, begin + kChunkItems);
    float* out = chunk.data();
    for (size_t i = begin; i < end; ++i, out += floats_per_item) make(i, out);
    TAILOR_RETURN_IF_ERROR(file.write(bytes_of(chunk.data(), (end - begin) * floats_per_item)));
    if (!progress.wrote(4 * (end - begin) * floats_per_item)) return progress.cancelled();
  }
  return Status::ok();
}

// Adds a buffer view over bin[offset, offset + length) and returns its index.
size_t add_view(nlohmann::json& views, size_t offset, size_t length, int target) {
  nlohmann::json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", length}};
  if (target != 0) view["target"] = target;
  views.push_back(view);
  return views.size() - 1;
}

}  // namespace

Status glb_base_color(const ExportOptions& options, std::string& bytes, std::string& mime_type) {
  if (options.texture_path.empty() || !options.image_uris.color.empty()) return Status::ok();
  TAILOR_RETURN_IF_ERROR(read_texture_bytes(options.texture_path, bytes, mime_type));
  // A JPEG that EXIF turns was mapped upright (load_image turns it), but glTF viewers show a
  // texture's stored rows: the upright pixels go in as PNG instead.
  if (mime_type == "image/jpeg" &&
      jpeg_exif_orientation({reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()}) != 1) {
    const Image* upright = options.texture_image;
    Image decoded;
    if (upright == nullptr) {
      TAILOR_RETURN_IF_ERROR(load_image(options.texture_path, decoded));
      upright = &decoded;
    }
    TAILOR_RETURN_IF_ERROR(encode_png(*upright, bytes).with_file(options.texture_path));
    mime_type = "image/png";
  }
  return Status::ok();
}

void add_glb_material(nlohmann::json& gltf, nlohmann::json& views, size_t blob_offset, std::string& blob,
                      const std::string& base_color, const std::string& mime_type, const ExportOptions& options,
                      int uv_set) {
  const MaterialTextures& material = options.material;
  nlohmann::json pbr = {{"metallicFactor", 0.0}, {"roughnessFactor", 1.0}};
  nlohmann::json out = {{"name", "tailor"}};
  nlohmann::json images = nlohmann::json::array(), textures = nlohmann::json::array();
  // One image and texture per map, its bytes in a view of their own unless it is named by URI;
  // returns the texture's reference.
  auto add = [&](const std::string& bytes, const std::string& mime, const std::string& uri) {
    if (uri.empty()) {
      const size_t view = add_view(views, blob_offset + blob.size(), bytes.size(), 0);
      blob += bytes;
      pad_to_4(blob, '\0');
      images.push_back({{"bufferView", view}, {"mimeType", mime}});
    } else {
      images.push_back({{"uri", uri}});
    }
    textures.push_back({{"sampler", 0}, {"source", images.size() - 1}});
    nlohmann::json ref = {{"index", textures.size() - 1}};
    if (uv_set != 0) ref["texCoord"] = uv_set;
    return ref;
  };
  const ImageUris& uris = options.image_uris;
  if (!options.texture_path.empty()) pbr["baseColorTexture"] = add(base_color, mime_type, uris.color);
  if (options.has_normal_map()) out["normalTexture"] = add(material.normal_png, "image/png", uris.normal);
  if (options.has_orm_map()) {
    const nlohmann::json ref = add(material.orm_png, "image/png", uris.orm);
    if (material.orm_roughness_metallic) {
      pbr["metallicRoughnessTexture"] = ref;
      pbr["metallicFactor"] = 1.0;  // the B channel says how metallic (0 where no metallic map was given)
    }
    if (material.orm_occlusion) out["occlusionTexture"] = ref;  // glTF reads occlusion from R
  }
  if (!images.empty()) {
    gltf["images"] = images;
    gltf["samplers"] = {
        {{"magFilter", kLinear}, {"minFilter", kLinearMipmapLinear}, {"wrapS", kRepeat}, {"wrapT", kRepeat}}};
    gltf["textures"] = textures;
  }
  out["pbrMetallicRoughness"] = pbr;
  if (options.symmetry == 4) out["extras"] = {{"tailor", {{"symmetry", 4}}}};
  gltf["materials"] = {out};
}

Status write_glb(const std::string& path, const ExportData& data, const ExportOptions& options) {
  const Mesh& mesh = *data.mesh;
  const SplitMesh& split = data.split;
  const size_t vertex_count = split.xref.size();
  const size_t index_count = split.indices.size();
  if (vertex_count > std::numeric_limits<uint32_t>::max() / 12 ||
      index_count > std::numeric_limits<uint32_t>::max() / 4)
    return Status::error(ErrorCode::kLimit, path, "mesh too large for a .glb buffer (4 GiB)");

  std::string texture_bytes, mime_type;
  TAILOR_RETURN_IF_ERROR(glb_base_color(options, texture_bytes, mime_type));
  // One primitive per part (a glTF scene's), each over its own range of split vertices and indices.
  std::vector<ExportPart> parts = data.parts;
  if (parts.empty()) parts.push_back({0, 0, vertex_count, 0, index_count});

  // The BIN chunk's layout: positions, normals (optional), kept attributes, texcoords, indices,
  // tangents (optional), images; one view each, one accessor per part into it. Every block is a
  // multiple of 4 bytes long, so each starts 4-byte aligned.
  const float* positions = mesh.positions.data();
  const bool normals = !data.normals.empty();
  size_t bin_size = 0;
  nlohmann::json views = nlohmann::json::array(), accessors = nlohmann::json::array();
  std::vector<nlohmann::json> primitives(parts.size(), {{"mode", kGltfTriangles}});
  // A view of `width` bytes per element (of `count`) and one accessor per part into it.
  auto add_array = [&](const std::string& attribute, size_t width, size_t count, int component_type, const char* type,
                       int target, auto&& extra) {
    const size_t view = add_view(views, bin_size, width * count, target);
    bin_size += width * count;
    // Several accessors on one vertex view need its stride (spec 3.6.2.4).
    if (target == kGltfArrayBuffer && parts.size() > 1) views[view]["byteStride"] = width;
    for (size_t i = 0; i < parts.size(); ++i) {
      const ExportPart& p = parts[i];
      const bool vertices = target == kGltfArrayBuffer;
      const size_t begin = vertices ? p.vertex_begin : p.index_begin, end = vertices ? p.vertex_end : p.index_end;
      nlohmann::json accessor = {
          {"bufferView", view}, {"componentType", component_type}, {"count", end - begin}, {"type", type}};
      if (begin != 0) accessor["byteOffset"] = width * begin;
      extra(p, accessor);
      if (attribute.empty())
        primitives[i]["indices"] = accessors.size();
      else
        primitives[i]["attributes"][attribute] = accessors.size();
      accessors.push_back(std::move(accessor));
    }
  };
  auto nothing = [](const ExportPart&, nlohmann::json&) {};
  // Split positions are source positions through xref, in split order (the order matters for
  // min/max: -0 and +0 compare equal, the first one seen is kept).
  add_array("POSITION", 12, vertex_count, kGltfFloat, "VEC3", kGltfArrayBuffer,
            [&](const ExportPart& p, nlohmann::json& a) {
              float lo[3] = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
                             std::numeric_limits<float>::max()};
              float hi[3] = {-lo[0], -lo[1], -lo[2]};
              for (size_t s = p.vertex_begin; s < p.vertex_end; ++s) {
                const float* q = &positions[3 * size_t{split.xref[s]}];
                for (int i = 0; i < 3; ++i) {
                  lo[i] = std::min(lo[i], q[i]);
                  hi[i] = std::max(hi[i], q[i]);
                }
              }
              a["min"] = {lo[0], lo[1], lo[2]};
              a["max"] = {hi[0], hi[1], hi[2]};
            });
  if (normals) add_array("NORMAL", 12, vertex_count, kGltfFloat, "VEC3", kGltfArrayBuffer, nothing);
  for (const CornerAttribute& a : data.kept)  // the file's own: colours, other UV sets
    add_array(a.name, 4 * size_t(a.components), vertex_count, kGltfFloat,
              a.components == 2   ? "VEC2"
              : a.components == 3 ? "VEC3"
                                  : "VEC4",
              kGltfArrayBuffer, nothing);
  add_array("TEXCOORD_" + std::to_string(data.uv_set), 8, vertex_count, kGltfFloat, "VEC2", kGltfArrayBuffer, nothing);
  add_array("", 4, index_count, kGltfUnsignedInt, "SCALAR", kGltfElementArrayBuffer, nothing);
  const bool tangents = !data.tangents.empty();
  // per split vertex, after the indices (written straight from data.tangents)
  if (tangents) add_array("TANGENT", 16, vertex_count, kGltfFloat, "VEC4", kGltfArrayBuffer, nothing);

  nlohmann::json node = {{"name", "tailor"}};
  if (options.up == SceneUp::kZ) node["rotation"] = {-kHalfSqrt2, 0.0, 0.0, kHalfSqrt2};
  nlohmann::json gltf;
  std::string images;  // the material's images, after the indices
  add_glb_material(gltf, views, bin_size, images, texture_bytes, mime_type, options, data.uv_set);
  add_glb_scene(gltf, data, node, std::move(primitives));
  texture_bytes = {};
  if (images.size() > std::numeric_limits<uint32_t>::max() - bin_size)
    return Status::error(ErrorCode::kLimit, path, "texture too large for a .glb buffer");
  bin_size += images.size();
  gltf["accessors"] = accessors;
  gltf["bufferViews"] = views;
  gltf["buffers"] = {{{"byteLength", bin_size}}};

  // Strings may come from file names, which need not be UTF-8: replace, never throw.
  std::string json = gltf.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  pad_to_4(json, ' ');
  const size_t total = 12 + 8 + json.size() + 8 + bin_size;
  if (total > std::numeric_limits<uint32_t>::max())
    return Status::error(ErrorCode::kLimit, path, "output larger than the 4 GiB a .glb can hold");

  // Header, JSON chunk and BIN chunk header in one small string; the rest goes straight from the
  // split (texture bytes) or through a small buffer (positions, normals, texcoords, indices).
  std::string head;
  head.reserve(28 + json.size());
  append_u32(head, kGlbMagic);
  append_u32(head, 2);
  append_u32(head, static_cast<uint32_t>(total));
  append_u32(head, static_cast<uint32_t>(json.size()));
  append_u32(head, kChunkJson);
  head += json;
  append_u32(head, static_cast<uint32_t>(bin_size));
  append_u32(head, kChunkBin);

  ExportProgress progress(options.progress, bin_size, path);
  AtomicFileWriter file(path);
  TAILOR_RETURN_IF_ERROR(file.open());
  TAILOR_RETURN_IF_ERROR(file.write(head));
  const uint32_t* xref = split.xref.data();
  TAILOR_RETURN_IF_ERROR(write_gathered(file, progress, vertex_count, 3, [&](size_t s, float* out) {
    std::memcpy(out, &positions[3 * size_t{xref[s]}], 3 * sizeof(float));
  }));
  if (normals) {
    const float* source = data.normals.data();
    TAILOR_RETURN_IF_ERROR(write_gathered(file, progress, vertex_count, 3, [&](size_t s, float* out) {
      std::memcpy(out, &source[3 * size_t{xref[s]}], 3 * sizeof(float));
    }));
  }
  for (const CornerAttribute& a : data.kept) {
    const size_t k = size_t(a.components);
    const float* values = a.values.data();
    TAILOR_RETURN_IF_ERROR(write_gathered(file, progress, vertex_count, k, [&](size_t s, float* out) {
      std::memcpy(out, &values[k * size_t{xref[s]}], k * sizeof(float));
    }));
  }
  // glTF's v axis points down the image: TEXCOORD_0 = (s, -t), the usual (s, 1 - t) shifted by a
  // whole repeat (invisible with REPEAT) but exact, so a round trip is bit-exact (see export.h).
  const float* uvs = split.uvs.data();
  TAILOR_RETURN_IF_ERROR(write_gathered(file, progress, vertex_count, 2, [&](size_t s, float* out) {
    out[0] = uvs[2 * s];
    out[1] = -uvs[2 * s + 1];
  }));
  if (parts.size() == 1) {
    TAILOR_RETURN_IF_ERROR(file.write(bytes_of(split.indices.data(), index_count)));
  } else {  // indices of a part count from its first vertex
    for (const ExportPart& p : parts) {
      constexpr size_t kChunk = 3 * 16384;
      std::vector<uint32_t> chunk(kChunk);
      const uint32_t base = static_cast<uint32_t>(p.vertex_begin);
      for (size_t begin = p.index_begin; begin < p.index_end; begin += kChunk) {
        const size_t end = std::min(p.index_end, begin + kChunk);
        for (size_t i = begin; i < end; ++i) chunk[i - begin] = split.indices[i] - base;
        TAILOR_RETURN_IF_ERROR(file.write(bytes_of(chunk.data(), end - begin)));
        if (!progress.wrote(4 * (end - begin))) return ExportProgress::cancelled(path);
      }
    }
  }
  if (tangents) TAILOR_RETURN_IF_ERROR(file.write(bytes_of(data.tangents.data(), data.tangents.size())));
  TAILOR_RETURN_IF_ERROR(file.write(images));
  if (!progress.reached(1.f)) return ExportProgress::cancelled(path);
  return file.commit();
}

}  // namespace tailor::internal
