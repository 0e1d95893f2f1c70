// tailor.Mesh (from numpy arrays or a file) and tailor.load. The arrays are validated and repaired
// by finalize_mesh, the same pass every file reader runs, so a Mesh from arrays and one from a
// file obey the same rules (and raise the same messages).
#include <cmath>
#include <cstdio>
#include <cstring>

#include "bindings.h"
#include "tailor/io.h"
#include "tailor/topology.h"

namespace tailor::python {
namespace {

constexpr const char* kArraysName = "tailor.Mesh";

// (V, 3) float32 or float64 -> mesh.positions. float32 in C order is one memcpy; other layouts
// and float64 are converted row by row (float64 values beyond float's range become inf, which
// finalize_mesh refuses as non-finite).
void copy_positions(const py::array& positions, std::vector<float>& out) {
  if (positions.ndim() != 2 || positions.shape(1) != 3)
    raise_error("positions must be a (V, 3) array, got " + describe(positions));
  const size_t count = static_cast<size_t>(positions.shape(0)) * 3;
  if (count / 3 > kMaxVertices) raise_status(Status::error(ErrorCode::kLimit, kArraysName, "too many vertices"));
  out.resize(count);
  // By kind and size, so that either byte order is taken (forcecast swaps a big-endian array's).
  const char kind = positions.dtype().kind();
  const py::ssize_t size = positions.dtype().itemsize();
  if (kind == 'f' && size == 4) {
    const auto typed = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(positions);
    const py::gil_scoped_release release;
    if (count) std::memcpy(out.data(), typed.data(), count * sizeof(float));
  } else if (kind == 'f' && size == 8) {
    const auto typed = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(positions);
    const double* in = typed.data();
    size_t beyond = count;
    {
      const py::gil_scoped_release release;
      for (size_t i = 0; i < count; ++i) {
        out[i] = static_cast<float>(in[i]);
        if (std::isfinite(in[i]) && !std::isfinite(out[i]) && beyond == count) beyond = i;
      }
    }
    if (beyond != count) {
      char value[32];
      std::snprintf(value, sizeof value, "%g", in[beyond]);
      raise_status(Status::error(ErrorCode::kInvalidMesh, kArraysName,
                                 std::string("vertex coordinate ") + value + " beyond the range of 32-bit floats",
                                 "vertex " + std::to_string(beyond / 3)));
    }
  } else {
    raise_error("positions must be float32 or float64, got " + describe(positions));
  }
}

// LoadReport's fields by their C++ names. Texts may quote the file (names, paths): not always UTF-8.
py::dict load_report_dict(const LoadReport& r) {
  py::dict d;
  d["format"] = utf8_text(r.format);
  d["file_bytes"] = r.file_bytes;
  d["source_faces"] = r.source_faces;
  d["polygons_triangulated"] = r.polygons_triangulated;
  d["concave_polygons"] = r.concave_polygons;
  d["degenerate_faces"] = r.degenerate_faces;
  d["duplicate_faces"] = r.duplicate_faces;
  d["zero_area_faces"] = r.zero_area_faces;
  d["unreferenced_vertices"] = r.unreferenced_vertices;
  d["welded_vertices"] = r.welded_vertices;
  d["faces_collapsed_by_weld"] = r.faces_collapsed_by_weld;
  d["faces_without_uv"] = r.faces_without_uv;
  d["primitive_without_uv"] = utf8_text(r.primitive_without_uv);
  d["faces_turned"] = r.faces_turned;
  d["mesh_instances"] = r.mesh_instances;
  d["skipped_primitives"] = r.skipped_primitives;
  d["not_kept"] = utf8_text(r.not_kept);
  d["not_read"] = utf8_text(r.not_read);
  d["texture_width"] = r.texture_width;
  d["texture_height"] = r.texture_height;
  d["texture_file"] = r.texture_file;
  d["texture_path"] = utf8_text(r.texture_path);
  d["texture_named"] = utf8_text(r.texture_named);
  d["texture_problem"] = utf8_text(r.texture_problem);
  d["texture_transform"] = r.texture_transform;
  d["texture_symmetry"] = r.texture_symmetry;
  d["load_seconds"] = r.load_seconds;
  return d;
}

}  // namespace

// One face row of any integer type -> uint32 indices; a negative or too large index is refused
// with finalize_mesh's message for an index out of range.
template <class T>
void copy_indices(const py::array& faces, size_t vertex_count, std::vector<uint32_t>& out, const char* name) {
  const auto typed = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(faces);
  const T* in = typed.data();
  const size_t count = out.size();
  size_t bad = count;
  {
    const py::gil_scoped_release release;
    for (size_t i = 0; i < count; ++i) {
      const T v = in[i];
      if constexpr (std::is_signed_v<T>) {
        if (v < 0) {
          bad = i;
          break;
        }
      }
      if (static_cast<uint64_t>(v) >= vertex_count) {  // finalize_mesh would name it too; uint32 may not hold it
        bad = i;
        break;
      }
      out[i] = static_cast<uint32_t>(v);
    }
  }
  if (bad != count)
    raise_status(Status::error(ErrorCode::kInvalidMesh, name,
                               "face index " + std::to_string(in[bad]) + " out of range (mesh has " +
                                   std::to_string(vertex_count) + " vertices)",
                               "face " + std::to_string(bad / 3)));
}

void copy_faces(const py::array& faces, size_t vertex_count, std::vector<uint32_t>& out, const char* name) {
  if (faces.ndim() != 2 || faces.shape(1) != 3) raise_error("faces must be an (F, 3) array, got " + describe(faces));
  if (static_cast<size_t>(faces.shape(0)) > kMaxFaces)
    raise_status(Status::error(ErrorCode::kLimit, name, "too many faces"));
  out.resize(static_cast<size_t>(faces.shape(0)) * 3);
  const char kind = faces.dtype().kind();
  const py::ssize_t size = faces.dtype().itemsize();
  if (kind == 'u' && size == 4)
    copy_indices<uint32_t>(faces, vertex_count, out, name);
  else if (kind == 'i' && size == 4)
    copy_indices<int32_t>(faces, vertex_count, out, name);
  else if (kind == 'i' && size == 8)
    copy_indices<int64_t>(faces, vertex_count, out, name);
  else if (kind == 'u' && size == 8)
    copy_indices<uint64_t>(faces, vertex_count, out, name);
  else
    raise_error("faces must be int32, int64, uint32 or uint64, got " + describe(faces));
}

void bind_mesh(py::module_& m) {
  py::class_<PyMesh>(m, "Mesh",
                     "A triangle mesh: positions (V, 3) float32 and faces (F, 3) uint32, counter-clockwise.\n\n"
                     "Mesh(positions, faces): positions float32 or float64 (V, 3), faces int32, int64, uint32 or\n"
                     "uint64 (F, 3), in either byte order. Native float32 and uint32 arrays in C order are\n"
                     "copied with one memcpy into the library's arrays (no conversion); other dtypes are\n"
                     "converted. The arrays are checked as every file reader checks them: non-finite\n"
                     "coordinates and indices out of range raise\n"
                     "tailor.Error; faces with a repeated vertex and exact duplicate faces are dropped and\n"
                     "counted in load_report (compare face_count with len(faces)).")
      .def(py::init([](const py::object& positions, const py::object& faces) {
             // Any array-like (nested lists too), as numpy reads it; what it cannot read is a
             // tailor.Error like a wrong shape, not pybind11's list of signatures.
             const auto array_of = [](const py::object& o, const char* name) {
               const std::optional<py::array> a = as_array(o);
               if (!a)
                 raise_error(std::string(name) + " must be an array of numbers, got a " +
                             py::type::of(o).attr("__name__").cast<std::string>() + " numpy cannot read as one");
               return *a;
             };
             auto mesh = std::make_unique<PyMesh>();
             copy_positions(array_of(positions, "positions"), mesh->mesh.positions);
             copy_faces(array_of(faces, "faces"), mesh->mesh.vertex_count(), mesh->mesh.indices, kArraysName);
             mesh->load.format = "arrays";
             mesh->load.source_faces = mesh->mesh.face_count();
             Status status;
             {
               const py::gil_scoped_release release;
               status = finalize_mesh(kArraysName, mesh->mesh, mesh->load);
             }
             if (!status) raise_status(status);
             return mesh;
           }),
           py::arg("positions"), py::arg("faces"))
      .def_property_readonly(
          "positions",
          [](py::object self) {
            const PyMesh& mesh = self.cast<const PyMesh&>();
            return readonly_view(mesh.mesh.positions.data(), {py::ssize_t(mesh.mesh.vertex_count()), 3}, self);
          },
          "(V, 3) float32, a read-only view of the mesh's own array (no copy)")
      .def_property_readonly(
          "faces",
          [](py::object self) {
            const PyMesh& mesh = self.cast<const PyMesh&>();
            return readonly_view(mesh.mesh.indices.data(), {py::ssize_t(mesh.mesh.face_count()), 3}, self);
          },
          "(F, 3) uint32, a read-only view (no copy); faces dropped as degenerate or duplicate are not in it")
      .def_property_readonly(
          "corner_uvs",
          [](py::object self) -> py::object {
            const PyMesh& mesh = self.cast<const PyMesh&>();
            if (mesh.mesh.corner_uvs.empty()) return py::none();
            return readonly_view(mesh.mesh.corner_uvs.data(), {py::ssize_t(mesh.mesh.face_count()), 3, 2}, self);
          },
          "(F, 3, 2) float32 texture coordinates read from the file (texture repeats), or None")
      .def_property_readonly(
          "seam_faces",
          [](py::object self) -> py::object {
            const PyMesh& mesh = self.cast<const PyMesh&>();
            if (mesh.mesh.seam_faces.empty()) return py::none();
            return readonly_view(mesh.mesh.seam_faces.data(), {py::ssize_t(mesh.mesh.face_count())}, self);
          },
          "(F,) uint8 seam flags read from the file (PLY 'seam' property), or None")
      .def_property_readonly(
          "vertex_count", [](const PyMesh& mesh) { return mesh.mesh.vertex_count(); }, "number of vertices")
      .def_property_readonly(
          "face_count", [](const PyMesh& mesh) { return mesh.mesh.face_count(); }, "number of faces")
      .def_property_readonly(
          "source", [](const PyMesh& mesh) { return path_text(mesh.source); },
          "the file it was loaded from ('' for arrays)")
      .def_property_readonly(
          "load_report", [](const PyMesh& mesh) { return load_report_dict(mesh.load); },
          "what loading found and repaired: tailor::LoadReport's fields by name (format, source_faces, "
          "degenerate_faces, duplicate_faces, not_kept, not_read, skipped_primitives, mesh_instances, ...)")
      .def("__repr__", [](const PyMesh& mesh) {
        const std::string text = "<tailor.Mesh " + std::to_string(mesh.mesh.vertex_count()) + " vertices, " +
                                 std::to_string(mesh.mesh.face_count()) + " faces" +
                                 (mesh.source.empty() ? std::string() : " from '" + mesh.source + "'") + ">";
        return py::reinterpret_steal<py::object>(
            PyUnicode_DecodeUTF8(text.data(), py::ssize_t(text.size()), "backslashreplace"));
      });

  m.def(
      "orient_faces",
      [](const PyMesh& mesh) {
        auto turned = std::make_unique<PyMesh>(mesh);
        {
          const py::gil_scoped_release release;
          turned->load.faces_turned = orient_faces_coherently(turned->mesh, build_topology(turned->mesh));
        }
        return turned;
      },
      py::arg("mesh"),
      "orient_faces(mesh) -> Mesh\n\nA copy of the mesh whose faces wound against their neighbours are turned to "
      "run as the surface around them (their corners' UVs with them), as `tailor map` does unless --keep-winding; "
      "load_report['faces_turned'] says how many. Mapped as they are, such faces are cut apart and their edges "
      "counted as seams.");
  m.def(
      "load",
      [](const py::object& path_object) {
        const std::string path = path_of(path_object);
        auto mesh = std::make_unique<PyMesh>();
        mesh->source = path;
        Status status;
        {
          const py::gil_scoped_release release;
          status = load_mesh(path, mesh->mesh, &mesh->load);
        }
        if (!status) raise_status(status);
        return mesh;
      },
      py::arg("path"),
      "load(path) -> Mesh\n\nReads a mesh file (.ply .obj .off .stl .glb; the format from the extension, else "
      "the content), as `tailor map` does. Raises tailor.Error with the command's message on a bad file.");
}

}  // namespace tailor::python
