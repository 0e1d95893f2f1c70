// tailor.save: export_mesh, the writer of `tailor map -o` (.glb .obj .ply, atomic).
#include "bindings.h"
#include "tailor/export.h"
#include "tailor/material.h"

namespace tailor::python {

void bind_save(py::module_& m) {
  m.def(
      "save",
      [](const py::object& path_object, const PyMesh& mesh, const PyResult& result, const py::object& texture,
         const py::object& material) {
        const std::string path = path_of(path_object);
        if (result.atlas.patch.size() != mesh.mesh.face_count())
          raise_error("the result has " + std::to_string(result.atlas.patch.size()) + " faces, the mesh " +
                      std::to_string(mesh.mesh.face_count()) + ": save the mesh that was mapped");
        if (!texture.is_none() && !material.is_none())
          raise_error("give texture= or material=, not both (the material's colour map is the texture)");
        std::string ext = path.size() >= 4 ? path.substr(path.size() - 4) : "";
        for (char& c : ext) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
        // The material: the one given, else map()'s when no texture is given and the file is a .glb
        // (an .obj or .ply written after map(material=...) gets the colour map, as a texture).
        const std::string material_path = !material.is_none()                  ? path_of(material)
                                          : texture.is_none() && ext == ".glb" ? result.material
                                                                               : "";
        if (!material.is_none() && ext != ".glb") raise_error("material= needs a .glb output, got '" + path + "'");
        ExportOptions options;
        options.texture_path = texture.is_none() ? result.texture : path_of(texture);
        options.texture_width = result.texture_width;
        options.texture_height = result.texture_height;
        options.symmetry = result.symmetry;
        Status status;
        {
          const py::gil_scoped_release release;
          if (!material_path.empty()) {
            MaterialMaps maps;
            status = load_material(material_path, maps);
            if (status && (maps.width != result.texture_width || maps.height != result.texture_height))
              status = Status::error(ErrorCode::kInvalidArgument, material_path,
                                     "material is " + std::to_string(maps.width) + "x" + std::to_string(maps.height) +
                                         " but the result was mapped for " + std::to_string(result.texture_width) +
                                         "x" + std::to_string(result.texture_height));
            options.texture_path = maps.color;
            options.material = std::move(maps.textures);
          }
          if (status) status = export_mesh(path, mesh.mesh, result.atlas, options);
        }
        if (!status) raise_status(status);
      },
      py::arg("path"), py::arg("mesh"), py::arg("result"), py::arg("texture") = py::none(),
      py::arg("material") = py::none(),
      R"(save(path, mesh, result, texture=None, material=None) -> None

Writes the mesh with the result's UVs as `tailor map -o` does: .glb (texture embedded byte for
byte, sampler REPEAT), .obj (+ .mtl naming the texture) or .ply (binary, per-vertex s t after
splitting vertices on their UVs). texture: a PNG or JPEG file; None = the texture given to map()
(if any). material: a PBR material folder or JSON as `tailor map --material` (.glb only: base
colour, normal map with tangents, metallicRoughness, occlusion); None = the material given to
map() for a .glb (an .obj or .ply gets its colour map). The file is written atomically (nothing
is left on failure). The GIL is released.)");

  m.def(
      "material_role",
      [](const std::string& file_name) -> py::tuple {
        static const char* kNames[] = {nullptr, "color", "normal", "roughness", "metallic", "occlusion", "height"};
        bool directx = false;
        const MaterialRole role = material_role_from_name(file_name, &directx);
        const char* name = kNames[static_cast<int>(role)];
        return py::make_tuple(name ? py::object(py::str(name)) : py::object(py::none()), directx);
      },
      py::arg("file_name"),
      R"(material_role(file_name) -> (role, directx)

The role `tailor map --material FOLDER` gives a file by its name's suffix (docs/formats.md):
'color', 'normal', 'roughness', 'metallic', 'occlusion', 'height', or None; directx is True for a
normal map named *_normal_dx (DirectX convention, green down).)");
}

}  // namespace tailor::python
