// Shared by the reader fuzz targets: what a successfully loaded mesh must satisfy. A violation
// aborts, so libFuzzer reports it like a crash (the readers must never return a bad mesh).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "tailor/io.h"

inline int fuzz_read_mesh(const uint8_t* data, size_t size, tailor::MeshFormat format) {
  tailor::Mesh mesh;
  tailor::LoadReport report;
  const std::span<const char> bytes(reinterpret_cast<const char*>(data), size);
  const tailor::Status s = tailor::read_mesh(bytes, format, "fuzz", mesh, &report);
  if (!s.is_ok()) {
    if (!mesh.empty() || s.what().empty()) std::abort();
    return 0;
  }
  const size_t nv = mesh.vertex_count();
  if (mesh.empty() || mesh.indices.size() % 3 != 0 || mesh.positions.size() % 3 != 0) std::abort();
  for (uint32_t i : mesh.indices) {
    if (i >= nv) std::abort();
  }
  for (float x : mesh.positions) {
    if (!std::isfinite(x)) std::abort();
  }
  if (!mesh.corner_uvs.empty() && mesh.corner_uvs.size() != 6 * mesh.face_count()) std::abort();
  if (!mesh.seam_faces.empty() && mesh.seam_faces.size() != mesh.face_count()) std::abort();
  return 0;
}
