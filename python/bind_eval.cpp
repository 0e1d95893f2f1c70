// tailor.evaluate: the UV metrics of `tailor eval` for any per-corner UVs of a mesh.
#include <chrono>

#include "bindings.h"
#include "tailor/mapping.h"
#include "tailor/metrics.h"
#include "tailor/report.h"
#include "tailor/topology.h"

namespace tailor::python {

void bind_eval(py::module_& m) {
  m.def(
      "evaluate",
      [](const PyMesh& mesh, const py::array& corner_uvs, const py::object& texture_size, uint32_t symmetry) {
        const size_t nf = mesh.mesh.face_count();
        const bool shape_ok =
            (corner_uvs.ndim() == 3 && static_cast<size_t>(corner_uvs.shape(0)) == nf && corner_uvs.shape(1) == 3 &&
             corner_uvs.shape(2) == 2) ||
            (corner_uvs.ndim() == 2 && static_cast<size_t>(corner_uvs.shape(0)) == 3 * nf && corner_uvs.shape(1) == 2);
        if (!shape_ok || corner_uvs.dtype().kind() != 'f')
          raise_error("corner_uvs must be a float (F, 3, 2) array with F = " + std::to_string(nf) + ", got " +
                      describe(corner_uvs));
        // Whole numbers as Python has them (numpy's integers too, through __index__), then the range.
        const auto whole = [](const py::handle& h, long long& out) {
          if (!whole_value(h, out)) raise_error("texture_size must be an int or (width, height)");
        };
        long long width = 0, height = 0;
        // A sequence by its length (a 0-d numpy array claims to be one and has none: a number).
        const Py_ssize_t length = py::isinstance<py::str>(texture_size) ? -1 : PySequence_Size(texture_size.ptr());
        if (length < 0) PyErr_Clear();
        if (length >= 0) {
          if (length != 2) raise_error("texture_size must be an int or (width, height)");
          const auto wh = texture_size.cast<py::sequence>();
          whole(wh[0], width);
          whole(wh[1], height);
        } else {
          whole(texture_size, width);
          height = width;
        }
        if (width < 1 || height < 1 || width > kMaxTextureSize || height > kMaxTextureSize)
          raise_error("texture_size must be between 1 and 65536, got " + std::to_string(width) + "x" +
                      std::to_string(height));
        if (symmetry != 1 && symmetry != 4) raise_error("symmetry must be 1 or 4, got " + std::to_string(symmetry));
        if (symmetry == 4 && width != height)
          raise_error("symmetry=4 needs a square texture_size, got " + std::to_string(width) + "x" +
                      std::to_string(height));
        const auto uvs = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(corner_uvs);
        EvalRun run;
        Status status;
        {
          const py::gil_scoped_release release;
          const auto start = std::chrono::steady_clock::now();
          // As `tailor eval` measures a file: repeats -> pixels, identical positions joined, patches
          // from the UVs (compute_stored_uv_metrics).
          std::vector<float> uv(uvs.data(), uvs.data() + uvs.size());
          MetricsOptions options{static_cast<float>(width), static_cast<float>(height)};
          options.symmetry = symmetry;
          StoredSurface surface;
          status = compute_stored_uv_metrics(mesh.mesh, nullptr, std::move(uv), options, run.metrics, &surface);
          run.file = mesh.source;
          run.format = mesh.load.format;
          run.vertices = mesh.mesh.vertex_count();
          run.texture_width = static_cast<int>(width);
          run.texture_height = static_cast<int>(height);
          run.texture_size_from = "option";
          run.symmetry = symmetry;
          run.boundary_edges = surface.boundary_edges;
          run.nonmanifold_edges = surface.nonmanifold_edges;
          run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        }
        if (!status) raise_status(status.with_file(mesh.source));
        return json_to_dict(eval_report_json(run));
      },
      py::arg("mesh"), py::arg("corner_uvs"), py::arg("texture_size") = 512, py::arg("symmetry") = 1,
      R"(evaluate(mesh, corner_uvs, texture_size=512, symmetry=1) -> dict

The quality metrics of per-corner UVs (F, 3, 2) in texture repeats, as `tailor eval --json`
prints them: patches, seam_length_ratio, flipped, stretch, l2_stretch, linf_stretch,
distortion_deg, seam_gap_px, ... (docs/metrics.md). texture_size: pixels per repeat, an int or
(width, height). Works on any UVs (tailor's, xatlas', a file's). The GIL is released.)");
}

}  // namespace tailor::python
