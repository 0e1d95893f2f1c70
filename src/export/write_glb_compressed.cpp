// Compressed .glb (ExportOptions::compression): the same node, mesh, material and texture as
// write_glb.cpp, with the geometry
//   quantize  KHR_mesh_quantization: positions as normalized int16 around the bounding box's
//             centre, undone by the node's translation and (uniform) scale, so normals need no
//             correction; normals normalized int16; UVs float (they span many repeats); indices
//             uint16 when the vertices allow;
//   meshopt   the same arrays in vertex-cache order (meshopt_optimizeVertexCache, then vertex
//             fetch order), each coded by EXT_meshopt_compression (Debian's libmeshoptimizer),
//             with the uncompressed layout declared in a fallback buffer as the extension asks;
//   draco     KHR_draco_mesh_compression (Debian's libdraco, edgebreaker): positions 16 bits,
//             normals 12, UVs 16. The stream is decoded once after encoding so that the accessors'
//             counts and POSITION's min/max are exactly what a reader gets.
// The arrays are built in memory (the codecs want whole streams); the output is deterministic.
// References: the KHR_mesh_quantization, EXT_meshopt_compression and KHR_draco_mesh_compression
// specifications.
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <string_view>
#include <vector>

#include "export/writers.h"
#include "io/glb_format.h"
#include "util/atomic_file.h"

namespace tailor::internal {
namespace {

// One array of the file: its bytes (uncompressed), element stride and the accessor that reads it.
struct Stream {
  std::string bytes;
  size_t stride = 0;
  int target = kGltfArrayBuffer;
  nlohmann::json accessor;
  const char* attribute = nullptr;  // null: the indices
  const char* filter = nullptr;     // meshopt: the filter `bytes` went through (they are its output)
};

template <class T>
std::string bytes_of(const std::vector<T>& v) {
  static_assert(std::endian::native == std::endian::little, "glb writer assumes a little-endian host");
  return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

// The source arrays of the split mesh: positions, normals (may be empty), UVs in glTF's
// convention (s, -t: see export.h), indices.
struct Arrays {
  std::vector<float> positions, normals, uvs;
  std::vector<CornerAttribute> kept;  // per split vertex
  std::string uv_name = "TEXCOORD_0";
  std::vector<uint32_t> indices;
  size_t vertex_count() const { return positions.size() / 3; }
};

Arrays gather(const ExportData& data) {
  Arrays a;
  const SplitMesh& split = data.split;
  const size_t nv = split.xref.size();
  a.positions.resize(3 * nv);
  if (!data.normals.empty()) a.normals.resize(3 * nv);
  a.uvs.resize(2 * nv);
  for (size_t s = 0; s < nv; ++s) {
    const size_t v = split.xref[s];
    std::memcpy(&a.positions[3 * s], &data.mesh->positions[3 * v], 12);
    if (!a.normals.empty()) std::memcpy(&a.normals[3 * s], &data.normals[3 * v], 12);
    a.uvs[2 * s] = split.uvs[2 * s];
    a.uvs[2 * s + 1] = -split.uvs[2 * s + 1];
  }
  for (const CornerAttribute& source : data.kept) {
    const size_t k = size_t(source.components);
    CornerAttribute& out = a.kept.emplace_back(CornerAttribute{source.name, source.components, {}});
    out.values.resize(k * nv);
    for (size_t s = 0; s < nv; ++s)
      std::memcpy(&out.values[k * s], &source.values[k * split.xref[s]], k * sizeof(float));
  }
  if (!data.tangents.empty()) a.kept.push_back(CornerAttribute{"TANGENT", 4, data.tangents});  // per split vertex
  a.uv_name = "TEXCOORD_" + std::to_string(data.uv_set);
  a.indices = split.indices;
  return a;
}

// Vertex-cache order for the triangles, then vertices in first-use order (what the meshopt codec
// compresses best).
void optimize_order(Arrays& a) {
  const size_t nv = a.vertex_count(), ni = a.indices.size();
  meshopt_optimizeVertexCache(a.indices.data(), a.indices.data(), ni, nv);
  std::vector<uint32_t> remap(nv);
  meshopt_optimizeVertexFetchRemap(remap.data(), a.indices.data(), ni, nv);
  meshopt_remapIndexBuffer(a.indices.data(), a.indices.data(), ni, remap.data());
  auto apply = [&](std::vector<float>& v, size_t width) {
    if (!v.empty()) meshopt_remapVertexBuffer(v.data(), v.data(), nv, width * sizeof(float), remap.data());
  };
  apply(a.positions, 3);
  apply(a.normals, 3);
  apply(a.uvs, 2);
  for (CornerAttribute& k : a.kept) apply(k.values, size_t(k.components));
}

int16_t snorm16(double x) { return static_cast<int16_t>(std::lround(std::clamp(x, -1.0, 1.0) * 32767.0)); }

// The quantization of all positions: centre and half side of the bounding cube, which the node's
// translation and scale undo.
void quantization(const Arrays& a, double center[3], double& half) {
  const size_t nv = a.vertex_count();
  double lo[3] = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                  std::numeric_limits<double>::max()};
  double hi[3] = {-lo[0], -lo[1], -lo[2]};
  for (size_t v = 0; v < nv; ++v)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], double{a.positions[3 * v + size_t(k)]});
      hi[k] = std::max(hi[k], double{a.positions[3 * v + size_t(k)]});
    }
  half = 0;
  for (int k = 0; k < 3; ++k) {
    center[k] = static_cast<float>(0.5 * (lo[k] + hi[k]));  // the value the file stores
    half = std::max(half, 0.5 * (hi[k] - lo[k]));
  }
  half = half > 0 ? static_cast<float>(half * (1 + 1e-6)) : 1.0;  // every point inside [-1, 1] after rounding
}

// The part of `a` over split vertices [p.vertex_begin, p.vertex_end) and its indices, renumbered.
Arrays slice(const Arrays& a, const ExportPart& p) {
  Arrays out;
  const size_t vb = p.vertex_begin, ve = p.vertex_end;
  auto range = [&](const std::vector<float>& v, size_t width) {
    return v.empty() ? std::vector<float>()
                     : std::vector<float>(v.begin() + long(width * vb), v.begin() + long(width * ve));
  };
  out.positions = range(a.positions, 3);
  out.normals = range(a.normals, 3);
  out.uvs = range(a.uvs, 2);
  for (const CornerAttribute& k : a.kept)
    out.kept.push_back(CornerAttribute{k.name, k.components, range(k.values, size_t(k.components))});
  out.uv_name = a.uv_name;
  out.indices.assign(a.indices.begin() + long(p.index_begin), a.indices.begin() + long(p.index_end));
  for (uint32_t& i : out.indices) i -= static_cast<uint32_t>(vb);
  return out;
}

// The quantized streams (KHR_mesh_quantization) under the quantization (center, half).
std::vector<Stream> quantized_streams(const Arrays& a, const double center[3], double half) {
  const size_t nv = a.vertex_count();
  std::vector<Stream> streams;
  std::vector<int16_t> q(4 * nv, 0);
  int qlo[3] = {32767, 32767, 32767}, qhi[3] = {-32767, -32767, -32767};
  for (size_t v = 0; v < nv; ++v)
    for (int k = 0; k < 3; ++k) {
      const int16_t value = snorm16((a.positions[3 * v + size_t(k)] - center[k]) / half);
      q[4 * v + size_t(k)] = value;
      qlo[k] = std::min<int>(qlo[k], value);
      qhi[k] = std::max<int>(qhi[k], value);
    }
  streams.push_back({bytes_of(q),
                     8,
                     kGltfArrayBuffer,
                     {{"componentType", kGltfShort},
                      {"normalized", true},
                      {"count", nv},
                      {"type", "VEC3"},
                      {"min", {qlo[0], qlo[1], qlo[2]}},
                      {"max", {qhi[0], qhi[1], qhi[2]}}},
                     "POSITION"});
  if (!a.normals.empty()) {
    std::fill(q.begin(), q.end(), int16_t{0});
    for (size_t v = 0; v < nv; ++v)
      for (int k = 0; k < 3; ++k) q[4 * v + size_t(k)] = snorm16(a.normals[3 * v + size_t(k)]);
    streams.push_back({bytes_of(q),
                       8,
                       kGltfArrayBuffer,
                       {{"componentType", kGltfShort}, {"normalized", true}, {"count", nv}, {"type", "VEC3"}},
                       "NORMAL"});
  }
  for (const CornerAttribute& k : a.kept)
    streams.push_back({bytes_of(k.values),
                       4 * size_t(k.components),
                       kGltfArrayBuffer,
                       {{"componentType", kGltfFloat},
                        {"count", nv},
                        {"type", k.components == 2   ? "VEC2"
                                 : k.components == 3 ? "VEC3"
                                                     : "VEC4"}},
                       k.name.c_str()});
  streams.push_back({bytes_of(a.uvs),
                     8,
                     kGltfArrayBuffer,
                     {{"componentType", kGltfFloat}, {"count", nv}, {"type", "VEC2"}},
                     a.uv_name.c_str()});
  if (nv <= 65535) {
    const std::vector<uint16_t> small(a.indices.begin(), a.indices.end());
    streams.push_back({bytes_of(small),
                       2,
                       kGltfElementArrayBuffer,
                       {{"componentType", kGltfUnsignedShort}, {"count", small.size()}, {"type", "SCALAR"}}});
  } else {
    streams.push_back({bytes_of(a.indices),
                       4,
                       kGltfElementArrayBuffer,
                       {{"componentType", kGltfUnsignedInt}, {"count", a.indices.size()}, {"type", "SCALAR"}}});
  }
  return streams;
}

// Bits kept by the meshopt filters: normals as 8-bit octahedral pairs (about half a degree), UVs
// with an 18-bit mantissa under their shared exponent (0.00025 repeats, an eighth of a pixel of a
// 512 px texture, at 60 repeats from the origin).
constexpr int kNormalBits = 8, kUvBits = 18;

// Meshopt mode: normals and UVs go through the codec's filters (smaller and better compressed).
void apply_meshopt_filters(const Arrays& a, std::vector<Stream>& streams) {
  const size_t nv = a.vertex_count();
  for (Stream& s : streams) {
    if (!s.attribute) continue;  // the indices
    if (s.attribute == std::string_view("NORMAL")) {
      std::vector<float> four(4 * nv, 0.0f);
      for (size_t v = 0; v < nv; ++v) std::memcpy(&four[4 * v], &a.normals[3 * v], 12);
      std::string out(4 * nv, '\0');
      meshopt_encodeFilterOct(out.data(), nv, 4, kNormalBits, four.data());
      s = {out,
           4,
           kGltfArrayBuffer,
           {{"componentType", kGltfByte}, {"normalized", true}, {"count", nv}, {"type", "VEC3"}},
           "NORMAL",
           "OCTAHEDRAL"};
    } else if (s.attribute == std::string_view(a.uv_name)) {
      std::string out(8 * nv, '\0');
      meshopt_encodeFilterExp(out.data(), nv, 8, kUvBits, a.uvs.data());
      s.bytes = out;
      s.filter = "EXPONENTIAL";
    }
  }
}

// EXT_meshopt_compression: each stream coded into `bin`, its view declared over the fallback buffer 1.
Status meshopt_views(const std::string& path, std::vector<Stream>& streams, std::string& bin, nlohmann::json& views,
                     size_t& fallback_size) {
  for (Stream& s : streams) {
    const size_t count = s.bytes.size() / s.stride;
    std::string coded;
    const bool indices = s.attribute == nullptr;
    if (indices) {
      std::vector<uint32_t> wide(count);
      for (size_t i = 0; i < count; ++i) {
        if (s.stride == 2) {
          uint16_t v;
          std::memcpy(&v, s.bytes.data() + 2 * i, 2);
          wide[i] = v;
        } else {
          std::memcpy(&wide[i], s.bytes.data() + 4 * i, 4);
        }
      }
      uint32_t vertices = 0;
      for (uint32_t v : wide) vertices = std::max(vertices, v + 1);
      coded.resize(meshopt_encodeIndexBufferBound(count, vertices));
      coded.resize(
          meshopt_encodeIndexBuffer(reinterpret_cast<unsigned char*>(coded.data()), coded.size(), wide.data(), count));
    } else {
      coded.resize(meshopt_encodeVertexBufferBound(count, s.stride));
      coded.resize(meshopt_encodeVertexBuffer(reinterpret_cast<unsigned char*>(coded.data()), coded.size(),
                                              s.bytes.data(), count, s.stride));
    }
    if (coded.empty()) return Status::error(ErrorCode::kInvalidArgument, path, "meshopt could not code a stream");
    nlohmann::json extension = {{"buffer", 0},
                                {"byteOffset", bin.size()},
                                {"byteLength", coded.size()},
                                {"byteStride", s.stride},
                                {"count", count},
                                {"mode", indices ? "TRIANGLES" : "ATTRIBUTES"}};
    if (s.filter) extension["filter"] = s.filter;
    nlohmann::json view = {{"buffer", 1},
                           {"byteOffset", fallback_size},
                           {"byteLength", s.bytes.size()},
                           {"target", s.target},
                           {"extensions", {{"EXT_meshopt_compression", extension}}}};
    if (!indices) view["byteStride"] = s.stride;
    views.push_back(view);
    s.accessor["bufferView"] = views.size() - 1;
    bin += coded;
    pad_to_4(bin);
    fallback_size += s.bytes.size();
    fallback_size += (4 - fallback_size % 4) % 4;
  }
  return Status::ok();
}

// KHR_draco_mesh_compression: the stream into `bin` (one view), accessors without views.
Status draco_primitive(const std::string& path, const Arrays& a, std::string& bin, nlohmann::json& views,
                       std::vector<Stream>& streams, nlohmann::json& extension, const ProgressCallback& step) {
  const size_t nv = a.vertex_count(), nf = a.indices.size() / 3;
  draco::Mesh mesh;
  mesh.set_num_points(static_cast<uint32_t>(nv));
  mesh.SetNumFaces(nf);
  for (size_t f = 0; f < nf; ++f)
    mesh.SetFace(draco::FaceIndex(static_cast<uint32_t>(f)),
                 {draco::PointIndex(a.indices[3 * f]), draco::PointIndex(a.indices[3 * f + 1]),
                  draco::PointIndex(a.indices[3 * f + 2])});
  auto add = [&](draco::GeometryAttribute::Type type, const std::vector<float>& values, int components) {
    draco::GeometryAttribute attribute;
    attribute.Init(type, nullptr, static_cast<uint8_t>(components), draco::DT_FLOAT32, false,
                   static_cast<int64_t>(sizeof(float)) * components, 0);
    const int id = mesh.AddAttribute(attribute, true, static_cast<uint32_t>(nv));
    draco::PointAttribute* pa = mesh.attribute(id);
    for (size_t v = 0; v < nv; ++v)
      pa->SetAttributeValue(draco::AttributeValueIndex(static_cast<uint32_t>(v)), &values[size_t(components) * v]);
    return pa->unique_id();
  };
  nlohmann::json ids;
  ids["POSITION"] = add(draco::GeometryAttribute::POSITION, a.positions, 3);
  if (!a.normals.empty()) ids["NORMAL"] = add(draco::GeometryAttribute::NORMAL, a.normals, 3);
  for (const CornerAttribute& k : a.kept)
    ids[k.name] = add(k.name == "COLOR_0"   ? draco::GeometryAttribute::COLOR
                      : k.name == "TANGENT" ? draco::GeometryAttribute::GENERIC  // not quantized: stays unit length
                                            : draco::GeometryAttribute::TEX_COORD,
                      k.values, k.components);
  ids[a.uv_name] = add(draco::GeometryAttribute::TEX_COORD, a.uvs, 2);
  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, 16);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, 12);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, 16);
  draco::EncoderBuffer buffer;
  const draco::Status encoded = encoder.EncodeMeshToBuffer(mesh, &buffer);
  if (!encoded.ok())
    return Status::error(ErrorCode::kInvalidArgument, path,
                         "Draco cannot encode the mesh: " + encoded.error_msg_string());

  if (!step(0.75f)) return ExportProgress::cancelled(path);
  // What a reader will get: the counts and the dequantized positions' bounds.
  draco::DecoderBuffer in;
  in.Init(buffer.data(), buffer.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&in);
  if (!decoded.ok() || !decoded.value())
    return Status::error(ErrorCode::kInvalidArgument, path, "Draco cannot decode what it encoded");
  const std::unique_ptr<draco::Mesh> back = std::move(decoded).value();
  const size_t points = back->num_points(), faces = back->num_faces();
  const draco::PointAttribute* position = back->GetAttributeByUniqueId(ids["POSITION"].get<uint32_t>());
  if (!position) return Status::error(ErrorCode::kInvalidArgument, path, "Draco lost the positions");
  float lo[3] = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
                 std::numeric_limits<float>::max()};
  float hi[3] = {-lo[0], -lo[1], -lo[2]};
  for (uint32_t i = 0; i < position->size(); ++i) {
    float p[3];
    position->ConvertValue<float>(draco::AttributeValueIndex(i), 3, p);
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  }
  views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", buffer.size()}});
  extension = {{"bufferView", views.size() - 1}, {"attributes", ids}};
  bin.append(buffer.data(), buffer.size());
  pad_to_4(bin);
  streams.push_back({{},
                     0,
                     kGltfArrayBuffer,
                     {{"componentType", kGltfFloat},
                      {"count", points},
                      {"type", "VEC3"},
                      {"min", {lo[0], lo[1], lo[2]}},
                      {"max", {hi[0], hi[1], hi[2]}}},
                     "POSITION"});
  if (!a.normals.empty())
    streams.push_back(
        {{}, 0, kGltfArrayBuffer, {{"componentType", kGltfFloat}, {"count", points}, {"type", "VEC3"}}, "NORMAL"});
  for (const CornerAttribute& k : a.kept)
    streams.push_back({{},
                       0,
                       kGltfArrayBuffer,
                       {{"componentType", kGltfFloat},
                        {"count", points},
                        {"type", k.components == 2   ? "VEC2"
                                 : k.components == 3 ? "VEC3"
                                                     : "VEC4"}},
                       k.name.c_str()});
  streams.push_back({{},
                     0,
                     kGltfArrayBuffer,
                     {{"componentType", kGltfFloat}, {"count", points}, {"type", "VEC2"}},
                     a.uv_name.c_str()});
  streams.push_back({{},
                     0,
                     kGltfElementArrayBuffer,
                     {{"componentType", points <= 65535 ? kGltfUnsignedShort : kGltfUnsignedInt},
                      {"count", 3 * faces},
                      {"type", "SCALAR"}}});
  return Status::ok();
}

}  // namespace

Status write_glb_compressed(const std::string& path, const ExportData& data, const ExportOptions& options) {
  const size_t nv = data.split.xref.size();
  if (nv > std::numeric_limits<uint32_t>::max() / 16 ||
      data.split.indices.size() > std::numeric_limits<uint32_t>::max() / 4)
    return Status::error(ErrorCode::kLimit, path, "mesh too large for a .glb buffer (4 GiB)");
  std::string texture_bytes, mime_type;
  TAILOR_RETURN_IF_ERROR(glb_base_color(options, texture_bytes, mime_type));

  Arrays arrays = gather(data);
  // One primitive per part (a glTF scene's), each its own streams (Draco codes one per primitive).
  std::vector<ExportPart> parts = data.parts;
  const bool whole = parts.empty();
  if (whole) parts.push_back({0, 0, nv, 0, arrays.indices.size()});
  nlohmann::json node = {{"name", "tailor"}};
  nlohmann::json views = nlohmann::json::array(), accessors = nlohmann::json::array();
  nlohmann::json used = nlohmann::json::array(), buffers = nlohmann::json::array();
  std::vector<nlohmann::json> primitives;
  std::string bin;
  const bool meshopt = options.compression == MeshCompression::kMeshopt;
  if (options.compression == MeshCompression::kNone) return write_glb(path, data, options);
  double center[3] = {0, 0, 0}, half = 1;
  if (options.compression != MeshCompression::kDraco) {
    quantization(arrays, center, half);
    node["translation"] = {center[0], center[1], center[2]};
    node["scale"] = {half, half, half};
  }
  size_t fallback = 0;
  // Progress: each part's share of the indices, in steps (the codecs give none of their own).
  ExportProgress progress(options.progress, 0, path);
  const double index_count = static_cast<double>(std::max<size_t>(1, arrays.indices.size()));
  if (!progress.reached(0.05f)) return progress.cancelled();
  for (const ExportPart& p : parts) {
    auto step = [&](float done) {
      const double begin = static_cast<double>(p.index_begin) / index_count;
      const double share = static_cast<double>(p.index_end - p.index_begin) / index_count;
      return progress.reached(static_cast<float>(0.05 + 0.9 * (begin + share * done)));
    };
    Arrays part_arrays = whole ? Arrays{} : slice(arrays, p);
    Arrays& a = whole ? arrays : part_arrays;
    nlohmann::json primitive = {{"mode", kGltfTriangles}};
    std::vector<Stream> streams;
    if (options.compression == MeshCompression::kDraco) {
      nlohmann::json extension;
      TAILOR_RETURN_IF_ERROR(draco_primitive(path, a, bin, views, streams, extension, step));
      primitive["extensions"] = {{"KHR_draco_mesh_compression", extension}};
    } else {
      if (meshopt) optimize_order(a);
      if (!step(0.5f)) return progress.cancelled();
      streams = quantized_streams(a, center, half);
      if (meshopt) {
        apply_meshopt_filters(a, streams);
        TAILOR_RETURN_IF_ERROR(meshopt_views(path, streams, bin, views, fallback));
      } else {
        for (Stream& s : streams) {
          nlohmann::json view = {
              {"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", s.bytes.size()}, {"target", s.target}};
          if (s.attribute) view["byteStride"] = s.stride;
          views.push_back(view);
          s.accessor["bufferView"] = views.size() - 1;
          bin += s.bytes;
          pad_to_4(bin);
        }
      }
    }
    if (!step(1.f)) return progress.cancelled();
    nlohmann::json attributes;
    for (const Stream& s : streams) {
      accessors.push_back(s.accessor);
      if (s.attribute)
        attributes[s.attribute] = accessors.size() - 1;
      else
        primitive["indices"] = accessors.size() - 1;
    }
    primitive["attributes"] = attributes;
    primitives.push_back(std::move(primitive));
  }
  if (options.compression == MeshCompression::kDraco) {
    used.push_back("KHR_draco_mesh_compression");
  } else {
    if (meshopt) {
      buffers.push_back(nullptr);  // buffer 0, the BIN chunk: its length is known at the end
      buffers.push_back(
          {{"byteLength", fallback}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}});
      used.push_back("EXT_meshopt_compression");
    }
    used.push_back("KHR_mesh_quantization");
  }
  if (options.up == SceneUp::kZ) {  // -90 degrees about x: (x, y, z) -> (x, z, -y), after the quantization
    constexpr double h = 0.70710678118654752;
    node["rotation"] = {-h, 0.0, 0.0, h};
    if (node.contains("translation")) {
      const nlohmann::json t = node["translation"];
      node["translation"] = {t[0], t[2], -t[1].get<double>()};
    }
  }
  std::sort(used.begin(), used.end());

  nlohmann::json gltf = {{"extensionsUsed", used}, {"extensionsRequired", used}};
  pad_to_4(bin);
  std::string images;
  add_glb_material(gltf, views, bin.size(), images, texture_bytes, mime_type, options, data.uv_set);
  add_glb_scene(gltf, data, node, std::move(primitives));
  bin += images;
  if (buffers.empty()) buffers.push_back(nullptr);
  buffers[0] = {{"byteLength", bin.size()}};
  gltf["buffers"] = buffers;
  gltf["accessors"] = accessors;
  gltf["bufferViews"] = views;

  std::string json = gltf.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  pad_to_4(json, ' ');
  const size_t total = 12 + 8 + json.size() + 8 + bin.size();
  if (total > std::numeric_limits<uint32_t>::max())
    return Status::error(ErrorCode::kLimit, path, "output larger than the 4 GiB a .glb can hold");
  std::string head;
  append_u32(head, kGlbMagic);
  append_u32(head, 2);
  append_u32(head, static_cast<uint32_t>(total));
  append_u32(head, static_cast<uint32_t>(json.size()));
  append_u32(head, kChunkJson);
  head += json;
  append_u32(head, static_cast<uint32_t>(bin.size()));
  append_u32(head, kChunkBin);
  AtomicFileWriter file(path);
  TAILOR_RETURN_IF_ERROR(file.open());
  TAILOR_RETURN_IF_ERROR(file.write(head));
  TAILOR_RETURN_IF_ERROR(file.write(bin));
  if (!progress.reached(1.f)) return progress.cancelled();
  return file.commit();
}

}  // namespace tailor::internal
