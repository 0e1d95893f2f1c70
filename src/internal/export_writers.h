// Per-format writers behind export_mesh (export.cpp). export.cpp validates the inputs, splits the
// vertices and computes normals once; each writer only serialises and writes atomically.
#pragma once

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "tailor/export.h"
#include "tailor/mesh.h"
#include "tailor/status.h"

namespace tailor::internal {

//! What every writer gets: the source mesh, its vertices split on UV with uvs in texture repeats
//! (OBJ convention, t up: see export.h), and unit normals per SOURCE vertex (#V by 3, or empty).
//! split.positions is left EMPTY: writers read mesh->positions[3 * split.xref[s]] as they stream,
//! which saves an array of 12 bytes per split vertex.
struct ExportData {
  const Mesh* mesh = nullptr;
  SplitMesh split;
  std::vector<float> normals;
};

//! split_vertices_scaled's result when every UV is finite.
inline constexpr size_t kNoBadCorner = static_cast<size_t>(-1);

//! split_vertices on the UVs corner_uv (#F*3 by 2, pixels) scaled to (float)(u * su), (float)(v * sv)
//! on the fly, bit for bit what scaling into an array first and splitting that gives, but without
//! the array. Leaves out.positions empty (split_positions fills it). Returns kNoBadCorner, or the
//! first corner whose scaled UV is not finite (`out` is then incomplete). Precondition: mesh.indices
//! are < vertex_count() and corner_uv.size() == 2 * mesh.indices.size(). O(corners).
size_t split_vertices_scaled(const Mesh& mesh, std::span<const float> corner_uv, double su, double sv, SplitMesh& out);

//! Fills split.positions (#S by 3) from mesh.positions through split.xref.
void split_positions(const Mesh& mesh, SplitMesh& split);

//! A texture file's bytes and MIME type ("image/png" or "image/jpeg", from the magic bytes).
//! Fails with kIo (unreadable) or kInvalidImage (neither PNG nor JPEG).
Status read_texture_bytes(const std::string& path, std::string& bytes, std::string& mime_type);

//! Appends the shortest decimal text that reads back as exactly `value` (std::to_chars).
void append_float(std::string& out, float value);

//! Path of `target` relative to the folder `base_dir` (generic separators), or absolute when none exists.
std::string relative_path(const std::string& target, const std::filesystem::path& base_dir);

Status write_glb(const std::string& path, const ExportData& data, const ExportOptions& options);
Status write_obj(const std::string& path, const ExportData& data, const ExportOptions& options);
Status write_ply(const std::string& path, const ExportData& data, const ExportOptions& options);

}  // namespace tailor::internal
