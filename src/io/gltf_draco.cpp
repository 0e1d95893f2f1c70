// KHR_draco_mesh_compression: a primitive's triangles and attributes decoded by Debian's libdraco.
// Reference: the extension's specification (attributes map glTF names to Draco unique ids; the
// primitive's accessors keep their count, type and min/max but have no buffer view).
#include <draco/compression/decode.h>

#include "io/gltf_document.h"

namespace tailor::internal {

Status decode_draco_primitive(GltfDocument& doc, const Json& primitive, const Json& extension,
                              const std::vector<std::string>& names, const std::string& where, DracoPrimitive& out) {
  const std::string here = where + " (KHR_draco_mesh_compression)";
  uint64_t view = 0, position = 0, indices_accessor = 0;
  const auto attributes = extension.find("attributes");
  const auto primitive_attributes = primitive.find("attributes");
  if (!get_uint(extension, "bufferView", view) || attributes == extension.end() || !attributes->is_object() ||
      primitive_attributes == primitive.end() || !get_uint(*primitive_attributes, "POSITION", position))
    return doc.parse_error("missing bufferView, attributes or POSITION", here);
  // What the file declares is what is charged before Draco allocates anything.
  AccessorInfo points, corners;
  TAILOR_RETURN_IF_ERROR(doc.accessor_info(position, points));
  const bool indexed = get_uint(primitive, "indices", indices_accessor);
  if (indexed) TAILOR_RETURN_IF_ERROR(doc.accessor_info(indices_accessor, corners));
  TAILOR_RETURN_IF_ERROR(doc.charge(points.count * 16 * names.size() + corners.count * 4, here));

  std::span<const unsigned char> bytes;
  uint64_t stride = 0;
  TAILOR_RETURN_IF_ERROR(doc.view_bytes(view, bytes, stride));
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok())
    return doc.parse_error("Draco data cannot be decoded: " + decoded.status().error_msg_string(), here);
  const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  if (!mesh) return doc.parse_error("Draco data holds no mesh", here);
  const size_t point_count = mesh->num_points(), face_count = mesh->num_faces();
  if (point_count != points.count || (indexed && 3 * face_count != corners.count))
    return doc.parse_error("Draco data holds " + std::to_string(point_count) + " points and " +
                               std::to_string(face_count) + " faces, the accessors say otherwise",
                           here);
  out.indices.resize(3 * face_count);
  for (size_t f = 0; f < face_count; ++f) {
    const auto& face = mesh->face(draco::FaceIndex(static_cast<uint32_t>(f)));
    for (int k = 0; k < 3; ++k) {
      const uint32_t p = face[k].value();
      if (p >= point_count) return doc.parse_error("Draco face index out of range", here);
      out.indices[3 * f + size_t(k)] = p;
    }
  }
  out.values.assign(names.size(), {});
  out.components.assign(names.size(), 0);
  for (size_t n = 0; n < names.size(); ++n) {
    uint64_t id = 0;
    if (!get_uint(*attributes, names[n].c_str(), id)) continue;
    const draco::PointAttribute* attribute =
        id <= INT32_MAX ? mesh->GetAttributeByUniqueId(static_cast<uint32_t>(id)) : nullptr;
    if (!attribute)
      return doc.parse_error("Draco data has no attribute " + std::to_string(id) + " for " + names[n], here);
    const int components = attribute->num_components();
    if (components < 1 || components > 4)
      return doc.parse_error(names[n] + " has " + std::to_string(components) + " components", here);
    std::vector<float>& values = out.values[n];
    values.resize(point_count * size_t(components));
    for (size_t p = 0; p < point_count; ++p) {
      const auto value = attribute->mapped_index(draco::PointIndex(static_cast<uint32_t>(p)));
      if (value.value() >= attribute->size() ||
          !attribute->ConvertValue<float>(value, static_cast<int8_t>(components), &values[p * size_t(components)]))
        return doc.parse_error("Draco attribute " + names[n] + " cannot be read", here);
    }
    out.components[n] = components;
  }
  return Status::ok();
}

}  // namespace tailor::internal
