// tailor._partition_block: one block of the streamed partition (tiles_stream._partition_into) cut
// by tile in one pass: each face's chunk cell, its tile's key, the faces' records grouped by tile
// (file order within a tile) and the block's distinct cells. Written here rather than in numpy:
// the numpy form (the cells packed twice, np.unique, a stable argsort, the records assembled and
// then taken in that order) was most of the partition's processor time, which the driver spends
// before any tile can be mapped.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "bindings.h"
#include "tailor/chunks.h"

namespace tailor::python {

namespace {

// A cell (or tile) as one int64 in the order of (z, y, x): tiles_stream._pack. chunk_cells keeps
// every cell in [-2^20, 2^20), and a tile (a cell shifted right) stays in it.
int64_t pack_cell(int32_t x, int32_t y, int32_t z) {
  constexpr int64_t kBias = int64_t{1} << 20;
  return ((int64_t{z} + kBias) << 42) | ((int64_t{y} + kBias) << 21) | (int64_t{x} + kBias);
}

}  // namespace

void bind_partition(py::module_& m) {
  m.def(
      "_partition_block",
      [](const py::array& ids_in, const py::array& corners_in, int cell_exponent, int tile_level, int index_bytes) {
        static_assert(std::endian::native == std::endian::little, "the records are little-endian");
        const auto ids = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(ids_in);
        const auto corners = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(corners_in);
        if (!ids || ids.ndim() != 2 || ids.shape(1) != 3)
          raise_error("ids must be an (F, 3) array, got " + describe(ids_in));
        if (!corners || corners.ndim() != 3 || corners.shape(0) != ids.shape(0) || corners.shape(1) != 3 ||
            corners.shape(2) != 3)
          raise_error("corners must be an (F, 3, 3) array beside the ids, got " + describe(corners_in));
        if (index_bytes != 4 && index_bytes != 8) raise_error("index_bytes must be 4 or 8");
        if (tile_level < 0 || tile_level > 20) raise_error("tile_level must be in 0..20");
        if (ids.shape(0) > py::ssize_t{std::numeric_limits<uint32_t>::max()})
          raise_error("a block holds at most 2^32 - 1 faces");
        const size_t face_count = static_cast<size_t>(ids.shape(0));
        const size_t record_bytes = 3 * static_cast<size_t>(index_bytes) + 9 * sizeof(float);
        std::vector<int32_t> cells(3 * face_count);
        Status status;
        {
          const py::gil_scoped_release release;
          status = chunk_cells({corners.data(), 9 * face_count}, cell_exponent, cells);
        }
        if (!status) raise_status(status);
        // A block holds few tiles and cells, and file order keeps a face's neighbours in its cell
        // as often as not: the distinct keys are sorted from the runs of equal keys, and the faces
        // are grouped by a counting sort over their tile's rank (no sort over the faces).
        std::vector<int64_t> tile_of(face_count), tile_keys, cell_keys;
        std::vector<uint32_t> order(face_count), start(1, 0);
        {
          const py::gil_scoped_release release;
          for (size_t f = 0; f < face_count; ++f) {
            const int32_t* c = &cells[3 * f];
            const int64_t cell = pack_cell(c[0], c[1], c[2]);
            // >> on a negative int32 is floor division by 2^level, as numpy's on int64.
            tile_of[f] = tile_level ? pack_cell(c[0] >> tile_level, c[1] >> tile_level, c[2] >> tile_level) : cell;
            if (f == 0 || cell != cell_keys.back()) cell_keys.push_back(cell);
            if (f == 0 || tile_of[f] != tile_of[f - 1]) tile_keys.push_back(tile_of[f]);
          }
          std::vector<int32_t>().swap(cells);
          for (std::vector<int64_t>* keys : {&cell_keys, &tile_keys}) {
            std::sort(keys->begin(), keys->end());
            keys->erase(std::unique(keys->begin(), keys->end()), keys->end());
          }
          // Each face's tile rank (binary search, the previous face's rank tried first), counted.
          std::vector<uint32_t> rank(face_count);
          start.assign(tile_keys.size() + 1, 0);
          uint32_t r = 0;
          for (size_t f = 0; f < face_count; ++f) {
            if (tile_keys[r] != tile_of[f])
              r = static_cast<uint32_t>(std::lower_bound(tile_keys.begin(), tile_keys.end(), tile_of[f]) -
                                        tile_keys.begin());
            rank[f] = r;
            ++start[r + 1];
          }
          for (size_t t = 0; t < tile_keys.size(); ++t) start[t + 1] += start[t];
          std::vector<uint32_t> fill(start.begin(), start.end() - 1);
          for (size_t f = 0; f < face_count; ++f) order[fill[rank[f]]++] = static_cast<uint32_t>(f);
        }
        const size_t tile_count = tile_keys.size();
        py::array_t<uint8_t> records({static_cast<py::ssize_t>(face_count), static_cast<py::ssize_t>(record_bytes)});
        py::array_t<int64_t> tiles(static_cast<py::ssize_t>(tile_count));
        py::array_t<int64_t> starts(static_cast<py::ssize_t>(tile_count + 1));
        py::array_t<int64_t> distinct(static_cast<py::ssize_t>(cell_keys.size()));
        {
          const py::gil_scoped_release release;
          uint8_t* out = records.mutable_data();
          const int64_t* id = ids.data();
          const float* p = corners.data();
          for (size_t i = 0; i < face_count; ++i, out += record_bytes) {
            // The record of tiles_stream.record_dtype: three vertex ids, then the nine coordinates.
            const size_t f = order[i];
            for (size_t k = 0; k < 3; ++k) {
              if (index_bytes == 4) {
                const auto v = static_cast<uint32_t>(id[3 * f + k]);
                std::memcpy(out + 4 * k, &v, 4);
              } else {
                const auto v = static_cast<uint64_t>(id[3 * f + k]);
                std::memcpy(out + 8 * k, &v, 8);
              }
            }
            std::memcpy(out + 3 * static_cast<size_t>(index_bytes), p + 9 * f, 9 * sizeof(float));
          }
          std::copy(tile_keys.begin(), tile_keys.end(), tiles.mutable_data());
          std::copy(start.begin(), start.end(), starts.mutable_data());
          std::copy(cell_keys.begin(), cell_keys.end(), distinct.mutable_data());
        }
        return py::make_tuple(records, tiles, starts, distinct);
      },
      py::arg("ids"), py::arg("corners"), py::arg("cell_exponent"), py::arg("tile_level"), py::arg("index_bytes"),
      "_partition_block(ids, corners, cell_exponent, tile_level, index_bytes) -> (records (F, R) uint8,\n"
      "tiles (T,) int64, starts (T + 1,) int64, cells (C,) int64): for tailor.tiles: the faces' records\n"
      "(ids as index_bytes-wide unsigned integers, then the corners) grouped by tile (file order within a\n"
      "tile), tile t's records at [starts[t], starts[t + 1]); tiles and cells as packed keys, sorted");
}

}  // namespace tailor::python
