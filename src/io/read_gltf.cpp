// glTF 2.0 reader (.glb and .gltf): the default scene's mesh instances in world space.
//
// The container and its JSON are parsed by our own code (gltf_document.cpp, nlohmann::json)
// rather than by tinygltf: tinygltf 2.7 hands an image's buffer view to the image loader without
// checking it against the buffer's size and opens any URI. Here every index is range-checked,
// every accessor checked against its buffer view before a byte is read, and the only files
// opened are buffers next to a .gltf (no scheme, no absolute path, no '..').
//
// What is read: the default scene (`scene`, else scene 0; every mesh once when the file has no
// scene) walked from its root nodes; each node that uses a mesh places an instance of it with the
// node's world transform (matrix or TRS, parents first) applied to the positions, winding flipped
// where the transform mirrors. Triangles, strips and fans become triangles; points and lines are
// skipped and counted (LoadReport::skipped_primitives). POSITION and the base colour texture's
// TEXCOORD set (TEXCOORD_0 by default) of any component
// type (KHR_mesh_quantization), sparse accessors, EXT_meshopt_compression buffer views and
// KHR_draco_mesh_compression primitives, EXT_mesh_gpu_instancing nodes. A required extension outside those is an error
// naming it. Reference: glTF 2.0 specification, sections 3.5 (scenes, nodes), 3.7 (meshes).
#include <stb/stb_image.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <new>
#include <optional>
#include <string_view>
#include <utility>

#include "io/gltf_document.h"
#include "io/readers.h"
#include "tailor/export.h"
#include "tailor/gltf.h"
#include "tailor/io.h"
#include "util/atomic_file.h"
#include "util/text_scan.h"

namespace tailor {
namespace {

using internal::AccessorInfo;
using internal::get_element;
using internal::get_uint;
using internal::GltfDocument;
using internal::Json;
using internal::quote_input;

constexpr uint64_t kTriangles = 4, kStrip = 5, kFan = 6;
constexpr std::array<const char*, 4> kSupportedExtensions = {"KHR_mesh_quantization", "EXT_meshopt_compression",
                                                             "KHR_draco_mesh_compression", "EXT_mesh_gpu_instancing"};

// Column-major 4x4, as glTF stores it.
using Matrix = std::array<double, 16>;
constexpr Matrix kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

Matrix multiply(const Matrix& a, const Matrix& b) {
  Matrix m{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      for (int k = 0; k < 4; ++k) m[size_t(4 * c + r)] += a[size_t(4 * k + r)] * b[size_t(4 * c + k)];
  return m;
}

// `n` finite numbers from the array member `key`; false when present but malformed.
bool get_numbers(const Json& node, const char* key, double* out, size_t n, bool& present) {
  const auto it = node.find(key);
  present = it != node.end();
  if (!present) return true;
  if (!it->is_array() || it->size() != n) return false;
  for (size_t i = 0; i < n; ++i) {
    if (!(*it)[i].is_number()) return false;
    out[i] = (*it)[i].get<double>();
    if (!std::isfinite(out[i])) return false;
  }
  return true;
}

// Scales the quaternion q (x y z w) to unit length, as glTF requires it and as viewers read one
// that is not (quantized rotations are only nearly so); false when it has no direction.
bool unit_quaternion(double* q) {
  double largest = 0;  // scaled by it first, so that huge or tiny finite components neither overflow nor vanish
  for (int k = 0; k < 4; ++k) {
    if (!std::isfinite(q[k])) return false;
    largest = std::max(largest, std::abs(q[k]));
  }
  if (!(largest > 0)) return false;
  for (int k = 0; k < 4; ++k) q[k] /= largest;
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (int k = 0; k < 4; ++k) q[k] /= norm;
  return true;
}

// translation * rotation (unit quaternion x y z w) * scale.
Matrix trs_matrix(const double* t, const double* q, const double* s) {
  Matrix m = kIdentity;
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  const double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),
                       2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                       2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y)};
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row) m[size_t(4 * c + row)] = r[3 * c + row] * s[c];
  for (int row = 0; row < 3; ++row) m[size_t(12 + row)] = t[row];
  return m;
}

// The node's local transform: `matrix`, or translation * rotation * scale.
bool local_transform(const Json& node, Matrix& m) {
  bool present = false;
  if (!get_numbers(node, "matrix", m.data(), 16, present)) return false;
  if (present) return true;
  double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
  if (!get_numbers(node, "translation", t, 3, present) || !get_numbers(node, "rotation", q, 4, present) ||
      !get_numbers(node, "scale", s, 3, present) || !unit_quaternion(q))
    return false;
  m = trs_matrix(t, q, s);
  return true;
}

struct Instance {
  size_t mesh = 0;
  Matrix world = kIdentity;
  uint64_t node = UINT64_MAX;  // UINT64_MAX: no scene (every mesh once)
};

// EXT_mesh_gpu_instancing: one instance per element of the TRANSLATION / ROTATION / SCALE
// accessors, each placed by world * its TRS.
Status gpu_instances(GltfDocument& doc, const Json& extension, size_t mesh, const Matrix& world, uint64_t node,
                     const std::string& where, std::vector<Instance>& instances) {
  const auto attributes = extension.find("attributes");
  if (attributes == extension.end() || !attributes->is_object())
    return doc.parse_error("EXT_mesh_gpu_instancing without attributes", where);
  static constexpr std::array<const char*, 3> kNames = {"TRANSLATION", "ROTATION", "SCALE"};
  static constexpr std::array<int, 3> kComponents = {3, 4, 3};
  std::array<std::vector<float>, 3> values;
  size_t count = SIZE_MAX;
  for (size_t k = 0; k < 3; ++k) {
    uint64_t accessor = 0;
    if (!get_uint(*attributes, kNames[k], accessor)) continue;
    AccessorInfo info;
    TAILOR_RETURN_IF_ERROR(doc.read_floats(accessor, values[k], info));
    if (info.components != kComponents[k])
      return doc.parse_error(std::string("EXT_mesh_gpu_instancing ") + kNames[k] + " has the wrong type", where);
    if (count != SIZE_MAX && info.count != count)
      return doc.parse_error("EXT_mesh_gpu_instancing attributes differ in count", where);
    count = info.count;
  }
  if (count == SIZE_MAX) return doc.parse_error("EXT_mesh_gpu_instancing without attributes", where);
  TAILOR_RETURN_IF_ERROR(doc.charge(count * sizeof(Instance), where));
  for (size_t i = 0; i < count; ++i) {
    double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    for (size_t c = 0; c < 3 && !values[0].empty(); ++c) t[c] = values[0][3 * i + c];
    for (size_t c = 0; c < 4 && !values[1].empty(); ++c) q[c] = values[1][4 * i + c];
    for (size_t c = 0; c < 3 && !values[2].empty(); ++c) s[c] = values[2][3 * i + c];
    if (!unit_quaternion(q))
      return doc.parse_error("EXT_mesh_gpu_instancing ROTATION without a direction",
                             where + " instance " + std::to_string(i));
    instances.push_back({mesh, multiply(world, trs_matrix(t, q, s)), node});
  }
  return Status::ok();
}

double determinant3(const Matrix& m) {
  return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) + m[8] * (m[1] * m[6] - m[5] * m[2]);
}

// Whether the transform's linear part has rank 1 or 0 (every pair of its columns parallel): it
// maps every face to a line or a point. A rank of 2 (a flattening scale such as [1, 1, 0]) keeps
// the area of the faces across the flattened direction.
bool flattens_to_a_line(const Matrix& m) {
  const double* c[3] = {&m[0], &m[4], &m[8]};
  for (size_t i = 0; i < 3; ++i)
    for (size_t j = i + 1; j < 3; ++j) {
      const double* a = c[i];
      const double* b = c[j];
      if (a[1] * b[2] - a[2] * b[1] != 0 || a[2] * b[0] - a[0] * b[2] != 0 || a[0] * b[1] - a[1] * b[0] != 0)
        return false;
    }
  return true;
}

// The mesh instances of the default scene, parents' transforms first. A node reached twice (the
// hierarchy is not a tree, or has a cycle) is an error.
Status scene_instances(GltfDocument& doc, std::vector<Instance>& instances) {
  const Json& json = doc.json();
  const auto meshes = json.find("meshes");
  const size_t mesh_count = meshes != json.end() && meshes->is_array() ? meshes->size() : 0;
  const auto scenes = json.find("scenes");
  if (scenes == json.end()) {  // no scene: every mesh once, where it is
    for (size_t m = 0; m < mesh_count; ++m) instances.push_back({m, kIdentity});
    return Status::ok();
  }
  uint64_t scene = 0;
  if (json.contains("scene") && !get_uint(json, "scene", scene)) return doc.parse_error("bad 'scene'");
  const Json* root = get_element(json, "scenes", scene);
  if (!root) return doc.parse_error("missing scene " + std::to_string(scene));
  const auto nodes = json.find("nodes");
  const size_t node_count = nodes != json.end() && nodes->is_array() ? nodes->size() : 0;
  std::vector<uint8_t> seen(node_count, 0);
  std::vector<std::pair<uint64_t, Matrix>> stack;
  const auto roots = root->find("nodes");
  if (roots != root->end()) {
    if (!roots->is_array()) return doc.parse_error("scene nodes is not an array", "scene " + std::to_string(scene));
    for (size_t i = roots->size(); i-- > 0;) {
      if (!(*roots)[i].is_number_unsigned()) return doc.parse_error("bad node index", "scene " + std::to_string(scene));
      stack.emplace_back((*roots)[i].get<uint64_t>(), kIdentity);
    }
  }
  while (!stack.empty()) {
    const auto [index, parent] = stack.back();
    stack.pop_back();
    const std::string where = "node " + std::to_string(index);
    const Json* node = get_element(json, "nodes", index);
    if (!node) return doc.parse_error("missing node", where);
    if (seen[static_cast<size_t>(index)]) return doc.parse_error("node appears twice in the scene (not a tree)", where);
    seen[static_cast<size_t>(index)] = 1;
    Matrix local;
    if (!local_transform(*node, local)) return doc.parse_error("bad matrix, translation, rotation or scale", where);
    const Matrix world = multiply(parent, local);
    uint64_t mesh = 0;
    if (node->contains("mesh")) {
      if (!get_uint(*node, "mesh", mesh) || mesh >= mesh_count) return doc.parse_error("bad mesh index", where);
      const Json* gpu = nullptr;
      const auto extensions = node->find("extensions");
      if (extensions != node->end() && extensions->is_object()) {
        const auto it = extensions->find("EXT_mesh_gpu_instancing");
        if (it != extensions->end() && it->is_object()) gpu = &*it;
      }
      if (gpu)
        TAILOR_RETURN_IF_ERROR(gpu_instances(doc, *gpu, static_cast<size_t>(mesh), world, index, where, instances));
      else
        instances.push_back({static_cast<size_t>(mesh), world, index});
    }
    const auto children = node->find("children");
    if (children == node->end()) continue;
    if (!children->is_array()) return doc.parse_error("children is not an array", where);
    for (size_t i = children->size(); i-- > 0;) {
      const Json& child = (*children)[i];
      if (!child.is_number_unsigned()) return doc.parse_error("bad child index", where);
      stack.emplace_back(child.get<uint64_t>(), world);
    }
  }
  return Status::ok();
}

// One primitive in its mesh's own space, triangulated.
struct Primitive {
  std::vector<float> positions;       // #V by 3
  std::vector<uint32_t> triangles;    // #T by 3, < #V
  std::vector<float> uv;              // empty, or #V by 2 (glTF convention)
  std::vector<CornerAttribute> kept;  // NORMAL, COLOR_0 (as RGBA), TEXCOORD_n: #V by components
  size_t source_faces = 0;
  uint64_t material = UINT64_MAX;
  size_t index = 0;  // in its mesh's primitives
};

// The vertex attributes kept beside POSITION and TEXCOORD_0 (what export can write back), and
// TANGENT when the material is read (read_glb_with_material: for shading, never written back).
bool is_kept_attribute(const std::string& name, bool tangents = false) {
  if (name == "NORMAL" || name == "COLOR_0" || (tangents && name == "TANGENT")) return true;
  return name.size() == 10 && name.starts_with("TEXCOORD_") && name[9] >= '0' && name[9] <= '7';
}

// Adds a kept attribute read as `values` (#V by components), checking its shape.
Status keep_attribute(const GltfDocument& doc, const std::string& name, std::vector<float>&& values, int components,
                      size_t vertex_count, const std::string& where, Primitive& out) {
  const int want = name == "NORMAL" ? 3 : name == "TANGENT" ? 4 : name == "COLOR_0" ? 0 : 2;
  if ((want != 0 && components != want) || (want == 0 && components != 3 && components != 4))
    return doc.parse_error(name + " has the wrong type", where);
  if (values.size() != vertex_count * size_t(components))
    return doc.parse_error(name + " and POSITION counts differ", where);
  if (name == "COLOR_0" && components == 3) {  // RGBA, opaque
    std::vector<float> rgba(4 * vertex_count, 1.0f);
    for (size_t v = 0; v < vertex_count; ++v) std::copy_n(&values[3 * v], 3, &rgba[4 * v]);
    values = std::move(rgba);
    components = 4;
  }
  out.kept.push_back({name, components, std::move(values)});
  return Status::ok();
}

// Triangles from a triangle list, strip or fan over `corners` (spec section 3.7.2.1).
Status triangulate(const GltfDocument& doc, uint64_t mode, const std::vector<uint32_t>& corners, size_t vertex_count,
                   const std::string& where, Primitive& out) {
  const size_t n = corners.size();
  if (mode == kTriangles && n % 3 != 0) return doc.parse_error("triangle index count is not a multiple of 3", where);
  const size_t faces = mode == kTriangles ? n / 3 : n >= 3 ? n - 2 : 0;
  out.triangles.resize(3 * faces);
  for (size_t i = 0; i < faces; ++i) {
    uint32_t* t = &out.triangles[3 * i];
    if (mode == kTriangles) {
      t[0] = corners[3 * i], t[1] = corners[3 * i + 1], t[2] = corners[3 * i + 2];
    } else if (mode == kStrip) {
      t[0] = corners[i], t[1] = corners[i + 1 + i % 2], t[2] = corners[i + 2 - i % 2];
    } else {
      t[0] = corners[i + 1], t[1] = corners[i + 2], t[2] = corners[0];
    }
  }
  for (size_t c = 0; c < out.triangles.size(); ++c)
    if (out.triangles[c] >= vertex_count)
      return Status::error(ErrorCode::kInvalidMesh, doc.name(), "index out of range",
                           where + " index " + std::to_string(mode == kTriangles ? c : c / 3));
  out.source_faces = faces;
  return Status::ok();
}

// A material's pbrMetallicRoughness.baseColorTexture object, or null.
const Json* base_colour_texture(const Json& json, uint64_t material) {
  const Json* m = get_element(json, "materials", material);
  if (!m) return nullptr;
  const auto pbr = m->find("pbrMetallicRoughness");
  if (pbr == m->end() || !pbr->is_object()) return nullptr;
  const auto base = pbr->find("baseColorTexture");
  return base != pbr->end() && base->is_object() ? &*base : nullptr;
}

// The texture coordinate set a material's base colour texture reads (its "texCoord", 0 to 7): the
// UVs a viewer draws the texture with, so the ones Mesh::corner_uvs holds (tailor map --uv-set N
// writes N there). 0 without a material or texture.
uint64_t base_colour_uv_set(const Json& json, uint64_t material) {
  const Json* base = base_colour_texture(json, material);
  uint64_t set = 0;
  if (!base || !get_uint(*base, "texCoord", set) || set > 7) return 0;
  return set;
}

// True when material's base colour texture carries KHR_texture_transform: its offset, rotation
// and scale are not applied (eval measures and render draws the UVs as stored).
bool base_colour_transformed(const Json& json, uint64_t material) {
  const Json* base = base_colour_texture(json, material);
  const auto extensions = base ? base->find("extensions") : json.end();
  return base && extensions != base->end() && extensions->is_object() && extensions->contains("KHR_texture_transform");
}

// Reads primitive `pi` of mesh `mi` (mode already known to be triangles, strip or fan).
Status read_primitive(GltfDocument& doc, const Json& prim, uint64_t mode, const std::string& where, bool tangents,
                      Primitive& out) {
  const auto attributes = prim.find("attributes");
  uint64_t position_index = 0, uv_index = 0, indices_index = 0, material = 0;
  if (attributes == prim.end() || !get_uint(*attributes, "POSITION", position_index))
    return doc.parse_error("primitive without POSITION", where);
  if (get_uint(prim, "material", material)) out.material = material;
  // The set the base colour texture reads; TEXCOORD_0 when the primitive lacks it (a file that names
  // a set it does not have: as it was read before texCoord was followed).
  std::string uv_name = "TEXCOORD_" + std::to_string(base_colour_uv_set(doc.json(), out.material));
  bool has_uv = get_uint(*attributes, uv_name.c_str(), uv_index);
  if (!has_uv && uv_name != "TEXCOORD_0") {
    uv_name = "TEXCOORD_0";
    has_uv = get_uint(*attributes, uv_name.c_str(), uv_index);
  }
  std::vector<uint32_t> corners;
  const auto extensions = prim.find("extensions");
  const Json* draco = nullptr;
  if (extensions != prim.end() && extensions->is_object()) {
    const auto it = extensions->find("KHR_draco_mesh_compression");
    if (it != extensions->end() && it->is_object()) draco = &*it;
  }
  if (draco) {
    internal::DracoPrimitive decoded;
    std::vector<std::string> names = {"POSITION", uv_name};
    for (const auto& item : attributes->items())
      if (is_kept_attribute(item.key(), tangents)) names.push_back(item.key());
    TAILOR_RETURN_IF_ERROR(internal::decode_draco_primitive(doc, prim, *draco, names, where, decoded));
    if (decoded.components[0] != 3) return doc.unsupported("Draco POSITION is not 3D", where);
    out.positions = std::move(decoded.values[0]);
    if (decoded.components[1] == 2) out.uv = std::move(decoded.values[1]);
    for (size_t n = 2; n < names.size(); ++n)
      if (decoded.components[n] > 0)
        TAILOR_RETURN_IF_ERROR(keep_attribute(doc, names[n], std::move(decoded.values[n]), decoded.components[n],
                                              out.positions.size() / 3, where, out));
    corners = std::move(decoded.indices);
    mode = kTriangles;  // Draco decodes to a triangle list
  } else {
    AccessorInfo info;
    TAILOR_RETURN_IF_ERROR(doc.read_floats(position_index, out.positions, info));
    if (info.components != 3) return doc.unsupported("POSITION must be VEC3", where);
    if (has_uv) {
      AccessorInfo uv_info;
      TAILOR_RETURN_IF_ERROR(doc.read_floats(uv_index, out.uv, uv_info));
      if (uv_info.components != 2) return doc.parse_error(uv_name + " must be VEC2", where);
      if (uv_info.count != info.count) return doc.parse_error(uv_name + " and POSITION counts differ", where);
    }
    for (const auto& item : attributes->items()) {
      uint64_t index = 0;
      if (!is_kept_attribute(item.key(), tangents) || !get_uint(*attributes, item.key().c_str(), index)) continue;
      std::vector<float> values;
      AccessorInfo kept_info;
      TAILOR_RETURN_IF_ERROR(doc.read_floats(index, values, kept_info));
      TAILOR_RETURN_IF_ERROR(
          keep_attribute(doc, item.key(), std::move(values), kept_info.components, info.count, where, out));
    }
    if (get_uint(prim, "indices", indices_index)) {
      TAILOR_RETURN_IF_ERROR(doc.read_indices(indices_index, corners));
    } else {
      TAILOR_RETURN_IF_ERROR(doc.charge(4 * info.count, where));
      corners.resize(info.count);
      for (size_t i = 0; i < info.count; ++i) corners[i] = static_cast<uint32_t>(i);
    }
  }
  return triangulate(doc, mode, corners, out.positions.size() / 3, where, out);
}

// The image of a material's texture `key` ("baseColorTexture" and "metallicRoughnessTexture" in
// pbrMetallicRoughness, "normalTexture" and "occlusionTexture" in the material itself): its index
// in "images", or UINT64_MAX when the material has no such texture.
uint64_t texture_image(const GltfDocument& doc, uint64_t material, const char* key) {
  const Json* m = get_element(doc.json(), "materials", material);
  if (!m || !m->is_object()) return UINT64_MAX;
  const Json* holder = m;
  if (std::string_view(key) == "baseColorTexture" || std::string_view(key) == "metallicRoughnessTexture") {
    const auto pbr = m->find("pbrMetallicRoughness");
    if (pbr == m->end() || !pbr->is_object()) return UINT64_MAX;
    holder = &*pbr;
  }
  const auto base = holder->find(key);
  if (base == holder->end() || !base->is_object()) return UINT64_MAX;
  uint64_t texture = 0, source = 0;
  if (!get_uint(*base, "index", texture)) return UINT64_MAX;
  const Json* t = get_element(doc.json(), "textures", texture);
  if (!t || !get_uint(*t, "source", source) || !get_element(doc.json(), "images", source)) return UINT64_MAX;
  return source;
}

// The encoded image of a material's texture `key` (texture_image), if it is stored in the file: in
// a buffer view, or as a data: URI. Copied, since a .gltf's buffers go with the document. An image
// file's URI is not followed here (its path is LoadReport::texture_path, which render loads).
void find_texture(GltfDocument& doc, uint64_t material, const char* key, std::string& bytes) {
  bytes.clear();
  const uint64_t source = texture_image(doc, material, key);
  if (source == UINT64_MAX) return;
  uint64_t view = 0, stride = 0;
  const Json* image = get_element(doc.json(), "images", source);
  if (!image) return;
  if (get_uint(*image, "bufferView", view)) {
    std::span<const unsigned char> view_bytes;
    if (doc.view_bytes(view, view_bytes, stride).is_ok())
      bytes.assign(reinterpret_cast<const char*>(view_bytes.data()), view_bytes.size());
    return;
  }
  const auto uri = image->find("uri");
  bool file = false;
  if (uri != image->end() && uri->is_string() && uri->get_ref<const std::string&>().starts_with("data:") &&
      !doc.image_uri_bytes(source, 0, bytes, file))
    bytes.clear();
}

std::span<const unsigned char> as_bytes(const std::string& bytes) {
  return {reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()};
}

// 4 where a material's extras say its map is 4-fold ({"tailor": {"symmetry": 4}}, written by
// tailor map --symmetry 4), else 1; anything else there is ignored.
uint32_t material_symmetry(GltfDocument& doc, uint64_t material) {
  const Json* m = get_element(doc.json(), "materials", material);
  if (!m || !m->is_object()) return 1;
  const auto extras = m->find("extras");
  if (extras == m->end() || !extras->is_object()) return 1;
  const auto tailor = extras->find("tailor");
  uint64_t symmetry = 1;
  if (tailor == extras->end() || !tailor->is_object() || !get_uint(*tailor, "symmetry", symmetry)) return 1;
  return symmetry == 4 ? 4 : 1;
}

// Decodes an embedded image. `undecodable` (may be null) tells a failure of the bytes themselves
// (not an image, corrupt data) apart from an image over `options`' limits.
Status decode_texture(std::span<const unsigned char> bytes, const std::string& name, const ImageLoadOptions& options,
                      Image& image, bool* undecodable = nullptr) {
  image = Image{};
  if (undecodable) *undecodable = false;
  if (bytes.size() > size_t{INT_MAX})
    return Status::error(ErrorCode::kInvalidImage, name, "embedded texture too large");
  const int length = static_cast<int>(bytes.size());
  int width = 0, height = 0, channels = 0;
  const auto cannot_decode = [&] {
    if (undecodable) *undecodable = true;
    return Status::error(ErrorCode::kInvalidImage, name, "embedded texture cannot be decoded");
  };
  if (!stbi_info_from_memory(bytes.data(), length, &width, &height, &channels)) return cannot_decode();
  if (Status s = internal::check_image_header(bytes, width, height, options, name); !s)
    return Status::error(ErrorCode::kInvalidImage, name, "embedded texture: " + s.what(), s.where());
  unsigned char* pixels = stbi_load_from_memory(bytes.data(), length, &width, &height, &channels, 0);
  if (!pixels) return cannot_decode();
  image.width = width;
  image.height = height;
  image.channels = channels;
  image.pixels.assign(pixels, pixels + size_t(width) * size_t(height) * size_t(channels));
  stbi_image_free(pixels);
  return Status::ok();
}

Status check_required_extensions(const GltfDocument& doc) {
  const auto required = doc.json().find("extensionsRequired");
  if (required == doc.json().end()) return Status::ok();
  if (!required->is_array()) return doc.parse_error("extensionsRequired is not an array");
  for (const Json& extension : *required) {
    if (!extension.is_string()) return doc.parse_error("extensionsRequired holds a non-string");
    const std::string& name = extension.get_ref<const std::string&>();
    if (std::find(kSupportedExtensions.begin(), kSupportedExtensions.end(), name) == kSupportedExtensions.end())
      return doc.unsupported("required extension " + quote_input(name) +
                             " is not supported (supported: KHR_mesh_quantization, EXT_meshopt_compression, "
                             "KHR_draco_mesh_compression, EXT_mesh_gpu_instancing)");
  }
  return Status::ok();
}

// Appends `p` placed by `world` to `mesh` (UVs per corner, OBJ convention up to a whole repeat:
// t = -v_gltf, see export.h).
void append_instance(const Primitive& p, const Matrix& world, Mesh& mesh) {
  const size_t base = mesh.vertex_count(), first = mesh.indices.size();
  const size_t nv = p.positions.size() / 3;
  mesh.positions.resize(mesh.positions.size() + 3 * nv);
  const bool identity = world == kIdentity;
  for (size_t i = 0; i < nv; ++i) {
    const float* in = &p.positions[3 * i];
    float* out = &mesh.positions[3 * (base + i)];
    if (identity) {
      out[0] = in[0], out[1] = in[1], out[2] = in[2];
      continue;
    }
    for (int r = 0; r < 3; ++r)
      out[r] = static_cast<float>(world[size_t(r)] * in[0] + world[size_t(4 + r)] * in[1] +
                                  world[size_t(8 + r)] * in[2] + world[size_t(12 + r)]);
  }
  const bool mirrored = determinant3(world) < 0;  // keep faces counter-clockwise seen from outside
  mesh.indices.resize(first + p.triangles.size());
  for (size_t c = 0; c < p.triangles.size(); c += 3) {
    const uint32_t b = static_cast<uint32_t>(base);
    mesh.indices[first + c] = b + p.triangles[c];
    mesh.indices[first + c + 1] = b + p.triangles[mirrored ? c + 2 : c + 1];
    mesh.indices[first + c + 2] = b + p.triangles[mirrored ? c + 1 : c + 2];
  }
  mesh.corner_uvs.resize(2 * mesh.indices.size(), 0.0f);
  if (!p.uv.empty()) {
    for (size_t c = first; c < mesh.indices.size(); ++c) {
      const size_t local = mesh.indices[c] - base;
      mesh.corner_uvs[2 * c] = p.uv[2 * local];
      mesh.corner_uvs[2 * c + 1] = -p.uv[2 * local + 1];
    }
  }
}

// The kept attributes of `p`'s corners (appended by append_instance from corner `first` on, with
// vertex ids from `base`): normals turned by the inverse transpose of `world` and renormalized.
// An attribute that an earlier or this primitive lacks is marked in `incomplete` (dropped later).
void append_kept(const Primitive& p, const Matrix& world, size_t base, size_t first, Mesh& mesh,
                 std::vector<uint8_t>& incomplete) {
  const size_t corners = mesh.indices.size();
  // Cofactors of the 3x3 part: det * inverse transpose; the sign of det keeps normals outward.
  const double c[9] = {world[5] * world[10] - world[6] * world[9], world[6] * world[8] - world[4] * world[10],
                       world[4] * world[9] - world[5] * world[8],  world[2] * world[9] - world[1] * world[10],
                       world[0] * world[10] - world[2] * world[8], world[1] * world[8] - world[0] * world[9],
                       world[1] * world[6] - world[2] * world[5],  world[2] * world[4] - world[0] * world[6],
                       world[0] * world[5] - world[1] * world[4]};
  const double sign = determinant3(world) < 0 ? -1.0 : 1.0;
  std::vector<uint8_t> seen(mesh.corner_attributes.size(), 0);
  for (const CornerAttribute& a : p.kept) {
    size_t slot = 0;
    while (slot < mesh.corner_attributes.size() && mesh.corner_attributes[slot].name != a.name) ++slot;
    if (slot == mesh.corner_attributes.size()) {  // new here: zeros before, incomplete unless first
      mesh.corner_attributes.push_back({a.name, a.components, {}});
      incomplete.push_back(first > 0);
      seen.push_back(0);
    }
    seen[slot] = 1;
    CornerAttribute& out = mesh.corner_attributes[slot];
    const size_t k = size_t(a.components);
    out.values.resize(k * corners, 0.0f);
    // Copied where nothing turns them (all but normals and tangents, and those under no transform:
    // most files), else each turned and renormalized: the per-corner loop with a sqrt cost 10 %
    // of loading a large .glb.
    if ((a.name != "NORMAL" && a.name != "TANGENT") || world == kIdentity) {
      const uint32_t* index = mesh.indices.data();
      const float* values = a.values.data();
      float* o = out.values.data();
      if (k == 3) {
        for (size_t corner = first; corner < corners; ++corner)
          std::memcpy(&o[3 * corner], &values[3 * (index[corner] - base)], 12);
      } else {
        for (size_t corner = first; corner < corners; ++corner)
          std::memcpy(&o[k * corner], &values[k * (index[corner] - base)], k * sizeof(float));
      }
      continue;
    }
    for (size_t corner = first; corner < corners; ++corner) {
      const float* in = &a.values[k * (mesh.indices[corner] - base)];
      float* o = &out.values[k * corner];
      if (a.name == "TANGENT") {  // a direction in the surface: the linear part, w flips with a mirror
        double t[3];
        for (int r = 0; r < 3; ++r)
          t[r] = world[size_t(r)] * in[0] + world[size_t(4 + r)] * in[1] + world[size_t(8 + r)] * in[2];
        const double length = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        for (int r = 0; r < 3; ++r) o[r] = length > 0 ? static_cast<float>(t[r] / length) : in[r];
        o[3] = static_cast<float>(sign) * (in[3] < 0 ? -1.0f : 1.0f);
        continue;
      }
      // Column-major: n'_r = sum_j cof[r][j] n_j, with cof stored by columns of the inverse transpose.
      double n[3];
      for (int r = 0; r < 3; ++r) n[r] = sign * (c[3 * 0 + r] * in[0] + c[3 * 1 + r] * in[1] + c[3 * 2 + r] * in[2]);
      const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (int r = 0; r < 3; ++r) o[r] = length > 0 ? static_cast<float>(n[r] / length) : in[r];
    }
  }
  for (size_t slot = 0; slot < seen.size(); ++slot) {
    if (seen[slot]) continue;
    CornerAttribute& out = mesh.corner_attributes[slot];
    out.values.resize(size_t(out.components) * corners, 0.0f);
    incomplete[slot] = 1;
  }
}

// A name member, or "" when absent or not a string.
std::string name_of(const Json* object) {
  if (!object || !object->is_object()) return {};
  const auto it = object->find("name");
  return it != object->end() && it->is_string() ? it->get<std::string>() : std::string();
}

// An extras member as JSON text, or "" when absent.
std::string extras_of(const Json* object) {
  if (!object || !object->is_object()) return {};
  const auto it = object->find("extras");
  return it != object->end() ? it->dump(-1, ' ', false, Json::error_handler_t::replace) : std::string();
}

// The properties of material `index` that the output can carry, checked so that what is
// written back is valid glTF; what is left out (textures, extensions) goes to `lost`.
std::string kept_material(const Json& material, std::vector<std::string>& lost) {
  auto note = [&](const char* what) {
    if (std::find(lost.begin(), lost.end(), what) == lost.end()) lost.emplace_back(what);
  };
  auto numbers = [](const Json& j, size_t n) {
    return j.is_array() && j.size() == n &&
           std::all_of(j.begin(), j.end(), [](const Json& x) { return x.is_number(); });
  };
  Json out = Json::object();
  if (!material.is_object()) return out.dump();
  for (const auto& item : material.items()) {
    const std::string& key = item.key();
    const Json& v = item.value();
    if ((key == "name" && v.is_string()) || key == "extras" || (key == "doubleSided" && v.is_boolean()) ||
        (key == "alphaCutoff" && v.is_number() && v.get<double>() >= 0) ||
        (key == "alphaMode" && v.is_string() && (v == "OPAQUE" || v == "MASK" || v == "BLEND")) ||
        (key == "emissiveFactor" && numbers(v, 3))) {
      out[key] = v;
    } else if (key == "pbrMetallicRoughness" && v.is_object()) {
      Json pbr = Json::object();
      for (const auto& p : v.items()) {
        if ((p.key() == "baseColorFactor" && numbers(p.value(), 4)) ||
            ((p.key() == "metallicFactor" || p.key() == "roughnessFactor") && p.value().is_number()))
          pbr[p.key()] = p.value();
        else if (p.key().ends_with("Texture"))
          note("material textures (tailor writes its own)");
        else if (p.key() == "extras")
          pbr[p.key()] = p.value();
        else
          note("material extensions");
      }
      out[key] = pbr;
    } else if (key.ends_with("Texture")) {
      note("material textures (tailor writes its own)");
    } else if (key == "extensions") {
      note("material extensions");
    }
  }
  return out.dump(-1, ' ', false, Json::error_handler_t::replace);
}

// True when node `index` has no transform (or the identity), no children and no GPU instances.
bool plain_leaf(const Json& json, const Json& index) {
  const Json* node = index.is_number_unsigned() ? get_element(json, "nodes", index.get<uint64_t>()) : nullptr;
  Matrix local;
  return node && !node->contains("children") && !node->contains("extensions") && local_transform(*node, local) &&
         local == kIdentity;
}

// True when the default scene is laid out as tailor writes it (src/export/glb_scene.cpp): one root
// node whose transform is at most a translation, a uniform scale and the quarter turn of --up z,
// and whose children are plain leaves (one per mesh instance). Re-mapped, such a file gets that
// layout again (the root's transform baked into world space, or written anew by --up z and
// --compress), so its hierarchy is not reported as lost.
bool tailor_layout(const Json& json) {
  uint64_t scene = 0;
  get_uint(json, "scene", scene);
  const Json* root_scene = get_element(json, "scenes", scene);
  const auto roots = root_scene ? root_scene->find("nodes") : json.end();
  if (!root_scene || roots == root_scene->end() || !roots->is_array() || roots->size() != 1) return false;
  const Json& root_index = (*roots)[0];
  const Json* root = root_index.is_number_unsigned() ? get_element(json, "nodes", root_index.get<uint64_t>()) : nullptr;
  if (!root || root->contains("matrix") || root->contains("extensions")) return false;
  double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
  bool present = false;
  if (!get_numbers(*root, "translation", t, 3, present) || !get_numbers(*root, "rotation", q, 4, present) ||
      !get_numbers(*root, "scale", s, 3, present) || !(s[0] > 0) || s[1] != s[0] || s[2] != s[0])
    return false;
  // The --up z rotation, -90 degrees about x, as write_glb writes it (%.9g).
  constexpr double kTolerance = 1e-6, kHalfSqrt2 = 0.70710678118654752;
  const bool identity = q[0] == 0 && q[1] == 0 && q[2] == 0 && q[3] == 1;
  const bool up_z =
      std::abs(q[0] + kHalfSqrt2) < kTolerance && q[1] == 0 && q[2] == 0 && std::abs(q[3] - kHalfSqrt2) < kTolerance;
  if (!identity && !up_z) return false;
  const auto children = root->find("children");
  if (children == root->end()) return true;
  if (!children->is_array() || root->contains("mesh")) return false;
  return std::all_of(children->begin(), children->end(), [&](const Json& child) { return plain_leaf(json, child); });
}

// What the output cannot carry: material textures and extensions (see kept_material), extras of
// other objects, attributes other than the kept ones, skins, animations, cameras; the node
// hierarchy is written flat (one node per mesh instance, in world space).
void not_kept(const GltfDocument& doc, const std::vector<Instance>& instances, std::vector<std::string>& lost) {
  const Json& json = doc.json();
  auto any = [&](const char* array, auto&& predicate) {
    const auto it = json.find(array);
    if (it == json.end() || !it->is_array()) return false;
    return std::any_of(it->begin(), it->end(), predicate);
  };
  auto non_empty = [&](const char* array) { return any(array, [](const Json&) { return true; }); };
  std::vector<std::string> attributes;
  bool primitive_extras = false;
  const auto meshes = json.find("meshes");
  if (meshes != json.end() && meshes->is_array())
    for (const Json& m : *meshes) {
      const auto primitives = m.is_object() ? m.find("primitives") : m.end();
      if (!m.is_object() || primitives == m.end() || !primitives->is_array()) continue;
      for (const Json& prim : *primitives) {
        const auto a = prim.is_object() ? prim.find("attributes") : prim.end();
        if (!prim.is_object() || a == prim.end() || !a->is_object()) continue;
        primitive_extras = primitive_extras || prim.contains("extras") || prim.contains("targets");
        for (const auto& item : a->items())
          if (item.key() != "POSITION" && item.key() != "TEXCOORD_0" && !is_kept_attribute(item.key()) &&
              std::find(attributes.begin(), attributes.end(), item.key()) == attributes.end())
            attributes.push_back(item.key());
      }
    }
  lost.insert(lost.end(), attributes.begin(), attributes.end());
  if (primitive_extras) lost.push_back("primitive extras and morph targets");
  for (const char* array : {"skins", "animations", "cameras"})
    if (non_empty(array)) lost.push_back(array);
  const bool moved =
      std::any_of(instances.begin(), instances.end(), [](const Instance& i) { return i.world != kIdentity; });
  if ((moved || any("nodes", [](const Json& n) { return n.is_object() && n.contains("children"); })) &&
      !tailor_layout(json))
    lost.push_back("node transforms and hierarchy (one node per mesh instance, in world space)");
}

// The encoded images of the first textured material's other maps (read_glb_with_material).
struct MaterialBytes {
  std::string normal, occlusion, metallic_roughness;
};

// Parses the file into mesh (not finalized); the base colour texture bytes go to `texture_bytes`,
// the other maps of the same material to `material` (which also keeps TANGENT in the mesh's
// corner attributes).
Status parse_gltf(std::span<const char> data, const std::string& name, const std::string& base_dir, Mesh& mesh,
                  LoadReport& report, std::string* texture_bytes, internal::ReadProgress* progress,
                  MaterialBytes* material = nullptr) {
  GltfDocument doc;
  TAILOR_RETURN_IF_ERROR(doc.open(data, name, base_dir));
  doc.set_progress(progress);  // in bytes of accessor data (about the file's size, more when compressed)
  report.format = doc.is_binary() ? "glTF binary" : "glTF";
  TAILOR_RETURN_IF_ERROR(check_required_extensions(doc));
  const auto used = doc.json().find("extensionsUsed");
  if (used != doc.json().end() && used->is_array())
    for (const Json& e : *used)
      if (e.is_string() && std::find(kSupportedExtensions.begin(), kSupportedExtensions.end(), e.get<std::string>()) !=
                               kSupportedExtensions.end())
        report.format += " + " + e.get<std::string>();

  std::vector<Instance> instances;
  TAILOR_RETURN_IF_ERROR(scene_instances(doc, instances));
  static const Json kNoMeshes = Json::array();
  const auto meshes_it = doc.json().find("meshes");
  const Json& meshes = meshes_it != doc.json().end() && meshes_it->is_array() ? *meshes_it : kNoMeshes;
  // Each mesh is decoded once, however many nodes use it.
  std::vector<std::optional<std::vector<Primitive>>> decoded(meshes.size());
  size_t triangle_primitives = 0, with_uv = 0, without_uv_faces = 0;
  std::string without_uv;  // the first triangle primitive without UVs
  bool texture_found = false;
  uint64_t first_image = UINT64_MAX;  // the first base colour texture's image, embedded or not
  bool symmetry_read = false;         // report.texture_symmetry: of the first material, until a texture's
  std::vector<uint8_t> incomplete;    // per mesh.corner_attributes: missing on some primitive
  std::vector<std::string> lost;
  // Names, extras and materials of what the faces came from (Mesh::scene, Mesh::face_parts).
  SceneParts& scene = mesh.scene;
  const Json* asset = doc.json().contains("asset") ? &doc.json()["asset"] : nullptr;
  scene.asset_extras = extras_of(asset);
  if (asset && asset->is_object() && asset->contains("copyright") && (*asset)["copyright"].is_string())
    scene.asset_copyright = (*asset)["copyright"].get<std::string>();
  {
    uint64_t scene_index = 0;
    get_uint(doc.json(), "scene", scene_index);
    const Json* root = get_element(doc.json(), "scenes", scene_index);
    scene.scene_name = name_of(root);
    scene.scene_extras = extras_of(root);
  }
  const auto materials_it = doc.json().find("materials");
  const size_t material_count = materials_it != doc.json().end() && materials_it->is_array() ? materials_it->size() : 0;
  std::vector<uint32_t> material_slot(material_count, kInvalid);  // input material -> scene.materials
  size_t collapsed = 0;  // instances flattened to a line or a point (a zero scale hides a node)
  uint64_t first_collapsed = UINT64_MAX;
  for (const Instance& instance : instances) {
    const size_t mi = instance.mesh;
    const Json& m = meshes[mi];
    const Json* node = instance.node == UINT64_MAX ? nullptr : get_element(doc.json(), "nodes", instance.node);
    const uint32_t instance_id = static_cast<uint32_t>(scene.instances.size());
    const size_t first_part = scene.parts.size();
    scene.instances.push_back({name_of(node), extras_of(node), name_of(&m), extras_of(&m)});
    // Each instance keeps its own copy of these texts: charged, so that a long mesh name or extras
    // under thousands of instances cannot grow memory past the file's bound.
    const auto& kept_texts = scene.instances.back();
    TAILOR_RETURN_IF_ERROR(doc.charge(kept_texts.node_name.size() + kept_texts.node_extras.size() +
                                          kept_texts.mesh_name.size() + kept_texts.mesh_extras.size(),
                                      "mesh " + std::to_string(mi)));
    // No face of it would have an area: the welding would drop every one as naming a vertex twice,
    // which does not say why. Its faces are skipped and named; it keeps its name as a node.
    if (flattens_to_a_line(instance.world)) {
      if (collapsed++ == 0) first_collapsed = instance.node;
      ++report.mesh_instances;
      continue;
    }
    const auto primitives = m.is_object() ? m.find("primitives") : m.end();
    if (!m.is_object() || primitives == m.end() || !primitives->is_array())
      return doc.parse_error("mesh without primitives", "mesh " + std::to_string(mi));
    const bool first_use = !decoded[mi].has_value();
    if (first_use) {
      decoded[mi].emplace();
      for (size_t pi = 0; pi < primitives->size(); ++pi) {
        const Json& prim = (*primitives)[pi];
        const std::string where = "mesh " + std::to_string(mi) + " primitive " + std::to_string(pi);
        if (!prim.is_object()) return doc.parse_error("primitive is not an object", where);
        uint64_t mode = kTriangles;
        if (prim.contains("mode") && !get_uint(prim, "mode", mode)) return doc.parse_error("bad primitive mode", where);
        if (mode < kTriangles) continue;  // counted per instance below
        if (mode > kFan) return doc.parse_error("unknown primitive mode " + std::to_string(mode), where);
        decoded[mi]->emplace_back().index = pi;
        TAILOR_RETURN_IF_ERROR(read_primitive(doc, prim, mode, where, material != nullptr, decoded[mi]->back()));
      }
    }
    for (const Json& prim : *primitives) {
      uint64_t mode = kTriangles;
      if (get_uint(prim, "mode", mode) && mode < kTriangles) ++report.skipped_primitives;
    }
    ++report.mesh_instances;
    for (const Primitive& p : *decoded[mi]) {
      const std::string where = "mesh " + std::to_string(mi);
      const size_t nv = p.positions.size() / 3, nf = p.triangles.size() / 3;
      if (mesh.vertex_count() + nv > kMaxVertices || mesh.face_count() + nf > kMaxFaces)
        return Status::error(ErrorCode::kLimit, name, "too many vertices or faces", where);
      TAILOR_RETURN_IF_ERROR(doc.charge(12 * nv + 40 * nf, where));  // positions, indices, corner UVs, parts
      uint32_t kept_slot = kInvalid;                                 // the part's material in scene.materials
      if (p.material < material_count) {
        if (material_slot[p.material] == kInvalid) {
          material_slot[p.material] = static_cast<uint32_t>(scene.materials.size());
          scene.materials.push_back(kept_material((*materials_it)[p.material], lost));
        }
        kept_slot = material_slot[p.material];
      }
      size_t part = first_part;
      while (part < scene.parts.size() && scene.parts[part].material != kept_slot) ++part;
      if (part == scene.parts.size()) scene.parts.push_back({instance_id, kept_slot});
      mesh.face_parts.resize(mesh.face_count() + nf, static_cast<uint32_t>(part));
      const size_t base = mesh.vertex_count(), first = mesh.indices.size();
      append_instance(p, instance.world, mesh);
      append_kept(p, instance.world, base, first, mesh, incomplete);
      ++triangle_primitives;
      with_uv += !p.uv.empty();
      if (p.uv.empty()) {
        without_uv_faces += nf;
        if (without_uv.empty()) {
          const std::string mesh_name = name_of(&m);
          without_uv = "mesh " + std::to_string(mi) + (mesh_name.empty() ? "" : " " + quote_input(mesh_name)) +
                       " primitive " + std::to_string(p.index);
        }
      }
      report.source_faces += p.source_faces;
      if (p.material != UINT64_MAX && base_colour_transformed(doc.json(), p.material)) report.texture_transform = true;
      // A 4-fold map's record is in its material: the textured one's, or without a texture the first.
      if (!symmetry_read && p.material != UINT64_MAX) {
        report.texture_symmetry = material_symmetry(doc, p.material);
        symmetry_read = true;
      }
      if (texture_bytes && first_image == UINT64_MAX && p.material != UINT64_MAX)
        first_image = texture_image(doc, p.material, "baseColorTexture");
      if (texture_bytes && !texture_found && p.material != UINT64_MAX) {
        find_texture(doc, p.material, "baseColorTexture", *texture_bytes);
        texture_found = !texture_bytes->empty();
        if (texture_found) report.texture_symmetry = material_symmetry(doc, p.material);
        if (material) {
          find_texture(doc, p.material, "normalTexture", material->normal);
          find_texture(doc, p.material, "occlusionTexture", material->occlusion);
          find_texture(doc, p.material, "metallicRoughnessTexture", material->metallic_roughness);
          // A material without a colour map but with others: its maps still count.
          texture_found = texture_found || !material->normal.empty();
        }
      }
    }
  }
  const std::string collapsed_text =
      collapsed == 0 ? ""
                     : std::to_string(collapsed) + (collapsed == 1 ? " mesh instance" : " mesh instances") +
                           " under a transform that flattens it to a line or a point (node " +
                           std::to_string(first_collapsed) + (collapsed == 1 ? ")" : ", ...)");
  if (triangle_primitives == 0 && collapsed > 0)
    return Status::error(ErrorCode::kInvalidMesh, name, "no face with an area in the scene: " + collapsed_text);
  if (collapsed > 0) lost.push_back(collapsed_text);
  if (triangle_primitives == 0)
    return Status::error(ErrorCode::kUnsupported, name,
                         report.skipped_primitives
                             ? "no triangles in the scene (only " + std::to_string(report.skipped_primitives) +
                                   " point and line primitives)"
                             : std::string("no triangle primitive in the scene"));
  // All or nothing: UVs are only meaningful when every primitive has them; the same for the rest.
  if (with_uv != triangle_primitives) mesh.corner_uvs.clear();
  if (with_uv > 0 && with_uv != triangle_primitives) {  // some have them: say which lacks them
    report.faces_without_uv = without_uv_faces;
    report.primitive_without_uv = without_uv;
  }
  for (size_t slot = mesh.corner_attributes.size(); slot-- > 0;) {
    if (!incomplete[slot]) continue;
    lost.push_back(mesh.corner_attributes[slot].name + " (not on every primitive)");
    mesh.corner_attributes.erase(mesh.corner_attributes.begin() + static_cast<std::ptrdiff_t>(slot));
  }
  not_kept(doc, instances, lost);
  for (const std::string& item : lost) report.not_kept += (report.not_kept.empty() ? "" : ", ") + item;
  // The texture's size from its header, never decoded, whatever its size: the embedded texture's
  // (the one decoded when asked), else the first base colour image given by a URI (a data: URI, or a
  // file next to the .gltf, of which only the first bytes are read).
  if (texture_bytes) {
    if (first_image != UINT64_MAX) {  // its file when a URI names one beside the .gltf
      report.texture_named = doc.image_file(first_image);
      if (report.texture_named.empty()) report.texture_named = "image " + std::to_string(first_image);
    }
    long width = 0, height = 0;
    bool sized = !texture_bytes->empty() && internal::image_header_size(as_bytes(*texture_bytes), width, height, false);
    if (!sized && texture_bytes->empty() && first_image != UINT64_MAX) {
      std::string head;
      bool file = false;
      for (const size_t max_bytes : {size_t{64} << 10, size_t{16} << 20}) {  // a JPEG's frame header may lie far in
        if (!doc.image_uri_bytes(first_image, max_bytes, head, file)) break;
        sized = internal::image_header_size(as_bytes(head), width, height, false);
        if (sized || head.size() < max_bytes) break;
      }
      report.texture_file = sized && file;
      if (report.texture_file) report.texture_path = doc.image_file(first_image);  // what render draws
    }
    if (sized && width <= INT_MAX && height <= INT_MAX) {
      report.texture_width = static_cast<int>(width);
      report.texture_height = static_cast<int>(height);
    } else {
      report.texture_file = false;
    }
  }
  // glTF splits vertices on UV seams; weld them so that seams are edges between faces again. A face
  // whose corners were distinct vertices at one position then repeats one (finalize_mesh drops it):
  // counted apart from the file's own degenerate faces.
  const auto repeating = [&mesh] {
    size_t count = 0;
    for (size_t f = 0; f < mesh.face_count(); ++f) {
      const uint32_t* v = &mesh.indices[3 * f];
      count += v[0] == v[1] || v[1] == v[2] || v[2] == v[0];
    }
    return count;
  };
  const size_t repeating_before = repeating();
  report.welded_vertices = weld_identical_positions(mesh);
  if (report.welded_vertices > 0) report.faces_collapsed_by_weld = repeating() - repeating_before;
  return Status::ok();
}

std::string folder_of(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

}  // namespace

namespace internal {

Status read_gltf(std::span<const char> data, const std::string& name, const std::string& base_dir, Mesh& mesh,
                 LoadReport& report, ReadProgress* progress) {
  return parse_gltf(data, name, base_dir, mesh, report, nullptr, progress);
}

}  // namespace internal

namespace {

Status read_gltf_with_texture(std::span<const char> data, const std::string& name, const std::string& base_dir,
                              Mesh& mesh, Image* texture, LoadReport* report, GltfMaterialMaps* material,
                              const ImageLoadOptions& image_options) {
  mesh = Mesh{};
  if (texture) *texture = Image{};
  if (material) *material = GltfMaterialMaps{};
  LoadReport local;
  LoadReport& r = report ? *report : local;
  r = LoadReport{};
  r.file_bytes = data.size();
  Status s;
  try {
    std::string texture_bytes;
    MaterialBytes material_bytes;
    s = parse_gltf(data, name, base_dir, mesh, r, &texture_bytes, nullptr, material ? &material_bytes : nullptr);
    if (s.is_ok()) s = finalize_mesh(name, mesh, r);
    if (s.is_ok() && material) {
      // TANGENT went through the repairs with the other corner attributes; it is not written back.
      for (size_t slot = 0; slot < mesh.corner_attributes.size(); ++slot) {
        if (mesh.corner_attributes[slot].name != "TANGENT") continue;
        material->corner_tangents = std::move(mesh.corner_attributes[slot].values);
        mesh.corner_attributes.erase(mesh.corner_attributes.begin() + static_cast<std::ptrdiff_t>(slot));
        break;
      }
      const std::pair<const std::string&, Image*> maps[] = {
          {material_bytes.normal, &material->normal},
          {material_bytes.occlusion, &material->occlusion},
          {material_bytes.metallic_roughness, &material->metallic_roughness}};
      for (const auto& [bytes, image] : maps)
        if (s.is_ok() && !bytes.empty()) s = decode_texture(as_bytes(bytes), name, image_options, *image);
    }
    if (s.is_ok() && texture && !texture_bytes.empty()) {
      // A base colour image that does not decode leaves the mesh good (its UVs are what eval
      // measures and render draws a checker on): noted, not fatal. Over the limits stays an error.
      bool undecodable = false;
      s = decode_texture(as_bytes(texture_bytes), name, image_options, *texture, &undecodable);
      if (undecodable) {
        r.texture_problem = s.what();
        s = Status::ok();
      }
    }
  } catch (const std::bad_alloc&) {
    s = Status::error(ErrorCode::kLimit, name, "not enough memory to load the mesh");
  } catch (...) {
    s = Status::error(ErrorCode::kParse, name, "unexpected failure while parsing");
  }
  if (!s.is_ok()) {
    mesh = Mesh{};
    if (texture) *texture = Image{};
    if (material) *material = GltfMaterialMaps{};
    return s.with_file(name);
  }
  return s;
}

}  // namespace

Status read_glb_memory(std::span<const char> data, const std::string& name, Mesh& mesh, Image* texture,
                       LoadReport* report, const ImageLoadOptions& image_options) {
  return read_gltf_with_texture(data, name, "", mesh, texture, report, nullptr, image_options);
}

Status read_glb_file(const std::string& path, Mesh& mesh, Image* texture, LoadReport* report,
                     const ImageLoadOptions& image_options) {
  return read_glb_with_material(path, mesh, texture, nullptr, report, image_options);
}

Status read_glb_with_material(const std::string& path, Mesh& mesh, Image* texture, GltfMaterialMaps* material,
                              LoadReport* report, const ImageLoadOptions& image_options) {
  const auto start = std::chrono::steady_clock::now();
  mesh = Mesh{};
  if (material) *material = GltfMaterialMaps{};
  std::string bytes;
  TAILOR_RETURN_IF_ERROR(internal::read_file(path, bytes));
  LoadReport local;
  LoadReport& r = report ? *report : local;
  const Status s = read_gltf_with_texture(bytes, path, folder_of(path), mesh, texture, &r, material, image_options);
  r.load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return s;
}

}  // namespace tailor
