// tailor.plan_chunks and tailor.save_uvs: the chunk rule and the writer of `tailor map -o` for
// code that cuts a mesh into tiles itself (python -m tailor.tiles): the rule's cells and faces as
// arrays, and any mesh written with per-corner UVs in texture pixels (as ChunkedMapper gives them).
#include <cstring>

#include "bindings.h"
#include "tailor/chunks.h"
#include "tailor/export.h"

namespace tailor::python {

void bind_tiles(py::module_& m) {
  m.def(
      "plan_chunks",
      [](const PyMesh& mesh, const py::object& chunk_cell) {
        ChunkOptions options;
        options.mode = ChunkMode::kOn;
        if (!chunk_cell.is_none()) {
          const int e = chunk_cell.cast<int>();
          if (e < -60 || e > 60) raise_error("chunk_cell must be None or a whole number in -60..60");
          options.cell_exponent = e;
        }
        ChunkPlan plan;
        Status status;
        {
          const py::gil_scoped_release release;
          status = plan_chunks(mesh.mesh, options, plan);
        }
        if (!status) raise_status(status.with_file(mesh.source));
        const auto chunks = static_cast<py::ssize_t>(plan.chunk_count());
        py::array_t<int32_t> cells({chunks, py::ssize_t{3}});
        if (chunks) std::memcpy(cells.mutable_data(), plan.cells.data(), plan.cells.size() * sizeof(plan.cells[0]));
        py::dict d;
        d["cell_exponent"] = plan.cell_exponent;
        d["cell_size"] = plan.cell_size;
        d["median_edge"] = plan.median_edge;
        d["longest_edge"] = plan.longest_edge;
        d["locality_radius"] = plan.locality_radius();
        d["cells"] = cells;
        d["chunk_start"] = py::array_t<uint32_t>({py::ssize_t(plan.chunk_start.size())}, plan.chunk_start.data());
        d["faces"] = py::array_t<uint32_t>({py::ssize_t(plan.faces.size())}, plan.faces.data());
        return d;
      },
      py::arg("mesh"), py::arg("chunk_cell") = py::none(),
      R"(plan_chunks(mesh, chunk_cell=None) -> dict

The chunked engine's rule (`tailor map --chunks on`): a grid anchored at the world origin, cell
side 2**cell_exponent world units (chunk_cell, else from the median edge length); a face belongs
to the cell of its centroid. Returns cell_exponent, cell_size, median_edge, longest_edge,
locality_radius, cells (K, 3) int32 in cell order (z, then y, then x), chunk_start (K+1,) uint32
and faces (F,) uint32: chunk k's face ids are faces[chunk_start[k]:chunk_start[k+1]].)");

  m.def(
      "save_uvs",
      [](const py::object& path_object, const PyMesh& mesh, const py::array& corner_uvs, const py::sequence& size,
         const py::object& texture) {
        const std::string path = path_of(path_object);
        const size_t faces = mesh.mesh.face_count();
        const auto uv = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(corner_uvs);
        if (!uv || uv.ndim() != 3 || static_cast<size_t>(uv.shape(0)) != faces || uv.shape(1) != 3 || uv.shape(2) != 2)
          raise_error("corner_uvs must be an (F, 3, 2) array with F = " + std::to_string(faces) + ", got " +
                      describe(corner_uvs));
        if (py::len(size) != 2) raise_error("texture_size must be (width, height), got " + sequence_text(size));
        ExportOptions options;
        options.texture_width = size[0].cast<int>();
        options.texture_height = size[1].cast<int>();
        if (options.texture_width <= 0 || options.texture_height <= 0)
          raise_error("texture_size must be positive, got " + sequence_text(size));
        if (!texture.is_none()) options.texture_path = path_of(texture);
        Atlas atlas;
        atlas.corner_uv.assign(uv.data(), uv.data() + 6 * faces);
        atlas.patch.assign(faces, 0);
        atlas.patch_count = faces ? 1 : 0;
        Status status;
        {
          const py::gil_scoped_release release;
          status = export_mesh(path, mesh.mesh, atlas, options);
        }
        if (!status) raise_status(status);
      },
      py::arg("path"), py::arg("mesh"), py::arg("corner_uvs"), py::arg("texture_size"), py::arg("texture") = py::none(),
      R"(save_uvs(path, mesh, corner_uvs, texture_size, texture=None) -> None

Writes the mesh with per-corner UVs given in texture pixels ((F, 3, 2), as ChunkedMapper.chunk()
gives them), divided by texture_size = (width, height) into texture repeats exactly as `tailor
map -o` does: .glb, .obj or .ply, atomically. texture: a PNG or JPEG to embed (.glb) or name
(.obj); None writes the UVs with a plain material.)");
}

}  // namespace tailor::python
