// tailor.canonical_tile: the order python -m tailor.tiles gives a tile's faces and vertices, so
// that its bytes and digest depend on its geometry only. Written here rather than in numpy: the
// numpy form made nine passes over the faces and took about a sixth of a streamed tile's task.
#include <algorithm>
#include <cstring>
#include <limits>

#include "bindings.h"

namespace tailor::python {

namespace {

bool less_point(const float* a, const float* b) {
  if (a[0] != b[0]) return a[0] < b[0];
  if (a[1] != b[1]) return a[1] < b[1];
  return a[2] < b[2];
}

struct Keyed {
  uint64_t hash;
  uint32_t face;
  bool operator<(const Keyed& o) const { return hash != o.hash ? hash < o.hash : face < o.face; }
};

}  // namespace

void bind_canonical(py::module_& m) {
  m.def(
      "canonical_tile",
      [](const py::array& positions_in, const py::array& faces_in) {
        const auto positions = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(positions_in);
        const auto faces = py::array_t<uint32_t, py::array::c_style | py::array::forcecast>::ensure(faces_in);
        if (!positions || positions.ndim() != 2 || positions.shape(1) != 3)
          raise_error("positions must be a (V, 3) array, got " + describe(positions_in));
        if (!faces || faces.ndim() != 2 || faces.shape(1) != 3)
          raise_error("faces must be an (F, 3) array, got " + describe(faces_in));
        constexpr py::ssize_t kMost = std::numeric_limits<uint32_t>::max();
        if (positions.shape(0) > kMost || faces.shape(0) > kMost)
          raise_error("a tile holds at most 2^32 - 1 vertices and faces");
        const size_t vertex_count = static_cast<uint32_t>(positions.shape(0));
        const size_t face_count = static_cast<uint32_t>(faces.shape(0));
        const float* p = positions.data();
        const uint32_t* f = faces.data();
        for (size_t i = 0; i < 3 * face_count; ++i)
          if (f[i] >= vertex_count)
            raise_error("face " + std::to_string(i / 3) + " has vertex " + std::to_string(f[i]) + ", the tile has " +
                        std::to_string(vertex_count));
        std::vector<uint32_t> turned(3 * face_count);
        std::vector<Keyed> keys(face_count);
        std::vector<uint32_t> by_use;
        py::array_t<uint32_t> out_faces({static_cast<py::ssize_t>(face_count), py::ssize_t{3}});
        {
          const py::gil_scoped_release release;
          for (size_t i = 0; i < face_count; ++i) {
            // The smallest corner (x, then y, then z) first, the winding kept.
            const uint32_t* c = f + 3 * i;
            uint32_t first = less_point(p + 3 * c[1], p + 3 * c[0]) ? 1 : 0;
            if (less_point(p + 3 * c[2], p + 3 * c[first])) first = 2;
            uint64_t hash = 0xCBF29CE484222325ull;  // FNV-1a over the nine coordinates' bits
            for (uint32_t k = 0; k < 3; ++k) {
              const uint32_t v = c[(first + k) % 3];
              turned[3 * i + k] = v;
              uint32_t bits[3];
              std::memcpy(bits, p + 3 * v, sizeof bits);
              for (const uint32_t b : bits) hash = (hash ^ b) * 0x100000001B3ull;
            }
            keys[i] = {hash, static_cast<uint32_t>(i)};
          }
          std::sort(keys.begin(), keys.end());  // by hash, ties in input order: a stable sort
          // Vertices numbered by first use in the sorted faces.
          std::vector<uint32_t> new_id(vertex_count, std::numeric_limits<uint32_t>::max());
          by_use.reserve(vertex_count);
          uint32_t* out = out_faces.mutable_data();
          for (size_t i = 0; i < face_count; ++i)
            for (uint32_t k = 0; k < 3; ++k) {
              const uint32_t v = turned[3 * keys[i].face + k];
              if (new_id[v] == std::numeric_limits<uint32_t>::max()) {
                new_id[v] = static_cast<uint32_t>(by_use.size());
                by_use.push_back(v);
              }
              out[3 * i + k] = new_id[v];
            }
        }
        py::array_t<float> out_positions({static_cast<py::ssize_t>(by_use.size()), py::ssize_t{3}});
        float* q = out_positions.mutable_data();
        for (size_t i = 0; i < by_use.size(); ++i) std::memcpy(q + 3 * i, p + 3 * by_use[i], 3 * sizeof(float));
        return py::make_tuple(out_positions, out_faces);
      },
      py::arg("positions"), py::arg("faces"),
      "canonical_tile(positions, faces) -> (positions (V, 3) float32, faces (F, 3) uint32): the faces and\n"
      "vertices in an order that depends on the geometry only: each face turned so that its smallest corner\n"
      "(by x, then y, then z) comes first, faces sorted by a 64-bit FNV-1a hash of their nine coordinates'\n"
      "bits (ties in input order), vertices numbered by first use; unused vertices dropped");
}

}  // namespace tailor::python
