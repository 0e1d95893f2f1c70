// tailor.ChunkedMapper: the chunked engine's chunks kept one by one (tailor/chunked_mapper.h), for
// clients that map a streamed world piece by piece.
#include "bindings.h"
#include "tailor/chunked_mapper.h"
#include "tailor/mapping.h"

namespace tailor::python {
namespace {

ChunkCell cell_of(const py::sequence& cell) {
  // A string is a sequence too ("abc": three letters, then "got 'a'"), bytes one of numbers (97,
  // 98, 99): refused whole.
  if (py::isinstance<py::str>(cell) || py::isinstance<py::bytes>(cell) || py::isinstance<py::bytearray>(cell))
    raise_error("cell must be three whole numbers (x, y, z), got " + py::repr(cell).cast<std::string>());
  if (py::len(cell) != 3) raise_error("cell must be three whole numbers (x, y, z), got " + sequence_text(cell));
  ChunkCell c;
  for (size_t k = 0; k < 3; ++k) c[k] = static_cast<int32_t>(whole_number(cell[k], "cell", INT32_MIN, INT32_MAX));
  return c;
}

py::tuple cell_tuple(const ChunkCell& cell) { return py::make_tuple(cell[0], cell[1], cell[2]); }

}  // namespace

void bind_chunks(py::module_& m) {
  py::class_<ChunkedMapper>(
      m, "ChunkedMapper",
      "ChunkedMapper(cell_exponent, texels_per_unit, *, threads=0, field_following=1.0, max_stretch=0.25,\n"
      "              texture_size=None, crack_rings=None, chunk_split=None)\n\n"
      "A mapping kept chunk by chunk, for worlds that load and change piece by piece. Chunks are the cells\n"
      "of a grid anchored at the world origin, side 2**cell_exponent world units (tailor map --chunk-cell);\n"
      "a face belongs to the cell of its centroid. A chunk's UVs depend on its own faces only: the same\n"
      "bits as `tailor map --chunks on --chunk-cell N` gives that chunk inside the whole mesh at the same\n"
      "density, whatever else is loaded, and setting or removing one chunk changes no other.\n"
      "texels_per_unit: texture pixels per world unit. texture_size: (width, height) of one texture repeat in\n"
      "pixels (the lattice the crack closing snaps to; None = 512 x 512), as tailor.map's texture_size or\n"
      "texture; crack_rings: None = 16, as tailor.map; chunk_split: None = 131072, as tailor.map (a cell of more\n"
      "faces is mapped in octant parts, as tailor map --chunk-split).")
      .def(py::init([](int cell_exponent, double texels_per_unit, uint32_t threads, float field_following,
                       float max_stretch, const py::object& texture_size, const py::object& crack_rings,
                       const py::object& chunk_split) {
             MapTextureOptions options;
             if (threads > 64) raise_error("threads: value " + std::to_string(threads) + " not in range [0 - 64]");
             options.mapping.threads = threads;
             options.mapping.field_following = field_following;
             options.mapping.max_stretch = max_stretch;
             if (!crack_rings.is_none())
               options.mapping.crack_rings = bounded_whole_number(crack_rings, "crack_rings", "--crack-rings");
             set_chunk_split(chunk_split, options.chunks.split_above);
             if (!texture_size.is_none()) {
               // The lattice of whole repeats the crack closing snaps to, as tailor.map(texture_size=...).
               if (!py::isinstance<py::sequence>(texture_size) || py::len(texture_size) != 2)
                 raise_error("texture_size must be (width, height), positive, got " + sequence_text(texture_size));
               const py::sequence pair = texture_size.cast<py::sequence>();
               const int size[2] = {static_cast<int>(whole_number(pair[0], "texture_size's width", 1, INT32_MAX)),
                                    static_cast<int>(whole_number(pair[1], "texture_size's height", 1, INT32_MAX))};
               if (const Status s = set_map_texture_size(options, size[0], size[1]); !s) raise_status(s);
             }
             auto mapper = std::make_unique<ChunkedMapper>(options, cell_exponent, texels_per_unit);
             if (const Status s = mapper->check(); !s) raise_status(s);
             return mapper;
           }),
           py::arg("cell_exponent"), py::arg("texels_per_unit"), py::kw_only(), py::arg("threads") = 0,
           py::arg("field_following") = 1.f, py::arg("max_stretch") = MappingOptions{}.max_stretch,
           py::arg("texture_size") = py::none(), py::arg("crack_rings") = py::none(),
           py::arg("chunk_split") = py::none())
      .def(
          "set_chunk",
          [](ChunkedMapper& mapper, const py::sequence& cell, const PyMesh& faces) {
            const ChunkCell c = cell_of(cell);
            Status status;
            {
              const py::gil_scoped_release release;
              status = mapper.set_chunk(c, faces.mesh);
            }
            if (!status) raise_status(status);
          },
          py::arg("cell"), py::arg("faces"),
          "Maps `faces` (a Mesh whose every face has its centroid in the cell) as that chunk, replacing it")
      .def(
          "set_mesh",
          [](ChunkedMapper& mapper, const PyMesh& mesh) {
            std::vector<ChunkCell> cells;
            Status status;
            {
              const py::gil_scoped_release release;
              status = mapper.set_mesh(mesh.mesh, &cells);
            }
            if (!status) raise_status(status.with_file(mesh.source));
            py::list out;
            for (const ChunkCell& c : cells) out.append(cell_tuple(c));
            return out;
          },
          py::arg("mesh"), "Cuts the mesh into chunks, maps them in parallel; returns their cells")
      .def(
          "remove_chunk",
          [](ChunkedMapper& mapper, const py::sequence& cell) { return mapper.remove_chunk(cell_of(cell)); },
          py::arg("cell"), "Drops a chunk; False when it held nothing")
      .def(
          "chunk",
          [](const ChunkedMapper& mapper, const py::sequence& cell) -> py::object {
            const ChunkResult* r = mapper.chunk(cell_of(cell));
            if (!r) return py::none();
            py::dict d;
            const py::ssize_t n = static_cast<py::ssize_t>(r->faces.size());
            d["faces"] = py::array_t<uint32_t>({n}, r->faces.data());
            d["corner_uvs"] = py::array_t<float>({n, py::ssize_t{3}, py::ssize_t{2}}, r->corner_uv.data());
            d["patch"] = py::array_t<uint32_t>({n}, r->patch.data());
            d["patch_count"] = r->patch_count;
            return d;
          },
          py::arg("cell"),
          "The chunk's mapping as a dict: faces (ids in the mesh it came from), corner_uvs (F, 3, 2) in texture\n"
          "pixels, patch, patch_count; None when the chunk holds nothing")
      .def(
          "cells",
          [](const ChunkedMapper& mapper) {
            py::list out;
            for (const ChunkCell& c : mapper.cells()) out.append(cell_tuple(c));
            return out;
          },
          "The cells that hold a chunk, in cell order (z, then y, then x)")
      .def_property_readonly("cell_size", &ChunkedMapper::cell_size, "the cells' side, world units")
      .def_property_readonly("texels_per_unit", &ChunkedMapper::texels_per_unit, "texture pixels per world unit");
}

}  // namespace tailor::python
