// ChunkedMapper (tailor/chunked_mapper.h): the chunked engine's chunks kept one by one. set_chunk
// maps one chunk as map_chunks does inside a whole mesh (chunk_mesh.h, map_chunk); set_mesh runs
// map_chunks and keeps each chunk's share.
#include "tailor/chunked_mapper.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <tuple>

#include "mapping/chunk_mesh.h"
#include "mapping/mapping_common.h"

namespace tailor {
namespace {

// Whether a cell can hold faces: the rule's cells lie within 2^20 of the origin on each axis (21
// bits each, as pack keeps them); any other would alias one of them.
bool in_grid(const ChunkCell& cell) {
  return std::all_of(cell.begin(), cell.end(), [](int32_t c) { return c >= -(1 << 20) && c < (1 << 20); });
}

uint64_t pack(const ChunkCell& cell) {
  uint64_t key = 0;
  for (int k = 2; k >= 0; --k) key = (key << 21) | (static_cast<uint64_t>(cell[static_cast<size_t>(k)]) & 0x1FFFFF);
  return key;
}

bool cell_less(const ChunkCell& a, const ChunkCell& b) {
  return std::tie(a[2], a[1], a[0]) < std::tie(b[2], b[1], b[0]);
}

}  // namespace

ChunkedMapper::ChunkedMapper(const MapTextureOptions& options, int cell_exponent, double texels_per_unit)
    : options_(options),
      cell_exponent_(cell_exponent),
      cell_size_(std::ldexp(1.0, std::clamp(cell_exponent, -60, 60))),
      // The density as the whole-mesh path carries it (MappingOptions::scale is a float).
      texels_per_unit_(static_cast<double>(static_cast<float>(texels_per_unit))) {
  options_.stage_progress = nullptr;
  options_.mapping.progress = nullptr;
  options_.orientation.progress = nullptr;
  options_.measure = false;
  options_.mapping.seam_faces = {};
}

Status ChunkedMapper::check() const {
  if (cell_exponent_ < -60 || cell_exponent_ > 60)
    return Status::error(ErrorCode::kInvalidArgument, "", "chunk cell exponent must be in -60..60");
  if (!(texels_per_unit_ > 0) || !std::isfinite(texels_per_unit_))
    return Status::error(ErrorCode::kInvalidArgument, "", "texels per unit must be a positive number");
  TAILOR_RETURN_IF_ERROR(internal::check_chunk_scale(texels_per_unit_, cell_size_));
  if (options_.orientation.axis == AxisSource::kSkeleton)
    return Status::error(ErrorCode::kInvalidArgument, "", "the skeleton axis needs the whole mesh, not chunks");
  TAILOR_RETURN_IF_ERROR(check_map_options(options_));  // the front ends' words first
  return internal::check_mapping_values(options_.mapping);
}

Status ChunkedMapper::set_chunk(const ChunkCell& cell, const Mesh& faces) {
  TAILOR_RETURN_IF_ERROR(check());
  if (faces.empty()) return Status::error(ErrorCode::kInvalidMesh, "", "a chunk needs at least one face");
  if (!faces.seam_faces.empty() && faces.seam_faces.size() != faces.face_count())
    return Status::error(ErrorCode::kInvalidMesh, "", "seam face flags must hold one entry per face");
  // The rule's own test: the plan of these faces alone must be this one cell (in one or more parts).
  ChunkOptions rule;
  rule.mode = ChunkMode::kOn;
  rule.cell_exponent = cell_exponent_;
  rule.split_above = options_.chunks.split_above;
  ChunkPlan plan;
  TAILOR_RETURN_IF_ERROR(plan_chunks(faces, rule, plan, options_.mapping.threads));
  const auto outside =
      std::find_if(plan.cells.begin(), plan.cells.end(), [&](const ChunkCell& c) { return c != cell; });
  if (outside != plan.cells.end()) {
    const size_t c = static_cast<size_t>(outside - plan.cells.begin());
    return Status::error(
        ErrorCode::kInvalidArgument, "",
        "face " + std::to_string(plan.faces[plan.chunk_start[c]]) + " has its centroid outside the chunk's cell",
        "cell " + std::to_string(cell[0]) + "," + std::to_string(cell[1]) + "," + std::to_string(cell[2]));
  }
  // Each part of the cell (one unless it holds more than the rule's split_above faces) as map_chunks
  // maps it, back to the faces' own order and corners, its patch ids after the parts' before it.
  ChunkResult result;
  const size_t n = faces.face_count();
  result.faces.resize(n);
  for (size_t f = 0; f < n; ++f) result.faces[f] = static_cast<uint32_t>(f);
  result.corner_uv.resize(6 * n);
  result.patch.resize(n);
  internal::ChunkWorker w;
  for (size_t c = 0; c < plan.chunk_count(); ++c) {
    const std::span<const uint32_t> part(plan.faces.data() + plan.chunk_start[c],
                                         plan.chunk_start[c + 1] - plan.chunk_start[c]);
    internal::build_chunk_mesh(faces, part, plan.chunk_origin(c), plan.chunk_size(c), faces.seam_faces, w);
    TAILOR_RETURN_IF_ERROR(internal::map_chunk(options_, plan.chunk_origin(c), plan.chunk_size(c), texels_per_unit_,
                                               options_.mapping.threads, {}, w));
    internal::write_chunk_atlas(w, result.patch_count, result.corner_uv.data(), result.patch.data());
    result.patch_count += w.map.atlas.patch_count;
    internal::add_stats(w.map.stats, result.stats);
  }
  result.stats.patches = result.patch_count;
  chunks_[pack(cell)] = std::move(result);
  return Status::ok();
}

Status ChunkedMapper::set_mesh(const Mesh& mesh, std::vector<ChunkCell>* cells) {
  TAILOR_RETURN_IF_ERROR(check());
  if (!mesh.seam_faces.empty() && mesh.seam_faces.size() != mesh.face_count())
    return Status::error(ErrorCode::kInvalidMesh, "", "seam face flags must hold one entry per face");
  MapTextureOptions o = options_;
  o.chunks.mode = ChunkMode::kOn;
  o.chunks.cell_exponent = cell_exponent_;
  o.mapping.scale = static_cast<float>(texels_per_unit_);  // with unit 1: pixels per world unit
  o.orientation.fixed_unit_scale = 1.f;
  o.mapping.seam_faces = mesh.seam_faces;
  TextureMap map;
  ChunkPlan plan;
  TAILOR_RETURN_IF_ERROR(internal::map_chunks(mesh, o, map, &plan));
  if (cells) cells->clear();
  // One result per cell: the parts of a split cell are consecutive chunks, their patches consecutive ids.
  for (size_t c = 0, end; c < plan.chunk_count(); c = end) {
    for (end = c + 1; end < plan.chunk_count() && plan.cells[end] == plan.cells[c];) ++end;
    const std::span<const uint32_t> faces(plan.faces.data() + plan.chunk_start[c],
                                          plan.chunk_start[end] - plan.chunk_start[c]);
    ChunkResult result;
    result.faces.assign(faces.begin(), faces.end());
    result.corner_uv.reserve(6 * faces.size());
    result.patch.reserve(faces.size());
    uint32_t first = kInvalid, last = 0;
    for (const uint32_t f : faces) {
      first = std::min(first, map.atlas.patch[f]);
      last = std::max(last, map.atlas.patch[f]);
    }
    for (const uint32_t f : faces) {
      const auto uv = map.atlas.corner_uv.begin() + static_cast<std::ptrdiff_t>(6 * size_t{f});
      result.corner_uv.insert(result.corner_uv.end(), uv, uv + 6);
      result.patch.push_back(map.atlas.patch[f] - first);
    }
    result.patch_count = last - first + 1;
    chunks_[pack(plan.cells[c])] = std::move(result);
    if (cells) cells->push_back(plan.cells[c]);
  }
  return Status::ok();
}

bool ChunkedMapper::remove_chunk(const ChunkCell& cell) { return in_grid(cell) && chunks_.erase(pack(cell)) > 0; }

const ChunkResult* ChunkedMapper::chunk(const ChunkCell& cell) const {
  if (!in_grid(cell)) return nullptr;
  const auto it = chunks_.find(pack(cell));
  return it == chunks_.end() ? nullptr : &it->second;
}

std::vector<ChunkCell> ChunkedMapper::cells() const {
  std::vector<ChunkCell> out;
  out.reserve(chunks_.size());
  for (const auto& [key, result] : chunks_) {
    ChunkCell cell;
    for (size_t k = 0; k < 3; ++k) {
      const uint64_t bits = (key >> (21 * k)) & 0x1FFFFF;
      cell[k] = static_cast<int32_t>(bits >= (uint64_t{1} << 20) ? static_cast<int64_t>(bits) - (int64_t{1} << 21)
                                                                 : static_cast<int64_t>(bits));
    }
    out.push_back(cell);
  }
  std::sort(out.begin(), out.end(), cell_less);
  return out;
}

}  // namespace tailor
