// The scene part of a .glb's JSON: nodes, meshes, materials, the scene and the asset. Without a
// glTF scene behind the mesh: one node "tailor" with one mesh and tailor's material. With one
// (Mesh::scene): a root node "tailor" that carries the file's transform, and under it one node per
// input mesh instance with its name and extras, holding a mesh with the input mesh's name and
// extras whose primitives are the instance's faces per input material (world space, so the
// children have no transform of their own); each input material keeps its properties and gets
// tailor's maps; the scene's and the asset's name, copyright and extras are written back.
#include <nlohmann/json.hpp>

#include "export/writers.h"
#include "util/bounded_json.h"

namespace tailor::internal {
namespace {

using Json = nlohmann::json;

// `text` (JSON kept by the reader) as a value, or null when empty or unreadable.
Json parsed(const std::string& text) {
  if (text.empty()) return nullptr;
  Json j;
  return internal::parse_json_bounded(text, j) == internal::JsonParse::kOk ? j : Json(nullptr);
}

// Sets object[key] to the JSON text `text` when it holds a value.
void set_kept(Json& object, const char* key, const std::string& text) {
  Json value = parsed(text);
  if (!value.is_null()) object[key] = std::move(value);
}

// An input material (kept properties) with tailor's maps (from `own`, tailor's material) added:
// the textures replace the input's (which the reader did not keep); the factors stay the input's.
Json merged_material(const std::string& kept, const Json& own) {
  Json m = parsed(kept);
  if (!m.is_object()) m = Json::object();
  for (const char* key : {"normalTexture", "occlusionTexture"})
    if (own.contains(key)) m[key] = own[key];
  const Json& pbr = own["pbrMetallicRoughness"];
  for (const char* key : {"baseColorTexture", "metallicRoughnessTexture"})
    if (pbr.contains(key)) m["pbrMetallicRoughness"][key] = pbr[key];
  // tailor's record of a 4-fold map (add_glb_material) is this map's, not the input's.
  if (m.contains("extras") && m["extras"].is_object()) {
    m["extras"].erase("tailor");
    if (m["extras"].empty()) m.erase("extras");
  }
  if (own.contains("extras") && own["extras"].contains("tailor")) {
    if (!m.contains("extras")) m["extras"] = Json::object();
    m["extras"]["tailor"] = own["extras"]["tailor"];
  }
  return m;
}

}  // namespace

void add_glb_scene(Json& gltf, const ExportData& data, Json root, std::vector<Json> primitives) {
  gltf["asset"] = {{"version", "2.0"}, {"generator", "tailor"}};
  gltf["scene"] = 0;
  const SceneParts* scene = data.scene;
  if (!scene || data.parts.empty()) {
    for (Json& p : primitives) p["material"] = 0;
    root["mesh"] = 0;
    gltf["nodes"] = {root};
    gltf["meshes"] = {{{"primitives", primitives}}};
    gltf["scenes"] = {{{"nodes", {0}}}};
    return;
  }
  // Materials: the input's used ones, in order, then tailor's own for faces that had none.
  const Json own = gltf["materials"][0];
  Json materials = Json::array();
  for (const std::string& kept : scene->materials) materials.push_back(merged_material(kept, own));
  size_t own_index = SIZE_MAX;
  Json meshes = Json::array(), nodes = Json::array({root}), children = Json::array();
  std::vector<size_t> mesh_of(scene->instances.size(), SIZE_MAX);
  for (size_t i = 0; i < data.parts.size(); ++i) {
    const SceneParts::Part& part = scene->parts[data.parts[i].part];
    Json& p = primitives[i];
    if (part.material != kInvalid) {
      p["material"] = part.material;
    } else {
      if (own_index == SIZE_MAX) {
        own_index = materials.size();
        materials.push_back(own);
      }
      p["material"] = own_index;
    }
    size_t& m = mesh_of[part.instance];
    if (m == SIZE_MAX) {
      m = meshes.size();
      const SceneParts::Instance& instance = scene->instances[part.instance];
      Json mesh = {{"primitives", Json::array()}};
      if (!instance.mesh_name.empty()) mesh["name"] = instance.mesh_name;
      set_kept(mesh, "extras", instance.mesh_extras);
      meshes.push_back(std::move(mesh));
    }
    meshes[m]["primitives"].push_back(std::move(p));
  }
  // One node per instance (those whose faces were all dropped keep their name, without a mesh).
  for (size_t i = 0; i < scene->instances.size(); ++i) {
    const SceneParts::Instance& instance = scene->instances[i];
    Json node = Json::object();
    if (!instance.node_name.empty()) node["name"] = instance.node_name;
    set_kept(node, "extras", instance.node_extras);
    if (mesh_of[i] != SIZE_MAX) node["mesh"] = mesh_of[i];
    children.push_back(nodes.size());
    nodes.push_back(std::move(node));
  }
  nodes[0]["children"] = children;
  gltf["nodes"] = nodes;
  gltf["meshes"] = meshes;
  gltf["materials"] = materials;
  Json s = {{"nodes", {0}}};
  if (!scene->scene_name.empty()) s["name"] = scene->scene_name;
  set_kept(s, "extras", scene->scene_extras);
  gltf["scenes"] = {s};
  if (!scene->asset_copyright.empty()) gltf["asset"]["copyright"] = scene->asset_copyright;
  set_kept(gltf["asset"], "extras", scene->asset_extras);
}

}  // namespace tailor::internal
