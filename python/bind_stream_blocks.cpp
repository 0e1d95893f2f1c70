// The per-block work of the streamed input (tiles_stream), which the driver does before any tile
// can be mapped: tailor._survey_block (the first pass: the bounding box and the histogram of the
// edge lengths' high bits), tailor._partition_block (a block cut by tile: each face's chunk
// cell, its tile's key, the faces' records grouped by tile in file order, the distinct cells) and
// tailor._gather_corners (a block's corners from the memory-mapped vertex element).
// One pass over a block each, in C++: in numpy the same work takes a pass per reduction, the
// keys packed twice, np.unique, a stable argsort and a gather of the records, most of those
// passes' processor time.
#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
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

// A float32 (3,) or int64 (65536,) array that the call updates in place, checked.
template <class T>
T* writable(const py::array& a, py::ssize_t size, const char* what) {
  if (!py::isinstance<py::array_t<T>>(a) || a.ndim() != 1 || a.shape(0) != size || !a.writeable() ||
      !(a.flags() & py::array::c_style))
    raise_error(std::string(what) + " must be a writable contiguous array of " + std::to_string(size) + " " +
                (sizeof(T) == 4 ? "float32" : "int64") + ", got " + describe(a));
  return static_cast<T*>(py::array(a).mutable_data());
}

// A filter in front of a sort + unique of a block's keys: a key found in its slot of a small
// direct-mapped table was listed already. A block holds a few hundred distinct cells, and a file
// whose face order is not spatial changes cell at nearly every face: sorting every change took a
// tenth of the partition's time. A key it lets through twice is removed by the unique.
class RecentKeys {
 public:
  RecentKeys() { slots_.fill(-1); }  // no packed key is negative (pack_cell)

  bool first_time(int64_t key) {
    int64_t& slot = slots_[static_cast<uint64_t>(key) * 0x9E3779B97F4A7C15ull >> (64 - kBits)];
    if (slot == key) return false;
    slot = key;
    return true;
  }

 private:
  static constexpr int kBits = 10;
  std::array<int64_t, size_t{1} << kBits> slots_;
};

}  // namespace

FloatArray corner_array(const py::array& corners_in) {
  auto corners = FloatArray::ensure(corners_in);
  if (!corners || corners.ndim() != 3 || corners.shape(1) != 3 || corners.shape(2) != 3)
    raise_error("corners must be an (F, 3, 3) float32 array, got " + describe(corners_in));
  return corners;
}

std::pair<IdArray, FloatArray> streamed_faces(const py::array& ids_in, const py::array& corners_in) {
  auto ids = IdArray::ensure(ids_in);
  if (!ids || ids.ndim() != 2 || ids.shape(1) != 3) raise_error("ids must be an (F, 3) array, got " + describe(ids_in));
  auto corners = corner_array(corners_in);
  if (corners.shape(0) != ids.shape(0))
    raise_error("corners must be beside the ids, a row each: " + describe(corners_in) + " against " + describe(ids_in));
  return {std::move(ids), std::move(corners)};
}

void bind_stream_blocks(py::module_& m) {
  m.def(
      "_survey_block",
      [](const py::array& corners_in, const py::array& lo_out, const py::array& hi_out, const py::object& histogram) {
        const FloatArray corners = corner_array(corners_in);
        float* lo = writable<float>(lo_out, 3, "lo");
        float* hi = writable<float>(hi_out, 3, "hi");
        int64_t* counts = histogram.is_none() ? nullptr : writable<int64_t>(histogram, 1 << 16, "histogram");
        const size_t face_count = static_cast<size_t>(corners.shape(0));
        const float* p = corners.data();
        const py::gil_scoped_release release;
        float low[3] = {lo[0], lo[1], lo[2]}, high[3] = {hi[0], hi[1], hi[2]};  // in registers: no aliasing
        for (size_t c = 0; c < 3 * face_count; ++c)
          for (size_t k = 0; k < 3; ++k) {
            low[k] = std::min(low[k], p[3 * c + k]);
            high[k] = std::max(high[k], p[3 * c + k]);
          }
        std::copy(low, low + 3, lo);
        std::copy(high, high + 3, hi);
        if (!counts) return;
        std::vector<float> lengths(3 * face_count);
        (void)chunk_edge_lengths({p, 9 * face_count}, lengths);  // the sizes match: no error
        for (const float length : lengths) {
          uint32_t bits = 0;
          std::memcpy(&bits, &length, sizeof bits);
          ++counts[bits >> 16];
        }
      },
      py::arg("corners"), py::arg("lo"), py::arg("hi"), py::arg("histogram"),
      "_survey_block(corners, lo, hi, histogram) -> None: for tailor.tiles: lo and hi ((3,) float32) take\n"
      "the corners' smallest and largest coordinates, and histogram ((65536,) int64, or None) counts the\n"
      "high 16 bits of each face's edge lengths as chunk_edge_lengths gives them");
  m.def(
      "_partition_block",
      [](const py::array& ids_in, const py::array& corners_in, int cell_exponent, int tile_level, int index_bytes) {
        static_assert(std::endian::native == std::endian::little, "the records are little-endian");
        const auto [ids, corners] = streamed_faces(ids_in, corners_in);
        if (index_bytes != 4 && index_bytes != 8) raise_error("index_bytes must be 4 or 8");
        if (tile_level < 0 || tile_level > 20) raise_error("tile_level must be in 0..20");
        if (ids.shape(0) > py::ssize_t{std::numeric_limits<uint32_t>::max()})
          raise_error("a block holds at most 2^32 - 1 faces");
        const size_t face_count = static_cast<size_t>(ids.shape(0));
        const size_t record_bytes = 3 * static_cast<size_t>(index_bytes) + 9 * sizeof(float);
        const uint64_t largest_id =
            index_bytes == 4 ? std::numeric_limits<uint32_t>::max() : std::numeric_limits<int64_t>::max();
        for (size_t i = 0; i < 3 * face_count; ++i)  // negative ids are above it as uint64
          if (static_cast<uint64_t>(ids.data()[i]) > largest_id)
            raise_error("vertex id " + std::to_string(ids.data()[i]) + " of face " + std::to_string(i / 3) +
                        " does not fit " + std::to_string(index_bytes) + " bytes");
        std::vector<int32_t> cells(3 * face_count);
        Status status;
        {
          const py::gil_scoped_release release;
          status = chunk_cells({corners.data(), 9 * face_count}, cell_exponent, cells);
        }
        if (!status) raise_status(status);
        // A block holds few tiles and cells: the distinct keys are sorted from the keys not among
        // the recently seen (RecentKeys), and the faces are grouped by a counting sort over their
        // tile's rank (no sort over the faces).
        std::vector<int64_t> tile_of(face_count), tile_keys, cell_keys;
        std::vector<uint32_t> order(face_count), start(1, 0);
        RecentKeys cell_seen, tile_seen;
        {
          const py::gil_scoped_release release;
          for (size_t f = 0; f < face_count; ++f) {
            const int32_t* c = &cells[3 * f];
            const int64_t cell = pack_cell(c[0], c[1], c[2]);
            // >> on a negative int32 is floor division by 2^level, as numpy's on int64.
            tile_of[f] = tile_level ? pack_cell(c[0] >> tile_level, c[1] >> tile_level, c[2] >> tile_level) : cell;
            if (cell_seen.first_time(cell)) cell_keys.push_back(cell);
            if (tile_seen.first_time(tile_of[f])) tile_keys.push_back(tile_of[f]);
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
  m.def(
      "_gather_corners",
      [](const py::buffer& source, size_t offset, size_t stride, size_t count, const py::array& ids_in) {
        // numpy's take of 12-byte records copies each one by a call of its own: a third of the
        // streamed partition's time.
        const char kind = ids_in.dtype().kind();
        auto ids = IdArray::ensure(ids_in);
        if (!ids || (kind != 'i' && kind != 'u') || ids.ndim() != 2 || ids.shape(1) != 3)
          raise_error("ids must be an (F, 3) array of integers, got " + describe(ids_in));
        const size_t n = static_cast<size_t>(ids.shape(0));
        const py::buffer_info info = source.request();  // held: the buffer stays mapped while we read
        // Read as one run of bytes from its start: a strided view (a numpy slice) is refused.
        py::ssize_t step = info.itemsize;
        for (size_t d = info.shape.size(); d-- > 0;) {
          if (info.shape[d] > 1 && info.strides[d] != step) raise_error("source must be a contiguous buffer");
          step *= info.shape[d];
        }
        if (n == 0) return py::array_t<float>({py::ssize_t{0}, py::ssize_t{3}, py::ssize_t{3}});
        const auto size = static_cast<size_t>(info.size * info.itemsize);
        if (stride < 12 || count == 0 || offset > size || size - offset < 12 ||
            (size - offset - 12) / stride < count - 1)
          raise_error("a vertex element of " + std::to_string(count) + " rows of " + std::to_string(stride) +
                      " bytes at byte " + std::to_string(offset) + " does not fit a buffer of " + std::to_string(size));
        py::array_t<float> out({static_cast<py::ssize_t>(n), py::ssize_t{3}, py::ssize_t{3}});
        const auto* base = static_cast<const uint8_t*>(info.ptr) + offset;
        const int64_t* id = ids.data();
        float* p = out.mutable_data();
        size_t bad = 3 * n;
        {
          const py::gil_scoped_release release;
          for (size_t c = 0; c < 3 * n; ++c) {
            if (static_cast<uint64_t>(id[c]) >= count) {  // negative ids too
              bad = c;
              break;
            }
            std::memcpy(p + 3 * c, base + static_cast<size_t>(id[c]) * stride, 12);
          }
        }
        if (bad < 3 * n)
          raise_error("vertex id " + std::to_string(id[bad]) + " of face " + std::to_string(bad / 3) +
                      " is not below " + std::to_string(count));
        return out;
      },
      py::arg("source"), py::arg("offset"), py::arg("stride"), py::arg("count"), py::arg("ids"),
      "_gather_corners(source, offset, stride, count, ids) -> (F, 3, 3) float32: for tailor.tiles: each\n"
      "id's three float32 at byte offset + id * stride of the buffer source (count rows), ids (F, 3)");
}

}  // namespace tailor::python
