// Vertex splitting on (vertex, uv) for export, and its inverse (welding identical positions) for
// readers of split files.
//
// Splitting: most vertices get one UV, a seam vertex a few. So each source vertex keeps the id of
// its newest split vertex (first[v]) and the split vertices of one source vertex are chained
// (next[s]); a corner walks its vertex's chain comparing UV bits. That is O(corners) with two
// small arrays (4 bytes per vertex and per split vertex), where a hash table of 2 x corners
// entries (64 MB on a 1.5 M face mesh) costs a cache miss per corner: 6x faster on that mesh. Ids
// are assigned in order of first corner whatever the chain order, so the result does not depend
// on the method. A vertex with very many distinct UVs (a fan of hundreds of patches) would make
// its chain walks quadratic: past a budget of steps the split restarts with one flat
// open-addressing table (linear probing, power-of-two size, load <= 0.5) whose keys are compared
// against the output arrays themselves, as meshoptimizer's indexgenerator.cpp and xatlas's
// Vertex::xref do. Welding uses the same kind of table.
// The corner UVs are converted (scaled, -0 -> +0) a block at a time, two corners per SSE2 step
// where available, with the same IEEE operations as the scalar code, hence the same bits.
#include "surface/vertex_split.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "tailor/export.h"
#include "util/huge_pages.h"
#include "util/simd.h"

namespace tailor {
namespace {

// -0 and +0 compare equal but differ in bits: adding +0.0f turns -0 into +0.
uint32_t float_bits(float x) { return std::bit_cast<uint32_t>(x + 0.0f); }

uint64_t mix64(uint64_t x) {  // splitmix64 finaliser
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return x;
}

size_t table_size_for(size_t keys) {
  size_t size = 16;
  while (size < 2 * keys) size *= 2;
  return size;
}

// The two UV bits of split vertex s as one key (u in the low half), as stored: already +0.
uint64_t stored_key(const float* uvs, uint32_t s) {
  uint64_t key;
  std::memcpy(&key, uvs + 2 * size_t{s}, 8);
  return key;
}

uint64_t key_of(float u, float w) {
  return uint64_t{std::bit_cast<uint32_t>(u)} | (uint64_t{std::bit_cast<uint32_t>(w)} << 32);
}

// Where a split starts: clears the outputs and reserves them. The reservations of xref and uvs are
// upper bounds (every corner its own vertex); pages never written are never touched, so they cost
// nothing.
void start_split(const Mesh& mesh, SplitMesh& out) {
  const size_t corners = mesh.indices.size();
  out.positions.clear();
  out.uvs.clear();
  out.xref.clear();
  out.indices.clear();
  internal::reserve_huge(out.indices, corners);  // push_back: no zero-fill of pages written anyway
  internal::reserve_huge(out.xref, corners);
  internal::reserve_huge(out.uvs, 2 * corners);
}

// Corner UV sources, passed by value so that the loops keep their fields in registers. Each writes
// the UVs of corners [begin, end) to out (2 floats per corner), normalised to +0, in a loop the
// compiler vectorizes, and returns false when one of them is rejected (first_rejected then says
// which).
struct RepeatUv {  // UVs already in repeats, taken as they are (split_vertices)
  const float* uv;
  bool operator()(size_t begin, size_t end, float* out) const {
    const float* in = uv + 2 * begin;
    for (size_t i = 0; i < 2 * (end - begin); ++i) out[i] = in[i] + 0.0f;
    return true;
  }
  size_t first_rejected(size_t, size_t) const { return internal::kNoBadCorner; }
};

struct ScaledUv {  // pixels scaled as an array of repeats would be: double product, float cast, +0
  const float* px;
  double su, sv;
  bool operator()(size_t begin, size_t end, float* out) const {
    const float* in = px + 2 * begin;
    const size_t n = 2 * (end - begin);
    size_t i = 0;
    bool finite = true;
#if TAILOR_SSE2
    // Two corners per step: (u0 v0 u1 v1) -> doubles (u0 v0), (u1 v1) times (su sv) -> floats.
    // The same IEEE operations as the scalar loop below, so the same bits.
    const __m128d scale = _mm_set_pd(sv, su);
    const __m128d max = _mm_set1_pd(std::numeric_limits<double>::max());
    const __m128d abs_mask = _mm_castsi128_pd(_mm_set1_epi64x(0x7fffffffffffffffLL));
    const __m128 zero = _mm_setzero_ps();
    __m128d ok = _mm_castsi128_pd(_mm_set1_epi64x(-1));
    for (; i + 4 <= n; i += 4) {
      const __m128 f = _mm_loadu_ps(in + i);
      const __m128d lo = _mm_mul_pd(_mm_cvtps_pd(f), scale);
      const __m128d hi = _mm_mul_pd(_mm_cvtps_pd(_mm_movehl_ps(f, f)), scale);
      ok = _mm_and_pd(ok, _mm_cmple_pd(_mm_and_pd(lo, abs_mask), max));  // false for inf and NaN
      ok = _mm_and_pd(ok, _mm_cmple_pd(_mm_and_pd(hi, abs_mask), max));
      const __m128 r = _mm_movelh_ps(_mm_cvtpd_ps(lo), _mm_cvtpd_ps(hi));
      _mm_storeu_ps(out + i, _mm_add_ps(r, zero));
    }
    finite = _mm_movemask_pd(ok) == 3;
#endif
    for (; i < n; i += 2) {
      const double du = in[i] * su, dv = in[i + 1] * sv;
      finite &= std::isfinite(du) && std::isfinite(dv);
      out[i] = static_cast<float>(du) + 0.0f;
      out[i + 1] = static_cast<float>(dv) + 0.0f;
    }
    return finite;
  }
  size_t first_rejected(size_t begin, size_t end) const {
    for (size_t c = begin; c < end; ++c)
      if (!std::isfinite(px[2 * c] * su) || !std::isfinite(px[2 * c + 1] * sv)) return c;
    return internal::kNoBadCorner;
  }
};

// Corners whose UVs are converted at once (a 16 KiB buffer on the stack).
constexpr size_t kUvBlock = 2048;

// A split vertex is new: appends it (xref, uvs) and returns its id.
uint32_t add_split_vertex(uint32_t v, float u, float w, SplitMesh& out) {
  const auto id = static_cast<uint32_t>(out.xref.size());
  out.xref.push_back(v);
  out.uvs.push_back(u);
  out.uvs.push_back(w);
  return id;
}

// The chained split. Returns kNoBadCorner when done, else the corner whose UV uv_of rejected, or,
// with `over_budget` set, the corner where the chain walks exceeded their budget (the caller then
// uses split_with_table); `out` is then incomplete.
template <class UvOf>
size_t split_with_chains(const Mesh& mesh, const UvOf uv_of, SplitMesh& out, bool& over_budget) {
  const size_t corners = mesh.indices.size();
  start_split(mesh, out);
  std::vector<uint32_t> first_of(mesh.vertex_count(), kInvalid);
  internal::HugeArray<uint32_t> next_of = internal::huge_uninitialized<uint32_t>(corners);
  const uint32_t* const source_index = mesh.indices.data();
  uint32_t* const first = first_of.data();
  uint32_t* const next = next_of.get();
  // A corner that finds its UV at the head of its chain takes no step; each further link is one.
  // Ordinary meshes take well under a step per corner; this bounds the walks to O(corners).
  size_t budget = 4 * corners + 4096;
  float block_uv[2 * kUvBlock];
  for (size_t begin = 0; begin < corners; begin += kUvBlock) {
    const size_t end = std::min(corners, begin + kUvBlock);
    if (!uv_of(begin, end, block_uv)) return uv_of.first_rejected(begin, end);
    for (size_t c = begin; c < end; ++c) {
      const uint32_t v = source_index[c];
      const uint64_t key = stored_key(block_uv, static_cast<uint32_t>(c - begin));
      const float* const uvs = out.uvs.data();
      uint32_t id = first[v];
      while (id != kInvalid && stored_key(uvs, id) != key) {
        id = next[id];
        if (budget-- == 0) {
          over_budget = true;
          return c;
        }
      }
      if (id == kInvalid) {
        id = add_split_vertex(v, block_uv[2 * (c - begin)], block_uv[2 * (c - begin) + 1], out);
        next[id] = first[v];
        first[v] = id;
      }
      out.indices.push_back(id);
    }
  }
  return internal::kNoBadCorner;
}

// The same result with one hash table over (vertex, uv): O(corners) whatever the valences.
template <class UvOf>
size_t split_with_table(const Mesh& mesh, const UvOf uv_of, SplitMesh& out) {
  const size_t corners = mesh.indices.size();
  start_split(mesh, out);
  const size_t table_size = table_size_for(corners);
  const size_t mask = table_size - 1;
  std::vector<uint32_t> table(table_size, kInvalid);
  float block_uv[2 * kUvBlock];
  for (size_t c = 0; c < corners; ++c) {
    if (c % kUvBlock == 0 && !uv_of(c, std::min(corners, c + kUvBlock), block_uv))
      return uv_of.first_rejected(c, std::min(corners, c + kUvBlock));
    const uint32_t v = mesh.indices[c];
    const float u = block_uv[2 * (c % kUvBlock)], w = block_uv[2 * (c % kUvBlock) + 1];
    const uint32_t ub = std::bit_cast<uint32_t>(u), wb = std::bit_cast<uint32_t>(w);
    const uint64_t key = key_of(u, w);
    size_t slot = mix64((uint64_t{v} << 32) ^ mix64((uint64_t{ub} << 32) | wb)) & mask;
    uint32_t id = kInvalid;
    while (table[slot] != kInvalid) {
      const uint32_t s = table[slot];
      if (out.xref[s] == v && stored_key(out.uvs.data(), s) == key) {
        id = s;
        break;
      }
      slot = (slot + 1) & mask;
    }
    if (id == kInvalid) {
      id = add_split_vertex(v, u, w, out);
      table[slot] = id;
    }
    out.indices.push_back(id);
  }
  return internal::kNoBadCorner;
}

template <class UvOf>
size_t split_any(const Mesh& mesh, const UvOf uv_of, SplitMesh& out) {
  bool over_budget = false;
  const size_t stopped = split_with_chains(mesh, uv_of, out, over_budget);
  return over_budget ? split_with_table(mesh, uv_of, out) : stopped;
}

}  // namespace

namespace internal {

void split_positions(const Mesh& mesh, SplitMesh& split) {
  const size_t split_count = split.xref.size();
  split.positions.clear();
  reserve_huge(split.positions, 3 * split_count);
  split.positions.resize(3 * split_count);
  for (size_t s = 0; s < split_count; ++s)
    std::memcpy(&split.positions[3 * s], &mesh.positions[3 * size_t{split.xref[s]}], 3 * sizeof(float));
}

size_t split_vertices_scaled(const Mesh& mesh, std::span<const float> corner_uv, double su, double sv, SplitMesh& out) {
  return split_any(mesh, ScaledUv{corner_uv.data(), su, sv}, out);
}

}  // namespace internal

void split_vertices(const Mesh& mesh, std::span<const float> corner_uv, SplitMesh& out) {
  split_any(mesh, RepeatUv{corner_uv.data()}, out);
  internal::split_positions(mesh, out);
}

size_t weld_identical_positions(Mesh& mesh) {
  const size_t nv = mesh.vertex_count();
  const size_t table_size = table_size_for(nv);
  const size_t mask = table_size - 1;
  std::vector<uint32_t> table(table_size, kInvalid);
  std::vector<uint32_t> remap(nv);
  uint32_t kept = 0;
  for (size_t v = 0; v < nv; ++v) {
    const float* p = &mesh.positions[3 * v];
    const uint32_t x = float_bits(p[0]), y = float_bits(p[1]), z = float_bits(p[2]);
    size_t slot = mix64(mix64((uint64_t{x} << 32) | y) ^ z) & mask;
    uint32_t id = kInvalid;
    while (table[slot] != kInvalid) {
      const float* q = &mesh.positions[3 * size_t{table[slot]}];  // already compacted, in place
      if (float_bits(q[0]) == x && float_bits(q[1]) == y && float_bits(q[2]) == z) {
        id = table[slot];
        break;
      }
      slot = (slot + 1) & mask;
    }
    if (id == kInvalid) {
      id = kept++;
      table[slot] = id;
      // Compact in place: id <= v, so this never overwrites a vertex not yet visited.
      std::memmove(&mesh.positions[3 * size_t{id}], p, 3 * sizeof(float));
    }
    remap[v] = id;
  }
  mesh.positions.resize(3 * size_t{kept});
  for (uint32_t& index : mesh.indices) index = remap[index];
  return nv - kept;
}

}  // namespace tailor
