// The chunk rule (tailor/chunks.h): a world grid kChunkGridOffset cells off the origin, cell side a power of two
// from the median edge length, a face in the cell of its centroid. Everything here is a function
// of the geometry alone: the median is order-free, the cell of a face depends on its own corners.
#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "mapping/sum_smallest_first.h"
#include "tailor/chunks.h"

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
                       "the mesh spans more than 2^21 chunk cells along an axis: give a larger chunk cell");
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

// Cuts the cells of more than split_above faces into octants, recursively (split_cell), in place:
// the plan's chunks become the parts, each cell's in octant order (z, then y, then x bit), the
// faces of a part in the order they had. Only the faces of split cells are touched.
class CellSplitter {
 public:
  CellSplitter(const Mesh& mesh, ChunkPlan& plan, uint32_t split_above)
      : p_(mesh.positions.data()), idx_(mesh.indices.data()), plan_(plan), split_above_(split_above) {}

  void run() {
    const size_t chunks = plan_.chunk_count();
    bool any = false;
    for (size_t c = 0; c < chunks && !any; ++c) any = plan_.chunk_start[c + 1] - plan_.chunk_start[c] > split_above_;
    plan_.levels.assign(chunks, 0);
    plan_.parts.assign(chunks, {0, 0, 0});
    if (!any) return;
    std::vector<uint32_t> faces;
    faces.reserve(plan_.faces.size());
    for (size_t c = 0; c < chunks; ++c) {
      const std::span<const uint32_t> cell(plan_.faces.data() + plan_.chunk_start[c],
                                           plan_.chunk_start[c + 1] - plan_.chunk_start[c]);
      std::vector<uint32_t> own(cell.begin(), cell.end());
      split(plan_.cells[c], 0, {0, 0, 0}, own, faces);
    }
    plan_.faces = std::move(faces);
    plan_.cells = std::move(cells_);
    plan_.levels = std::move(levels_);
    plan_.parts = std::move(parts_);
    plan_.chunk_start = std::move(start_);
  }

 private:
  // Emits the part (cell, level, part) holding `faces`, or its octants when it holds too many.
  void split(const std::array<int32_t, 3>& cell, int level, const std::array<uint16_t, 3>& part,
             std::vector<uint32_t>& faces, std::vector<uint32_t>& out) {
    if (faces.size() <= split_above_ || level == kMaxChunkSplitLevels) {
      if (start_.empty()) start_.push_back(0);
      out.insert(out.end(), faces.begin(), faces.end());
      start_.push_back(static_cast<uint32_t>(out.size()));
      cells_.push_back(cell);
      levels_.push_back(static_cast<uint8_t>(level));
      parts_.push_back(part);
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
    std::vector<uint8_t> octant(faces.size());
    std::array<uint32_t, 9> start{};
    for (size_t i = 0; i < faces.size(); ++i) {
      const uint32_t* corner = idx_ + 3 * size_t{faces[i]};
      double c[3];
      centroid3(p_ + 3 * size_t{corner[0]}, p_ + 3 * size_t{corner[1]}, p_ + 3 * size_t{corner[2]}, c);
      uint8_t o = 0;
      for (int k = 2; k >= 0; --k) {
        const size_t axis = static_cast<size_t>(k);
        const double s = c[k] * inverse3 - corner_at[axis] - first[axis];
        o = static_cast<uint8_t>((o << 1) | (s >= 1.0 ? 1 : 0));
      }
      octant[i] = o;
      ++start[o + 1u];
    }
    for (size_t o = 0; o < 8; ++o) start[o + 1] += start[o];
    std::vector<uint32_t> sorted(faces.size());
    std::array<uint32_t, 9> fill = start;
    for (size_t i = 0; i < faces.size(); ++i) sorted[fill[octant[i]]++] = faces[i];
    std::vector<uint32_t>().swap(faces);
    std::vector<uint8_t>().swap(octant);
    for (uint32_t o = 0; o < 8; ++o) {
      if (start[o] == start[o + 1]) continue;
      std::vector<uint32_t> children(sorted.begin() + start[o], sorted.begin() + start[o + 1]);
      const std::array<uint16_t, 3> child_part = {static_cast<uint16_t>(2 * part[0] + (o & 1)),
                                                  static_cast<uint16_t>(2 * part[1] + ((o >> 1) & 1)),
                                                  static_cast<uint16_t>(2 * part[2] + ((o >> 2) & 1))};
      split(cell, child, child_part, children, out);
    }
  }

  const float* p_;
  const uint32_t* idx_;
  ChunkPlan& plan_;
  uint32_t split_above_;
  std::vector<std::array<int32_t, 3>> cells_;
  std::vector<uint8_t> levels_;
  std::vector<std::array<uint16_t, 3>> parts_;
  std::vector<uint32_t> start_;
};

}  // namespace

Status plan_chunks(const Mesh& mesh, const ChunkOptions& options, ChunkPlan& plan) {
  TAILOR_RETURN_IF_ERROR(check_chunk_options(options));
  const size_t face_count = mesh.face_count();
  if (face_count == 0) return Status::error(ErrorCode::kInvalidMesh, "", "mesh has no face");
  const float* p = mesh.positions.data();
  const uint32_t* idx = mesh.indices.data();

  // The longest edge (the locality radius reaches that far beyond a cell) and, for the automatic
  // cell only, the median edge: each face's three (an interior edge counts twice, which leaves the
  // median where it is on a closed surface and shifts it by a hair on an open one). The longest is
  // taken over squared lengths: the root and the rounding to float keep the order, so it is the
  // longest of edge_length's values.
  double median = 0.0, longest_squared = 0.0;
  const auto squared = [&](size_t f, int k) {
    return edge_length_squared(p + 3 * size_t{idx[3 * f + static_cast<size_t>(k)]},
                               p + 3 * size_t{idx[3 * f + static_cast<size_t>((k + 1) % 3)]});
  };
  if (options.cell_exponent == kAutoCellExponent) {
    std::vector<float> lengths(3 * face_count);
    for (size_t f = 0; f < face_count; ++f)
      for (int k = 0; k < 3; ++k) {
        const double l2 = squared(f, k);
        longest_squared = std::max(longest_squared, l2);
        lengths[3 * f + static_cast<size_t>(k)] = static_cast<float>(std::sqrt(l2));  // as edge_length
      }
    auto middle = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2);
    std::nth_element(lengths.begin(), middle, lengths.end());
    median = *middle;
  } else {
    for (size_t f = 0; f < face_count; ++f)
      for (int k = 0; k < 3; ++k) longest_squared = std::max(longest_squared, squared(f, k));
  }
  plan.median_edge = median;
  plan.longest_edge = static_cast<float>(std::sqrt(longest_squared));

  int exponent = 0;
  TAILOR_RETURN_IF_ERROR(chunk_cell_exponent(median, options, exponent));
  plan.cell_exponent = exponent;
  plan.cell_size = std::ldexp(1.0, exponent);
  const double inverse3 = std::ldexp(1.0, -exponent) / 3.0;

  // Each face's cell, packed in 63 bits (21 per axis, offset to be unsigned): x fastest.
  std::vector<uint64_t> key(face_count);
  for (size_t f = 0; f < face_count; ++f) {
    const uint32_t* corner = idx + 3 * f;
    if (!face_cell_key(p + 3 * size_t{corner[0]}, p + 3 * size_t{corner[1]}, p + 3 * size_t{corner[2]}, inverse3,
                       key[f]))
      return too_many_cells();
  }
  // The distinct cells, in key order (z, y, x).
  CellTable table;
  for (size_t f = 0; f < face_count; ++f) table.insert(key[f]);
  std::vector<uint64_t> cells = table.keys();
  std::sort(cells.begin(), cells.end());
  const size_t chunks = cells.size();
  for (size_t c = 0; c < chunks; ++c) table.set_value(cells[c], static_cast<uint32_t>(c));
  plan.cells.resize(chunks);
  for (size_t c = 0; c < chunks; ++c)
    for (int k = 0; k < 3; ++k) plan.cells[c][static_cast<size_t>(k)] = unpack_cell(cells[c], k);
  // Faces grouped by chunk (a counting sort, file order within a chunk).
  std::vector<uint32_t> chunk_of(face_count);
  plan.chunk_start.assign(chunks + 1, 0);
  for (size_t f = 0; f < face_count; ++f) {
    const uint32_t c = table.value(key[f]);
    chunk_of[f] = c;
    ++plan.chunk_start[c + 1];
  }
  std::vector<uint64_t>().swap(key);
  for (size_t c = 0; c < chunks; ++c) plan.chunk_start[c + 1] += plan.chunk_start[c];
  plan.faces.resize(face_count);
  std::vector<uint32_t> fill(plan.chunk_start.begin(), plan.chunk_start.end() - 1);
  for (size_t f = 0; f < face_count; ++f) plan.faces[fill[chunk_of[f]]++] = static_cast<uint32_t>(f);
  CellSplitter(mesh, plan, options.split_above ? options.split_above : ~uint32_t{0}).run();
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
  if (!(median_edge > 0.0) || !std::isfinite(median_edge))
    return Status::error(ErrorCode::kInvalidMesh, "", "no edge of positive length to size the chunks by");
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
