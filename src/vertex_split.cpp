// Vertex splitting on (vertex, uv) for export, and its inverse (welding identical positions) for
// readers of split files. Both use one flat open-addressing table (linear probing, power-of-two
// size, load <= 0.5) storing output ids; keys are compared against the output arrays themselves,
// so nothing is allocated per element. (Same approach as meshoptimizer's indexgenerator.cpp and
// xatlas's Vertex::xref.)
#include <bit>
#include <cstring>

#include "tailor/export.h"

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

}  // namespace

void split_vertices(const Mesh& mesh, std::span<const float> corner_uv, SplitMesh& out) {
  const size_t corners = mesh.indices.size();
  out.positions.clear();
  out.uvs.clear();
  out.xref.clear();
  out.indices.resize(corners);
  out.xref.reserve(mesh.vertex_count());
  out.uvs.reserve(2 * mesh.vertex_count());

  const size_t table_size = table_size_for(corners);
  const size_t mask = table_size - 1;
  std::vector<uint32_t> table(table_size, kInvalid);
  for (size_t c = 0; c < corners; ++c) {
    const uint32_t v = mesh.indices[c];
    const float u = corner_uv[2 * c] + 0.0f, w = corner_uv[2 * c + 1] + 0.0f;
    const uint32_t ub = float_bits(u), wb = float_bits(w);
    size_t slot = mix64((uint64_t{v} << 32) ^ mix64((uint64_t{ub} << 32) | wb)) & mask;
    uint32_t id = kInvalid;
    while (table[slot] != kInvalid) {
      const uint32_t s = table[slot];
      if (out.xref[s] == v && float_bits(out.uvs[2 * size_t{s}]) == ub && float_bits(out.uvs[2 * size_t{s} + 1]) == wb) {
        id = s;
        break;
      }
      slot = (slot + 1) & mask;
    }
    if (id == kInvalid) {
      id = static_cast<uint32_t>(out.xref.size());
      table[slot] = id;
      out.xref.push_back(v);
      out.uvs.push_back(u);
      out.uvs.push_back(w);
    }
    out.indices[c] = id;
  }
  const size_t split_count = out.xref.size();
  out.positions.resize(3 * split_count);
  for (size_t s = 0; s < split_count; ++s)
    std::memcpy(&out.positions[3 * s], &mesh.positions[3 * size_t{out.xref[s]}], 3 * sizeof(float));
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
