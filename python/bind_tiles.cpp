// tailor.plan_chunks, tailor.save_uvs, tailor.load_material and tailor.simplify_uvs: the chunk
// rule, the writer of `tailor map -o` and libmeshoptimizer's simplifier for code that cuts a mesh
// into tiles itself (python -m tailor.tiles): the rule's cells and faces as arrays, any mesh
// written with per-corner UVs in texture pixels (as ChunkedMapper gives them), with a texture or
// a PBR material read once, and a coarser copy that keeps those UVs.
#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "bindings.h"
#include "tailor/chunks.h"
#include "tailor/export.h"
#include "tailor/image.h"
#include "tailor/map_warnings.h"
#include "tailor/material.h"

namespace tailor::python {

namespace {

// (F, 3, 2) float32 per-corner UVs of `mesh`, checked.
py::array_t<float, py::array::c_style | py::array::forcecast> corner_uv_array(const py::array& corner_uvs,
                                                                              size_t faces) {
  const auto uv = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(corner_uvs);
  if (!uv || uv.ndim() != 3 || static_cast<size_t>(uv.shape(0)) != faces || uv.shape(1) != 3 || uv.shape(2) != 2)
    raise_error("corner_uvs must be an (F, 3, 2) array with F = " + std::to_string(faces) + ", got " +
                describe(corner_uvs));
  return uv;
}

// A material as tailor.load_material returns it: the dict's fields into the export options, each
// checked (a dict may have been edited): a size of whole numbers, flags that are bools, maps that
// are PNGs of the material's size.
void material_from_dict(const py::dict& d, ExportOptions& options) {
  if (!d.contains("width") || !d.contains("height"))
    raise_error("material must be a folder, a JSON or what tailor.load_material returns");
  const int64_t width = whole_number(d["width"], "material['width']", 1, kMaxImageSide);
  const int64_t height = whole_number(d["height"], "material['height']", 1, kMaxImageSide);
  auto png_of = [&](const char* key) {
    if (!d.contains(key) || d[key].is_none()) return std::string();
    if (!py::isinstance<py::bytes>(d[key])) raise_error(std::string("material['") + key + "'] must be bytes or None");
    std::string png = d[key].cast<std::string>();
    // The PNG signature, then the IHDR chunk's big-endian width and height.
    const auto be32 = [&](size_t at) {
      int64_t v = 0;
      for (size_t k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(png[at + k]);
      return v;
    };
    if (png.size() < 24 || png.compare(0, 8, std::string("\x89PNG\r\n\x1a\n", 8)) != 0 ||
        png.compare(12, 4, "IHDR") != 0 || be32(16) != width || be32(20) != height)
      raise_error(std::string("material['") + key + "'] must be a PNG of the material's " + std::to_string(width) +
                  "x" + std::to_string(height) + " px");
    return png;
  };
  auto flag_of = [&](const char* key) {
    if (!d.contains(key)) return false;
    if (!py::isinstance<py::bool_>(d[key])) raise_error(std::string("material['") + key + "'] must be True or False");
    return d[key].cast<bool>();
  };
  if (d.contains("symmetry") && !d["symmetry"].is_none()) {
    const int64_t symmetry = whole_number(d["symmetry"], "material['symmetry']", 0, 4);
    if (symmetry != 0 && symmetry != 1 && symmetry != 4) raise_error("material['symmetry'] must be 0, 1 or 4");
  }
  if (d.contains("color") && !d["color"].is_none()) options.texture_path = path_of(d["color"]);
  options.material.normal_png = png_of("normal_png");
  options.material.orm_png = png_of("orm_png");
  options.material.orm_roughness_metallic = flag_of("orm_roughness_metallic");
  options.material.orm_occlusion = flag_of("orm_occlusion");
  if (width != options.texture_width || height != options.texture_height)
    raise_error("the material is " + std::to_string(width) + "x" + std::to_string(height) + " but texture_size is " +
                std::to_string(options.texture_width) + "x" + std::to_string(options.texture_height));
}

// What tailor.load_material returns for a material read by load_material.
py::dict material_dict(const MaterialMaps& maps) {
  auto bytes_or_none = [](const std::string& b) {
    return b.empty() ? py::object(py::none()) : py::object(py::bytes(b));
  };
  py::dict d;
  d["color"] = maps.color.empty() ? py::object(py::none()) : path_text(maps.color);
  d["width"] = maps.width;
  d["height"] = maps.height;
  d["normal_png"] = bytes_or_none(maps.textures.normal_png);
  d["orm_png"] = bytes_or_none(maps.textures.orm_png);
  d["orm_roughness_metallic"] = maps.textures.orm_roughness_metallic;
  d["orm_occlusion"] = maps.textures.orm_occlusion;
  d["symmetry"] = maps.symmetry;
  py::list files, notes;
  for (const std::string& file : maps.files) files.append(path_text(file));
  for (const std::string& note : maps.notes) notes.append(utf8_text(note));
  d["files"] = files;
  d["notes"] = notes;
  return d;
}

// A material description (folder, JSON) read without the GIL, as the dict material_dict makes.
py::dict read_material_dict(const py::object& path_object) {
  const std::string path = path_of(path_object);
  MaterialMaps maps;
  Status status;
  {
    const py::gil_scoped_release release;
    status = load_material(path, maps);
  }
  if (!status) raise_status(status);
  return material_dict(maps);
}

}  // namespace

void bind_simplify(py::module_& m);
void bind_canonical(py::module_& m);
void bind_compact(py::module_& m);
void bind_stream_blocks(py::module_& m);

void bind_tiles(py::module_& m) {
  m.def(
      "plan_chunks",
      [](const PyMesh& mesh, const py::object& chunk_cell) {
        ChunkOptions options;
        options.mode = ChunkMode::kOn;
        if (!chunk_cell.is_none()) {
          const int e = static_cast<int>(whole_number(chunk_cell, "chunk_cell", -60, 60));
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
        d["levels"] = py::array_t<uint8_t>({chunks}, plan.levels.data());
        py::array_t<uint16_t> parts({chunks, py::ssize_t{3}});
        if (chunks) std::memcpy(parts.mutable_data(), plan.parts.data(), plan.parts.size() * sizeof(plan.parts[0]));
        d["parts"] = parts;
        d["chunk_start"] = py::array_t<uint32_t>({py::ssize_t(plan.chunk_start.size())}, plan.chunk_start.data());
        d["faces"] = py::array_t<uint32_t>({py::ssize_t(plan.faces.size())}, plan.faces.data());
        return d;
      },
      py::arg("mesh"), py::arg("chunk_cell") = py::none(),
      R"(plan_chunks(mesh, chunk_cell=None) -> dict

The chunked engine's rule (`tailor map --chunks on`): a grid anchored at the world origin, cell
side 2**cell_exponent world units (chunk_cell, else from the median edge length); a face belongs
to the cell of its centroid; a cell of more than 131,072 faces is cut into octants, recursively
(parts). Returns cell_exponent, cell_size, median_edge, longest_edge, locality_radius, cells (K, 3)
int32 in cell order (z, then y, then x; a split cell's parts one after the other share it), levels
(K,) uint8 (0: the whole cell, else the part's octant depth), parts (K, 3) uint16 (the part's place
in its cell in units of 2**-level of the side), chunk_start (K+1,) uint32 and faces (F,) uint32:
chunk k's face ids are faces[chunk_start[k]:chunk_start[k+1]].)");

  // The rule's arithmetic on blocks of faces, for a partition that streams the mesh (tailor.tiles).
  m.def(
      "chunk_edge_lengths",
      [](const py::array& corners) {
        const FloatArray c = corner_array(corners);
        const py::ssize_t n = c.shape(0);
        py::array_t<float> out({n, py::ssize_t{3}});
        Status status;
        {
          const py::gil_scoped_release release;
          status = chunk_edge_lengths({c.data(), static_cast<size_t>(9 * n)},
                                      {out.mutable_data(), static_cast<size_t>(3 * n)});
        }
        if (!status) raise_status(status);
        return out;
      },
      py::arg("corners"),
      "chunk_edge_lengths(corners) -> (F, 3) float32: each face's edge lengths (corner k to k+1) exactly as\n"
      "plan_chunks measures them for its median; corners: (F, 3, 3) float32");
  m.def(
      "chunk_cell_exponent",
      [](double median_edge, const py::object& chunk_cell) {
        ChunkOptions options;
        if (!chunk_cell.is_none())
          options.cell_exponent = static_cast<int>(whole_number(chunk_cell, "chunk_cell", -60, 60));
        if (const Status s = check_chunk_options(options); !s) raise_status(s);
        int exponent = 0;
        if (const Status s = chunk_cell_exponent(median_edge, options, exponent); !s) raise_status(s);
        return exponent;
      },
      py::arg("median_edge"), py::arg("chunk_cell") = py::none(),
      "chunk_cell_exponent(median_edge, chunk_cell=None) -> int: the cell exponent plan_chunks takes for a mesh\n"
      "of this median edge length (chunk_cell when given)");
  m.def("_far_from_origin_warning", py::overload_cast<double, double>(&far_from_origin_warning),
        py::arg("largest_coordinate"), py::arg("median_edge"),
        "_far_from_origin_warning(largest_coordinate, median_edge) -> str: for tailor.tiles: what tailor map says\n"
        "of positions that 32-bit floats round by more than 1 % of the median edge ('' when they do not)");
  m.def(
      "_far_from_origin_warning", [](const PyMesh& mesh) { return far_from_origin_warning(mesh.mesh); },
      py::arg("mesh"), "_far_from_origin_warning(mesh) -> str: the same, of a loaded mesh (a sample's median edge)");
  m.def(
      "chunk_cells",
      [](const py::array& corners, int cell_exponent) {
        const FloatArray c = corner_array(corners);
        const py::ssize_t n = c.shape(0);
        py::array_t<int32_t> out({n, py::ssize_t{3}});
        Status status;
        {
          const py::gil_scoped_release release;
          status = chunk_cells({c.data(), static_cast<size_t>(9 * n)}, cell_exponent,
                               {out.mutable_data(), static_cast<size_t>(3 * n)});
        }
        if (!status) raise_status(status);
        return out;
      },
      py::arg("corners"), py::arg("cell_exponent"),
      "chunk_cells(corners, cell_exponent) -> (F, 3) int32: each face's chunk cell (x, y, z), the cell of its\n"
      "centroid exactly as plan_chunks computes it; corners: (F, 3, 3) float32");

  m.def(
      "save_uvs",
      [](const py::object& path_object, const PyMesh& mesh, const py::array& corner_uvs, const py::sequence& size,
         const py::object& texture, const py::object& material, const std::string& up, const py::dict& image_uris) {
        const std::string path = path_of(path_object);
        const size_t faces = mesh.mesh.face_count();
        const auto uv = corner_uv_array(corner_uvs, faces);
        if (py::len(size) != 2) raise_error("texture_size must be (width, height), got " + sequence_text(size));
        ExportOptions options;
        options.texture_width = static_cast<int>(whole_number(size[0], "texture_size's width", 1, INT32_MAX));
        options.texture_height = static_cast<int>(whole_number(size[1], "texture_size's height", 1, INT32_MAX));
        if (up != "y" && up != "z") raise_error("--up must be y or z, got '" + up + "'");
        options.up = up == "z" ? SceneUp::kZ : SceneUp::kY;
        if (!texture.is_none() && !material.is_none())
          raise_error("give texture= or material=, not both (the material's colour map is the texture)");
        if (!texture.is_none()) options.texture_path = path_of(texture);
        if (py::isinstance<py::dict>(material)) {
          material_from_dict(material.cast<py::dict>(), options);
        } else if (!material.is_none()) {
          material_from_dict(read_material_dict(material), options);
        }
        for (const auto& [key, value] : image_uris) {
          const std::string role = py::str(key);
          std::string* uri = role == "color"    ? &options.image_uris.color
                             : role == "normal" ? &options.image_uris.normal
                             : role == "orm"    ? &options.image_uris.orm
                                                : nullptr;
          if (!uri) raise_error("image_uris: a role is color, normal or orm, got '" + role + "'");
          if (!py::isinstance<py::str>(value)) raise_error("image_uris: the URI of " + role + " must be a str");
          *uri = value.cast<std::string>();
          if (uri->empty()) raise_error("image_uris: the URI of " + role + " is empty");
        }
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
      py::arg("material") = py::none(), py::arg("up") = "y", py::arg("image_uris") = py::dict(),
      R"(save_uvs(path, mesh, corner_uvs, texture_size, texture=None, material=None, up='y', image_uris={}) -> None

Writes the mesh with per-corner UVs given in texture pixels ((F, 3, 2), as ChunkedMapper.chunk()
gives them), divided by texture_size = (width, height) into texture repeats exactly as `tailor
map -o` does: .glb, .obj or .ply, atomically. texture: a PNG or JPEG to embed (.glb) or name
(.obj); None writes the UVs with a plain material. material: instead of texture, a PBR material
as `tailor map --material` (.glb: base colour, normal map with tangents, metallicRoughness,
occlusion): a folder or JSON, or what tailor.load_material returned (read once for many files);
its size must be texture_size. up: 'z' for Z-up coordinates, turned Y-up by the .glb node's
rotation as `tailor map --up z`. image_uris: {role: URI} for maps the .glb names (relative to
itself) instead of embedding, without reading them: roles 'color' (needs the texture or the
material's colour map), 'normal' and 'orm' (the material's maps; the ORM map needs the roles the
material gives it): many tiles then share one copy of the images.)");

  m.def(
      "load_material", [](const py::object& path_object) { return read_material_dict(path_object); }, py::arg("path"),
      R"(load_material(path) -> dict

Reads a PBR material as `tailor map --material` does (a folder of maps named *_color, *_normal,
*_roughness..., or a JSON naming them, such as the material.json of `tailor tile --set`) and
returns the maps a .glb holds: color (the colour map's path, embedded as is, or None), width and
height (the repeat in pixels), normal_png (the normal map in glTF's convention, PNG bytes, or
None), orm_png (occlusion, roughness and metallic packed in R, G, B as glTF wants, or None),
orm_roughness_metallic and orm_occlusion (what orm_png serves as), symmetry (4 for quarter-turn
tiles, 1 or 0 otherwise), files ("role: path" of every map read) and notes (one-line warnings).
save_uvs(material=...) takes the dict.)");
  bind_simplify(m);
  bind_canonical(m);
  bind_compact(m);
  bind_stream_blocks(m);
}

void bind_simplify(py::module_& m) {
  m.def(
      "simplify_uvs",
      [](const PyMesh& mesh, const py::array& corner_uvs, size_t target_faces, bool lock_border) {
        const size_t faces = mesh.mesh.face_count();
        const auto uv = corner_uv_array(corner_uvs, faces);
        const float* const values = uv.data();
        for (size_t i = 0; i < 6 * faces; ++i)  // the simplifier would carry NaN through silently
          if (!std::isfinite(values[i]))
            raise_error("corner_uvs: UV is not finite (corner " + std::to_string(i / 2) + ")");
        SplitMesh split;
        std::vector<uint32_t> kept;
        float error = 0.f, scale = 0.f;
        {
          const py::gil_scoped_release release;
          split_vertices(mesh.mesh, std::span<const float>(uv.data(), 6 * faces), split);
          kept.resize(split.indices.size());
          const size_t vertices = split.xref.size();
          // Corners with one position and different UVs are one vertex to the simplifier (its
          // seams): both sides of a UV seam move together, so the surface stays closed.
          const size_t count = meshopt_simplify(kept.data(), split.indices.data(), split.indices.size(),
                                                split.positions.data(), vertices, 3 * sizeof(float),
                                                3 * std::min(target_faces, faces), std::numeric_limits<float>::max(),
                                                lock_border ? unsigned{meshopt_SimplifyLockBorder} : 0u, &error);
          kept.resize(count);
          scale = meshopt_simplifyScale(split.positions.data(), vertices, 3 * sizeof(float));
        }
        // The kept split vertices in order of first use; each keeps its UV bit for bit.
        std::vector<uint32_t> new_id(split.xref.size(), kInvalid);
        std::vector<uint32_t> order;
        for (uint32_t& v : kept) {
          if (new_id[v] == kInvalid) {
            new_id[v] = static_cast<uint32_t>(order.size());
            order.push_back(v);
          }
          v = new_id[v];
        }
        const auto n = static_cast<py::ssize_t>(order.size()), f = static_cast<py::ssize_t>(kept.size() / 3);
        py::array_t<float> positions({n, py::ssize_t{3}});
        py::array_t<uint32_t> out_faces({f, py::ssize_t{3}});
        py::array_t<float> out_uv({f, py::ssize_t{3}, py::ssize_t{2}});
        float* p = positions.mutable_data();
        for (size_t i = 0; i < order.size(); ++i)
          for (size_t k = 0; k < 3; ++k) p[3 * i + k] = split.positions[3 * size_t{order[i]} + k];
        if (!kept.empty()) std::memcpy(out_faces.mutable_data(), kept.data(), kept.size() * sizeof(uint32_t));
        float* t = out_uv.mutable_data();
        for (size_t c = 0; c < kept.size(); ++c) {
          const uint32_t s = order[kept[c]];
          t[2 * c] = split.uvs[2 * size_t{s}];
          t[2 * c + 1] = split.uvs[2 * size_t{s} + 1];
        }
        py::dict d;
        d["positions"] = positions;
        d["faces"] = out_faces;
        d["corner_uvs"] = out_uv;
        d["error"] = static_cast<double>(error) * static_cast<double>(scale);
        return d;
      },
      py::arg("mesh"), py::arg("corner_uvs"), py::arg("target_faces"), py::arg("lock_border") = true,
      R"(simplify_uvs(mesh, corner_uvs, target_faces, lock_border=True) -> dict

A coarser copy of a mapped mesh by libmeshoptimizer's simplifier (edge collapses under a quadric
error), down to about target_faces faces where the error allows. The UVs are kept: vertices are
split where their corners' UVs differ (as the .glb writer splits them), the simplifier moves both
sides of such a seam together, and every kept corner has its UV bit for bit. lock_border keeps
the mesh's open borders (a tile's sides) where they are, so neighbouring tiles still meet.
Returns positions (V, 3), faces (F, 3), corner_uvs (F, 3, 2) and error: the largest deviation
from the input surface the simplifier measured, in world units.)");
}

}  // namespace tailor::python
