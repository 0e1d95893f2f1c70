// tailor.canonical_tile: the order python -m tailor.tiles gives a tile's faces and vertices, so
// that its bytes and digest depend on its geometry only. Written here rather than in numpy: the
// numpy form made nine passes over the faces and took about a sixth of a streamed tile's task.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

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
        if (!positions || positions.ndim() != 2 || positions.shape(1) != 3)
          raise_error("positions must be a (V, 3) array, got " + describe(positions_in));
        constexpr py::ssize_t kMost = std::numeric_limits<uint32_t>::max();
        if (positions.shape(0) > kMost) raise_error("a tile holds at most 2^32 - 1 vertices");
        const size_t vertex_count = static_cast<uint32_t>(positions.shape(0));
        // NaN compares false both ways: the order, and so the tile's bytes, would depend on the input's.
        for (size_t i = 0; i < 3 * vertex_count; ++i)
          if (!std::isfinite(positions.data()[i]))
            raise_error(
                "tailor.canonical_tile: vertex coordinate not finite or beyond the range of 32-bit floats "
                "(3.4e38) (vertex " +
                std::to_string(i / 3) + ")");
        // Integer indices each below the vertex count, as tailor.Mesh takes them (a cast would wrap
        // 2^32 + 2 to 2 and truncate 1.5 to 1).
        std::vector<uint32_t> face_indices;
        copy_faces(faces_in, vertex_count, face_indices, "tailor.canonical_tile");
        const size_t face_count = face_indices.size() / 3;
        const float* p = positions.data();
        const uint32_t* f = face_indices.data();
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

// tailor._compact_tile: the read-back of a streamed tile (tiles_stream.read_tile) without numpy's
// sorts: the ids' compaction through a table over their range, the repeated faces found among the
// faces of each smallest vertex (a counting sort, as build_topology groups its edges). O(F) where
// the numpy form (a lexsort of the faces, np.unique with its inverse) was a sixth of a tile's task.
void bind_compact(py::module_& m) {
  m.def(
      "_compact_tile",
      [](const py::array& ids_in, const py::array& corners_in) {
        const auto [ids, corners] = streamed_faces(ids_in, corners_in);
        if (ids.shape(0) > py::ssize_t{std::numeric_limits<uint32_t>::max() / 3})
          raise_error("a tile holds at most (2^32 - 1) / 3 faces");
        const size_t face_count = static_cast<size_t>(ids.shape(0)), corner_count = 3 * face_count;
        const int64_t* id = ids.data();
        const float* p = corners.data();
        constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
        constexpr uint64_t kTableEntries = uint64_t{1} << 24;
        std::vector<uint32_t> compact(corner_count), first_corner;  // per corner its vertex; per vertex a corner
        std::vector<uint8_t> keep(face_count, 1);
        size_t kept = face_count;
        {
          const py::gil_scoped_release release;
          // === Vertices numbered in the order of their ids ===
          int64_t lo = 0, hi = -1;
          if (corner_count) {
            const auto [a, b] = std::minmax_element(id, id + corner_count);
            lo = *a;
            hi = *b;
          }
          const uint64_t range = corner_count ? static_cast<uint64_t>(hi) - static_cast<uint64_t>(lo) + 1 : 0;
          // (range is 0 with faces only when the ids span all 2^64 values: a sort then.)
          if (corner_count == 0 || (range != 0 && range <= 4 * uint64_t{corner_count} + kTableEntries)) {
            // A table over the ids' range (at most 16 bytes per corner, or 64 MB): mark, number in
            // id order. A tile's ids span most of a mesh's vertex numbering as often as not.
            std::vector<uint32_t> slot(range, kNone);
            uint32_t* const table = slot.data();
            for (size_t c = corner_count; c-- > 0;)  // the first corner of each id stays
              table[static_cast<uint64_t>(id[c] - lo)] = static_cast<uint32_t>(c);
            first_corner.resize(corner_count);
            uint32_t* const first = first_corner.data();
            uint32_t used = 0;
            for (uint64_t r = 0; r < range; ++r)
              if (table[r] != kNone) {
                first[used] = table[r];
                table[r] = used++;
              }
            first_corner.resize(used);
            for (size_t c = 0; c < corner_count; ++c) compact[c] = table[static_cast<uint64_t>(id[c] - lo)];
          } else {
            // Ids spread too far for a table: sorted (id, corner) pairs.
            std::vector<std::pair<int64_t, uint32_t>> by_id(corner_count);
            for (size_t c = 0; c < corner_count; ++c) by_id[c] = {id[c], static_cast<uint32_t>(c)};
            std::sort(by_id.begin(), by_id.end());
            for (size_t i = 0; i < corner_count; ++i) {
              if (i == 0 || by_id[i].first != by_id[i - 1].first) first_corner.push_back(by_id[i].second);
              compact[by_id[i].second] = static_cast<uint32_t>(first_corner.size() - 1);
            }
          }
          // === Faces that repeat another face's vertices: the first in file order is kept ===
          // Faces listed by their smallest vertex (in face order), then compared within each list.
          const size_t vertex_count = first_corner.size();
          std::vector<uint32_t> start(vertex_count + 1, 0), listed(face_count);
          std::vector<std::array<uint32_t, 3>> sorted(face_count);
          for (size_t f = 0; f < face_count; ++f) {
            std::array<uint32_t, 3> v = {compact[3 * f], compact[3 * f + 1], compact[3 * f + 2]};
            std::sort(v.begin(), v.end());
            sorted[f] = v;
            ++start[v[0] + 1];
          }
          for (size_t v = 0; v < vertex_count; ++v) start[v + 1] += start[v];
          {
            std::vector<uint32_t> cursor(start.begin(), start.end() - 1);
            for (size_t f = 0; f < face_count; ++f) listed[cursor[sorted[f][0]]++] = static_cast<uint32_t>(f);
          }
          for (size_t v = 0; v < vertex_count; ++v) {
            uint32_t* list = listed.data() + start[v];
            const size_t n = start[v + 1] - start[v];
            // Same smallest vertex: the same face when the other two match.
            const auto same = [&](uint32_t a, uint32_t b) {
              return sorted[a][1] == sorted[b][1] && sorted[a][2] == sorted[b][2];
            };
            if (n > 32)  // a fan: sorted by the other two vertices, then the face (the first stays first)
              std::sort(list, list + n, [&](uint32_t a, uint32_t b) {
                if (sorted[a][1] != sorted[b][1]) return sorted[a][1] < sorted[b][1];
                if (sorted[a][2] != sorted[b][2]) return sorted[a][2] < sorted[b][2];
                return a < b;
              });
            for (size_t i = 1; i < n; ++i)
              for (size_t j = n > 32 ? i - 1 : 0; j < i; ++j)
                if (same(list[j], list[i])) {  // an earlier face with these vertices
                  keep[list[i]] = 0;
                  --kept;
                  break;
                }
          }
        }
        const auto vertex_total = static_cast<py::ssize_t>(first_corner.size());
        py::array_t<float> out_positions({vertex_total, py::ssize_t{3}});
        py::array_t<uint32_t> out_faces({static_cast<py::ssize_t>(kept), py::ssize_t{3}});
        py::array_t<int64_t> out_kept(static_cast<py::ssize_t>(kept));
        {
          const py::gil_scoped_release release;
          float* q = out_positions.mutable_data();
          for (size_t v = 0; v < first_corner.size(); ++v)
            std::memcpy(q + 3 * v, p + 3 * size_t{first_corner[v]}, 3 * sizeof(float));
          uint32_t* o = out_faces.mutable_data();
          int64_t* k = out_kept.mutable_data();
          for (size_t f = 0, i = 0; f < face_count; ++f) {
            if (!keep[f]) continue;
            std::memcpy(o + 3 * i, compact.data() + 3 * f, 3 * sizeof(uint32_t));
            k[i++] = static_cast<int64_t>(f);
          }
        }
        return py::make_tuple(out_positions, out_faces, out_kept);
      },
      py::arg("ids"), py::arg("corners"),
      "_compact_tile(ids, corners) -> (positions (V, 3) float32, faces (F', 3) uint32, kept (F',) int64):\n"
      "for tailor.tiles: the vertices numbered in the order of their ids (each position from one of its\n"
      "corners), the faces that repeat another face's vertices dropped (the first kept), and the kept\n"
      "faces' indices");
}

}  // namespace tailor::python
