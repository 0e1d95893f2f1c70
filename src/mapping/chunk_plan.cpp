// The chunk rule (tailor/chunks.h): a world grid kChunkGridOffset cells off the origin, cell side a power of two
// from the median edge length, a face in the cell of its centroid. Everything here is a function
// of the geometry alone: the median is order-free, the cell of a face depends on its own corners.
#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <span>
#include <vector>

#include "mapping/sum_smallest_first.h"
#include "tailor/chunks.h"
#include "util/bin_select.h"
#include "util/huge_pages.h"
#include "util/parallel_chunks.h"

namespace tailor {

Status check_chunk_options(const ChunkOptions& options) {
  if (options.mode != ChunkMode::kAuto && options.mode != ChunkMode::kOn && options.mode != ChunkMode::kOff)
    return Status::error(ErrorCode::kInvalidArgument, "", "chunk mode must be auto, on or off");
  if (options.cell_exponent != kAutoCellExponent && (options.cell_exponent < -60 || options.cell_exponent > 60))
    return Status::error(ErrorCode::kInvalidArgument, "", "chunk cell exponent must be in -60..60");
  if (!(options.cell_edges >= 8.f && options.cell_edges <= 4096.f))
    return Status::error(ErrorCode::kInvalidArgument, "", "chunk cell edges must be in 8..4096");
  if (options.split_above != 0 && options.split_above < 64)
    return Status::error(ErrorCode::kInvalidArgument, "", "the chunk split must be 0 (never cut) or at least 64 faces");
  return Status::ok();
}

bool uses_chunks(const ChunkOptions& options, size_t face_count) {
  return options.mode == ChunkMode::kOn || (options.mode == ChunkMode::kAuto && face_count >= options.min_faces);
}

namespace {

// Cells per axis either side of the origin: cell coordinates pack into 21 bits each.
constexpr double kMaxCell = double{1 << 20};

// The face's centroid as three times it, in doubles, the three terms added smallest first so that
// the corners' order cannot change a rounding (a NaN corner's is NaN: in no cell).
inline void centroid3(const float* p0, const float* p1, const float* p2, double out[3]) {
  for (int k = 0; k < 3; ++k) out[k] = internal::sum_smallest_first(p0[k], p1[k], p2[k]);
}

// An edge's squared length in doubles, and its length as the median is taken over: that rounded to
// float.
inline double edge_length_squared(const float* a, const float* b) {
  const double dx = double{a[0]} - b[0], dy = double{a[1]} - b[1], dz = double{a[2]} - b[2];
  return dx * dx + dy * dy + dz * dz;
}
inline float edge_length(const float* a, const float* b) {
  return static_cast<float>(std::sqrt(edge_length_squared(a, b)));
}
// Face f's three edges' squared lengths (edge j from corner j to j + 1). Its corners are read once:
// a loop that also stores 32-bit counts would otherwise read them again after every store (which
// may alias the indices).
inline std::array<double, 3> face_edges_squared(const float* p, const uint32_t* idx, size_t f) {
  const float* a = p + 3 * size_t{idx[3 * f]};
  const float* b = p + 3 * size_t{idx[3 * f + 1]};
  const float* c = p + 3 * size_t{idx[3 * f + 2]};
  return {edge_length_squared(a, b), edge_length_squared(b, c), edge_length_squared(c, a)};
}

// The cell of a face (its corners p0, p1, p2) packed in 63 bits (21 per axis, offset to be
// unsigned, x fastest); false when it lies beyond kMaxCell cells from the origin.
inline bool face_cell_key(const float* p0, const float* p1, const float* p2, double inverse3, uint64_t& key) {
  double c[3];
  centroid3(p0, p1, p2, c);
  uint64_t packed = 0;
  for (int k = 2; k >= 0; --k) {
    const double x = c[k] * inverse3 - kChunkGridOffset;
    // floor(x) lies in range exactly when x does (NaN does not). Then floor is the truncation, less
    // one below zero: std::floor is a call on the baseline x86-64 (no SSE4.1 round).
    if (!(x >= -kMaxCell && x < kMaxCell)) return false;
    const auto truncated = static_cast<int64_t>(x);
    const int64_t cell = truncated - (static_cast<double>(truncated) > x ? 1 : 0);
    packed = (packed << 21) | static_cast<uint64_t>(cell + static_cast<int64_t>(kMaxCell));
  }
  key = packed;
  return true;
}

inline int32_t unpack_cell(uint64_t key, int axis) {
  return static_cast<int32_t>(static_cast<int64_t>((key >> (21 * axis)) & ((uint64_t{1} << 21) - 1)) -
                              static_cast<int64_t>(kMaxCell));
}

Status too_many_cells() {
  return Status::error(ErrorCode::kInvalidMesh, "",
                       "a face's centroid lies 2^20 chunk cells or more from the origin along an axis, or is not "
                       "finite: give a larger chunk cell (at most 2^60 units)");
}

// A set of cell keys (open addressing, linear probing): the distinct cells are few (one per ~100k
// faces), so this stays in cache where sorting every face's key would not.
class CellTable {
 public:
  static constexpr uint64_t kEmpty = ~uint64_t{0};
  void insert(uint64_t key) {
    if (2 * (size_ + 1) > keys_.size()) grow();
    size_t i = slot(key);
    while (keys_[i] != kEmpty && keys_[i] != key) i = (i + 1) & (keys_.size() - 1);
    if (keys_[i] == kEmpty) {
      keys_[i] = key;
      ++size_;
    }
  }
  //! The value stored for a key that was inserted.
  uint32_t value(uint64_t key) const {
    size_t i = slot(key);
    while (keys_[i] != key) i = (i + 1) & (keys_.size() - 1);
    return values_[i];
  }
  std::vector<uint64_t> keys() const {
    std::vector<uint64_t> out;
    out.reserve(size_);
    for (const uint64_t k : keys_)
      if (k != kEmpty) out.push_back(k);
    return out;
  }
  void set_value(uint64_t key, uint32_t value) {
    size_t i = slot(key);
    while (keys_[i] != key) i = (i + 1) & (keys_.size() - 1);
    values_[i] = value;
  }

 private:
  size_t slot(uint64_t key) const { return (key * 0x9E3779B97F4A7C15ull >> 17) & (keys_.size() - 1); }
  void grow() {
    std::vector<uint64_t> old = keys_.empty() ? std::vector<uint64_t>() : keys();
    keys_.assign(std::max<size_t>(64, 2 * keys_.size()), kEmpty);
    values_.assign(keys_.size(), 0);
    size_ = 0;
    for (const uint64_t k : old) insert(k);
  }
  std::vector<uint64_t> keys_;
  std::vector<uint32_t> values_;
  size_t size_ = 0;
};

// Cuts the cells of more than split_above faces into octants, recursively (split), in place: the
// plan's chunks become the parts, each cell's in octant order (z, then y, then x bit), the faces of
// a part in the order they had. A split only reorders its cell's own range of plan.faces, so the
// cells are cut side by side, each into its own list of parts.
class CellSplitter {
 public:
  CellSplitter(const Mesh& mesh, ChunkPlan& plan, uint32_t split_above)
      : p_(mesh.positions.data()), idx_(mesh.indices.data()), plan_(plan), split_above_(split_above) {}

  void run(size_t threads) {
    const size_t chunks = plan_.chunk_count();
    bool any = false;
    for (size_t c = 0; c < chunks && !any; ++c) any = plan_.chunk_start[c + 1] - plan_.chunk_start[c] > split_above_;
    plan_.levels.assign(chunks, 0);
    plan_.parts.assign(chunks, {0, 0, 0});
    if (!any) return;
    std::vector<Parts> parts(chunks);  // empty for a cell kept whole
    internal::for_each_chunk(
        chunks, threads,
        [&](size_t c, size_t, size_t) {
          if (plan_.chunk_start[c + 1] - plan_.chunk_start[c] <= split_above_) return;
          Scratch scratch;
          split(plan_.cells[c], 0, {0, 0, 0}, plan_.chunk_start[c], plan_.chunk_start[c + 1], scratch, parts[c]);
        },
        1);
    std::vector<std::array<int32_t, 3>> cells;
    std::vector<uint8_t> levels;
    std::vector<std::array<uint16_t, 3>> places;
    std::vector<uint32_t> start(1, 0);
    for (size_t c = 0; c < chunks; ++c) {
      const Parts& cell = parts[c];
      if (cell.start.empty()) {
        cells.push_back(plan_.cells[c]);
        levels.push_back(0);
        places.push_back({0, 0, 0});
        start.push_back(plan_.chunk_start[c + 1]);
      }
      for (size_t i = 0; i < cell.start.size(); ++i) {
        cells.push_back(plan_.cells[c]);
        levels.push_back(cell.level[i]);
        places.push_back(cell.part[i]);
        start.push_back(i + 1 < cell.start.size() ? cell.start[i + 1] : plan_.chunk_start[c + 1]);
      }
    }
    plan_.cells = std::move(cells);
    plan_.levels = std::move(levels);
    plan_.parts = std::move(places);
    plan_.chunk_start = std::move(start);
  }

 private:
  // One cut cell's parts, in order: where each starts in plan.faces, its level and place.
  struct Parts {
    std::vector<uint32_t> start;
    std::vector<uint8_t> level;
    std::vector<std::array<uint16_t, 3>> part;
  };
  struct Scratch {
    std::vector<uint8_t> octant;
    std::vector<uint32_t> sorted;
  };

  // Emits the part (cell, level, part) holding plan.faces[begin, end), or cuts it into its octants
  // when it holds too many.
  void split(const std::array<int32_t, 3>& cell, int level, const std::array<uint16_t, 3>& part, uint32_t begin,
             uint32_t end, Scratch& scratch, Parts& out) {
    if (end - begin <= split_above_ || level == kMaxChunkSplitLevels) {
      out.start.push_back(begin);
      out.level.push_back(static_cast<uint8_t>(level));
      out.part.push_back(part);
      return;
    }
    // Each face's octant in the part: its centroid in units of the child parts' side, from the
    // cell's corner, clamped into the part (a centroid on the cell's edge rounds either way).
    const int child = level + 1;
    const double inverse3 = std::ldexp(1.0, child - plan_.cell_exponent) / 3.0;
    // The cell's corner and the part's first child, in child sides (ldexp is exact: the same
    // values as computed per face, without a call per face and axis).
    std::array<double, 3> corner_at{}, first{};
    for (size_t k = 0; k < 3; ++k) {
      corner_at[k] = std::ldexp(cell[k] + kChunkGridOffset, child);
      first[k] = 2.0 * part[k];
    }
    uint32_t* const faces = plan_.faces.data() + begin;
    const size_t n = end - begin;
    scratch.octant.resize(n);
    scratch.sorted.resize(n);
    std::array<uint32_t, 9> start{};
    for (size_t i = 0; i < n; ++i) {
      const uint32_t* corner = idx_ + 3 * size_t{faces[i]};
      double c[3];
      centroid3(p_ + 3 * size_t{corner[0]}, p_ + 3 * size_t{corner[1]}, p_ + 3 * size_t{corner[2]}, c);
      uint8_t o = 0;
      for (int k = 2; k >= 0; --k) {
        const size_t axis = static_cast<size_t>(k);
        const double s = c[k] * inverse3 - corner_at[axis] - first[axis];
        o = static_cast<uint8_t>((o << 1) | (s >= 1.0 ? 1 : 0));
      }
      scratch.octant[i] = o;
      ++start[o + 1u];
    }
    for (size_t o = 0; o < 8; ++o) start[o + 1] += start[o];
    std::array<uint32_t, 9> fill = start;
    for (size_t i = 0; i < n; ++i) scratch.sorted[fill[scratch.octant[i]]++] = faces[i];
    std::memcpy(faces, scratch.sorted.data(), n * sizeof(uint32_t));
    for (uint32_t o = 0; o < 8; ++o) {
      if (start[o] == start[o + 1]) continue;
      const std::array<uint16_t, 3> child_part = {static_cast<uint16_t>(2 * part[0] + (o & 1)),
                                                  static_cast<uint16_t>(2 * part[1] + ((o >> 1) & 1)),
                                                  static_cast<uint16_t>(2 * part[2] + ((o >> 2) & 1))};
      split(cell, child, child_part, begin + start[o], begin + start[o + 1], scratch, out);
    }
  }

  const float* p_;
  const uint32_t* idx_;
  ChunkPlan& plan_;
  uint32_t split_above_;
};

// The k-th smallest (from 0) of each face's three edge_length values, as std::nth_element over all
// 3F of them gives it, without storing them: lengths are non-negative floats, whose bits order as
// unsigned integers, so counting the high 16 bits finds the bin that holds it, and counting the
// low 16 bits of that bin's lengths finds the rest. Also the longest squared length.
float kth_edge_length(const float* p, const uint32_t* idx, size_t face_count, uint64_t k, size_t parts,
                      double& longest_squared) {
  using internal::kSelectBins;
  // Counts per part (3F corners fit in 32 bits: so does a count).
  std::vector<uint32_t> counts(parts * kSelectBins);
  std::vector<double> longest(parts, 0.0);
  auto bits = [](double l2) { return std::bit_cast<uint32_t>(static_cast<float>(std::sqrt(l2))); };  // as edge_length
  internal::for_each_part(face_count, parts, [&](size_t t, size_t begin, size_t end) {
    uint32_t* count = counts.data() + t * kSelectBins;
    double most = 0.0;
    for (size_t f = begin; f < end; ++f)
      for (const double l2 : face_edges_squared(p, idx, f)) {
        most = std::max(most, l2);
        ++count[bits(l2) >> 16];
      }
    longest[t] = most;
  });
  longest_squared = *std::max_element(longest.begin(), longest.end());
  internal::sum_bin_rows(counts, parts);
  const uint32_t high = internal::select_bin(counts, k);
  std::fill(counts.begin(), counts.end(), 0);
  internal::for_each_part(face_count, parts, [&](size_t t, size_t begin, size_t end) {
    uint32_t* count = counts.data() + t * kSelectBins;
    for (size_t f = begin; f < end; ++f)
      for (const double l2 : face_edges_squared(p, idx, f))
        if (const uint32_t b = bits(l2); b >> 16 == high) ++count[b & 0xFFFF];
  });
  internal::sum_bin_rows(counts, parts);
  return std::bit_cast<float>(high << 16 | internal::select_bin(counts, k));  // the passes count alike
}

}  // namespace

Status plan_chunks(const Mesh& mesh, const ChunkOptions& options, ChunkPlan& plan, uint32_t threads) {
  TAILOR_RETURN_IF_ERROR(check_chunk_options(options));
  const size_t face_count = mesh.face_count();
  if (face_count == 0) return Status::error(ErrorCode::kInvalidMesh, "", "mesh has no face");
  const float* p = mesh.positions.data();
  const uint32_t* idx = mesh.indices.data();
  // Threads as asked, but none of fewer than 65,536 faces (each holds a 256 KB histogram).
  const size_t parts = internal::parallel_parts(face_count, threads);

  // The longest edge (the locality radius reaches that far beyond a cell) and, for the automatic
  // cell only, the median edge: each face's three (an interior edge counts twice, which leaves the
  // median where it is on a closed surface and shifts it by a hair on an open one). The longest is
  // taken over squared lengths: the root and the rounding to float keep the order, so it is the
  // longest of edge_length's values.
  double median = 0.0, longest_squared = 0.0;
  if (options.cell_exponent == kAutoCellExponent) {
    median = kth_edge_length(p, idx, face_count, 3 * uint64_t{face_count} / 2, parts, longest_squared);
  } else {
    std::vector<double> longest(parts, 0.0);
    internal::for_each_part(face_count, parts, [&](size_t t, size_t begin, size_t end) {
      double most = 0.0;
      for (size_t f = begin; f < end; ++f)
        for (const double l2 : face_edges_squared(p, idx, f)) most = std::max(most, l2);
      longest[t] = most;
    });
    longest_squared = *std::max_element(longest.begin(), longest.end());
  }
  plan.median_edge = median;
  plan.longest_edge = static_cast<float>(std::sqrt(longest_squared));

  int exponent = 0;
  TAILOR_RETURN_IF_ERROR(chunk_cell_exponent(median, options, exponent));
  plan.cell_exponent = exponent;
  plan.cell_size = std::ldexp(1.0, exponent);
  const double inverse3 = std::ldexp(1.0, -exponent) / 3.0;

  // Each face's cell, packed in 63 bits (21 per axis, offset to be unsigned): x fastest; and each
  // part's distinct cells (a run of faces in one cell is looked up once).
  internal::HugeArray<uint64_t> key = internal::huge_uninitialized<uint64_t>(face_count);  // each written first
  std::vector<CellTable> part_cells(parts);
  std::atomic<bool> outside{false};
  internal::for_each_part(face_count, parts, [&](size_t t, size_t begin, size_t end) {
    uint64_t last = CellTable::kEmpty;
    for (size_t f = begin; f < end; ++f) {
      const uint32_t* corner = idx + 3 * f;
      if (!face_cell_key(p + 3 * size_t{corner[0]}, p + 3 * size_t{corner[1]}, p + 3 * size_t{corner[2]}, inverse3,
                         key[f])) {
        outside.store(true, std::memory_order_relaxed);
        return;
      }
      if (key[f] != last) part_cells[t].insert(last = key[f]);
    }
  });
  if (outside.load()) return too_many_cells();
  // The distinct cells, in key order (z, y, x).
  CellTable table;
  for (const CellTable& cells : part_cells)
    for (const uint64_t k : cells.keys()) table.insert(k);
  std::vector<CellTable>().swap(part_cells);
  std::vector<uint64_t> cells = table.keys();
  std::sort(cells.begin(), cells.end());
  const size_t chunks = cells.size();
  for (size_t c = 0; c < chunks; ++c) table.set_value(cells[c], static_cast<uint32_t>(c));
  plan.cells.resize(chunks);
  for (size_t c = 0; c < chunks; ++c)
    for (int k = 0; k < 3; ++k) plan.cells[c][static_cast<size_t>(k)] = unpack_cell(cells[c], k);
  // Faces grouped by chunk, file order within a chunk: each part counts its faces per chunk (their
  // chunk in place of their key), then writes them from where the parts before it end. One part
  // where the counts would take more than a word per face (cells of a few faces each).
  const size_t groups = parts * chunks <= face_count ? parts : 1;
  std::vector<uint32_t> count(groups * chunks, 0);
  internal::for_each_part(face_count, groups, [&](size_t t, size_t begin, size_t end) {
    uint32_t* own = count.data() + t * chunks;
    uint64_t last = CellTable::kEmpty, chunk = 0;
    for (size_t f = begin; f < end; ++f) {
      if (key[f] != last) chunk = table.value(last = key[f]);
      key[f] = chunk;
      ++own[chunk];
    }
  });
  plan.chunk_start.assign(chunks + 1, 0);
  for (size_t c = 0; c < chunks; ++c) {
    uint32_t at = plan.chunk_start[c];
    for (size_t t = 0; t < groups; ++t) {
      const uint32_t faces = count[t * chunks + c];
      count[t * chunks + c] = at;  // where part t's faces of chunk c go
      at += faces;
    }
    plan.chunk_start[c + 1] = at;
  }
  internal::reserve_huge(plan.faces, face_count);
  plan.faces.resize(face_count);
  internal::for_each_part(face_count, groups, [&](size_t t, size_t begin, size_t end) {
    uint32_t* fill = count.data() + t * chunks;
    for (size_t f = begin; f < end; ++f) plan.faces[fill[key[f]]++] = static_cast<uint32_t>(f);
  });
  key.reset();
  CellSplitter(mesh, plan, options.split_above ? options.split_above : ~uint32_t{0}).run(parts);
  return Status::ok();
}

Status chunk_edge_lengths(std::span<const float> corners, std::span<float> lengths) {
  if (corners.size() % 9 != 0 || lengths.size() != corners.size() / 3)
    return Status::error(ErrorCode::kInvalidArgument, "", "chunk_edge_lengths: 9 floats per face in, 3 out");
  const size_t faces = corners.size() / 9;
  const float* c = corners.data();
  for (size_t f = 0; f < faces; ++f, c += 9)
    for (int k = 0; k < 3; ++k) lengths[3 * f + static_cast<size_t>(k)] = edge_length(c + 3 * k, c + 3 * ((k + 1) % 3));
  return Status::ok();
}

Status chunk_cell_exponent(double median_edge, const ChunkOptions& options, int& exponent) {
  exponent = options.cell_exponent;
  if (exponent != kAutoCellExponent) return Status::ok();
  if (!(median_edge > 0.0))
    return Status::error(ErrorCode::kInvalidMesh, "", "no edge of positive length to size the chunks by");
  if (!std::isfinite(median_edge))  // coordinates near 3.4e38: their differences overflow
    return Status::error(ErrorCode::kInvalidMesh, "", "the edge lengths overflow 32-bit floats: give a chunk cell");
  exponent = static_cast<int>(std::lround(std::log2(double{options.cell_edges} * median_edge)));
  exponent = std::clamp(exponent, -60, 60);
  return Status::ok();
}

Status chunk_cells(std::span<const float> corners, int cell_exponent, std::span<int32_t> cells) {
  if (corners.size() % 9 != 0 || cells.size() != corners.size() / 3)
    return Status::error(ErrorCode::kInvalidArgument, "", "chunk_cells: 9 floats per face in, 3 out");
  if (cell_exponent < -60 || cell_exponent > 60)
    return Status::error(ErrorCode::kInvalidArgument, "", "chunk cell exponent must be in -60..60");
  const double inverse3 = std::ldexp(1.0, -cell_exponent) / 3.0;
  const size_t faces = corners.size() / 9;
  const float* c = corners.data();
  for (size_t f = 0; f < faces; ++f, c += 9) {
    uint64_t key = 0;
    if (!face_cell_key(c, c + 3, c + 6, inverse3, key)) return too_many_cells();
    for (int k = 0; k < 3; ++k) cells[3 * f + static_cast<size_t>(k)] = unpack_cell(key, k);
  }
  return Status::ok();
}

}  // namespace tailor
