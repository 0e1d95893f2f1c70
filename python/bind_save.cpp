// tailor.save: export_mesh, the writer of `tailor map -o` (.glb .obj .ply, atomic).
#include "bindings.h"
#include "tailor/export.h"

namespace tailor::python {

void bind_save(py::module_& m) {
  m.def(
      "save",
      [](const py::object& path_object, const PyMesh& mesh, const PyResult& result, const py::object& texture) {
        const std::string path = path_of(path_object);
        if (result.atlas.patch.size() != mesh.mesh.face_count())
          raise_error("the result has " + std::to_string(result.atlas.patch.size()) + " faces, the mesh " +
                      std::to_string(mesh.mesh.face_count()) + ": save the mesh that was mapped");
        ExportOptions options;
        options.texture_path = texture.is_none() ? result.texture : path_of(texture);
        options.texture_width = result.texture_width;
        options.texture_height = result.texture_height;
        Status status;
        {
          const py::gil_scoped_release release;
          status = export_mesh(path, mesh.mesh, result.atlas, options);
        }
        if (!status) raise_status(status);
      },
      py::arg("path"), py::arg("mesh"), py::arg("result"), py::arg("texture") = py::none(),
      R"(save(path, mesh, result, texture=None) -> None

Writes the mesh with the result's UVs as `tailor map -o` does: .glb (texture embedded byte for
byte, sampler REPEAT), .obj (+ .mtl naming the texture) or .ply (binary, per-vertex s t after
splitting vertices on their UVs). texture: a PNG or JPEG file; None = the texture given to map()
(if any). The file is written atomically (nothing is left on failure). The GIL is released.)");
}

}  // namespace tailor::python
