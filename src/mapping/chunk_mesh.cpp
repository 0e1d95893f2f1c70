// One chunk in canonical form (chunk_mesh.h).
#include "mapping/chunk_mesh.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "mapping/sum_smallest_first.h"

namespace tailor::internal {
namespace {

// Spreads the low 21 bits of x to every third bit (Morton interleave).
inline uint64_t spread3(uint64_t x) {
  x &= 0x1FFFFF;
  x = (x | x << 32) & 0x1F00000000FFFFull;
  x = (x | x << 16) & 0x1F0000FF0000FFull;
  x = (x | x << 8) & 0x100F00F00F00F00Full;
  x = (x | x << 4) & 0x10C30C30C30C30C3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

// Lexicographic order of two points (x, then y, then z).
inline bool point_less(const float* a, const float* b) {
  if (a[0] != b[0]) return a[0] < b[0];
  if (a[1] != b[1]) return a[1] < b[1];
  return a[2] < b[2];
}

// faces sorted by Morton key, stably (equal keys keep their order): least significant digit first,
// 11 bits a pass, a pass skipped where every key has the same digit. A chunk's keys are spread
// over their cube, so a comparison sort mispredicts about every other comparison; this does not
// compare. `scratch` is resized to the faces' count.
void sort_by_morton(std::vector<ChunkFace>& faces, std::vector<ChunkFace>& scratch) {
  constexpr int kBits = 11, kPasses = 6;  // 66 bits cover the 63 of a key
  constexpr size_t kBuckets = size_t{1} << kBits;
  const size_t n = faces.size();
  std::vector<uint32_t> count(kPasses * kBuckets, 0);
  for (const ChunkFace& f : faces)
    for (int pass = 0; pass < kPasses; ++pass)
      ++count[pass * kBuckets + ((f.morton >> (kBits * pass)) & (kBuckets - 1))];
  scratch.resize(n);
  ChunkFace* from = faces.data();
  ChunkFace* to = scratch.data();
  for (int pass = 0; pass < kPasses; ++pass) {
    uint32_t* bucket = &count[pass * kBuckets];
    if (std::find(bucket, bucket + kBuckets, static_cast<uint32_t>(n)) != bucket + kBuckets) continue;  // one digit
    uint32_t sum = 0;
    for (size_t b = 0; b < kBuckets; ++b) sum += std::exchange(bucket[b], sum);
    for (size_t i = 0; i < n; ++i) to[bucket[(from[i].morton >> (kBits * pass)) & (kBuckets - 1)]++] = from[i];
    std::swap(from, to);
  }
  if (from != faces.data()) faces.swap(scratch);
}

}  // namespace

void VertexTable::reset(size_t expected) {
  size_t want = 64;
  while (want < 2 * expected) want *= 2;
  if (want > keys_.size()) {
    keys_.assign(want, 0);
    values_.assign(want, 0);
    stamps_.assign(want, 0);
    stamp_ = 0;
  }
  if (++stamp_ == 0) {  // wrapped: clear the stamps once
    std::fill(stamps_.begin(), stamps_.end(), 0u);
    stamp_ = 1;
  }
  size_ = 0;
}

void VertexTable::grow() {
  std::vector<uint32_t> keys, values;
  for (size_t i = 0; i < keys_.size(); ++i)
    if (stamps_[i] == stamp_) {
      keys.push_back(keys_[i]);
      values.push_back(values_[i]);
    }
  keys_.assign(2 * keys_.size(), 0);
  values_.assign(keys_.size(), 0);
  stamps_.assign(keys_.size(), 0);
  stamp_ = 1;
  const size_t mask = keys_.size() - 1;
  for (size_t j = 0; j < keys.size(); ++j) {
    size_t i = slot(keys[j], mask);
    while (stamps_[i] == stamp_) i = (i + 1) & mask;
    stamps_[i] = stamp_;
    keys_[i] = keys[j];
    values_[i] = values[j];
  }
}

uint32_t VertexTable::find_or_add(uint32_t v, uint32_t& next, bool& added) {
  if (2 * (size_ + 1) > keys_.size()) grow();
  const size_t mask = keys_.size() - 1;
  size_t i = slot(v, mask);
  while (stamps_[i] == stamp_) {
    if (keys_[i] == v) {
      added = false;
      return values_[i];
    }
    i = (i + 1) & mask;
  }
  stamps_[i] = stamp_;
  keys_[i] = v;
  values_[i] = next;
  added = true;
  ++size_;
  return next++;
}

void build_chunk_mesh(const Mesh& mesh, std::span<const uint32_t> faces, const std::array<double, 3>& origin,
                      double size, std::span<const uint8_t> seam_faces, ChunkWorker& w) {
  const float* pos = mesh.positions.data();
  const uint32_t* idx = mesh.indices.data();
  const double inverse = 1.0 / size;
  w.faces.resize(faces.size());
  for (size_t i = 0; i < faces.size(); ++i) {
    const uint32_t f = faces[i];
    const float* p[3] = {pos + 3 * size_t{idx[3 * f]}, pos + 3 * size_t{idx[3 * f + 1]},
                         pos + 3 * size_t{idx[3 * f + 2]}};
    uint32_t r = 0;
    if (point_less(p[1], p[r])) r = 1;
    if (point_less(p[2], p[r])) r = 2;
    uint64_t morton = 0;
    for (int k = 0; k < 3; ++k) {
      const double sum = sum_smallest_first(p[0][k], p[1][k], p[2][k]);  // as the chunk rule adds them
      const double t = (sum / 3.0 - origin[static_cast<size_t>(k)]) * inverse;
      // Clamped, then truncated: the floor of what lies in range, without a call to floor.
      const double q = std::clamp(t * double{1 << 21}, 0.0, double{(1 << 21) - 1});
      morton |= spread3(static_cast<uint64_t>(q)) << k;
    }
    w.faces[i] = ChunkFace{morton, f, r};
  }
  auto corner = [&](const ChunkFace& face, uint32_t k) {
    return pos + 3 * size_t{idx[3 * size_t{face.face} + (face.rotation + k) % 3]};
  };
  // By Morton key, then (faces in one key's box, rare) by their corners, then by face.
  sort_by_morton(w.faces, w.sorting);
  const auto less_in_key = [&](const ChunkFace& a, const ChunkFace& b) {
    for (uint32_t k = 0; k < 3; ++k) {
      const float *pa = corner(a, k), *pb = corner(b, k);
      if (point_less(pa, pb)) return true;
      if (point_less(pb, pa)) return false;
    }
    return a.face < b.face;  // the same triangle twice: indistinguishable anyway
  };
  for (auto run = w.faces.begin(); run != w.faces.end();) {
    auto end = run + 1;
    while (end != w.faces.end() && end->morton == run->morton) ++end;
    if (end - run > 1) std::sort(run, end, less_in_key);
    run = end;
  }
  const size_t n = w.faces.size();
  w.vertices.reset(n / 2 + 16);  // a surface has about half as many vertices as faces; grows when not
  w.mesh.indices.resize(3 * n);
  w.mesh.positions.clear();
  w.mesh.positions.reserve(3 * n);
  const bool seams = !seam_faces.empty();
  w.seam_flags.resize(seams ? n : 0);
  uint32_t next = 0;
  for (size_t i = 0; i < n; ++i) {
    const ChunkFace& face = w.faces[i];
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t v = idx[3 * size_t{face.face} + (face.rotation + k) % 3];
      bool added = false;
      w.mesh.indices[3 * i + k] = w.vertices.find_or_add(v, next, added);
      if (added) w.mesh.positions.insert(w.mesh.positions.end(), pos + 3 * size_t{v}, pos + 3 * size_t{v} + 3);
    }
    if (seams) w.seam_flags[i] = seam_faces[face.face];
  }
}

void write_chunk_atlas(const ChunkWorker& w, uint32_t first_patch, float* corner_uv, uint32_t* patch) {
  const float* uv = w.map.atlas.corner_uv.data();
  for (size_t i = 0; i < w.faces.size(); ++i) {
    const ChunkFace& face = w.faces[i];
    for (uint32_t k = 0; k < 3; ++k) {
      const size_t corner = 3 * size_t{face.face} + (face.rotation + k) % 3;
      corner_uv[2 * corner] = uv[6 * i + 2 * k];
      corner_uv[2 * corner + 1] = uv[6 * i + 2 * k + 1];
    }
    patch[face.face] = first_patch + w.map.atlas.patch[i];
  }
}

}  // namespace tailor::internal
