// Vertex splitting for the export stage (the public split_vertices is in tailor/export.h): the
// scaled split that export_mesh runs without a scaled copy of the UVs, and the positions fill.
#pragma once

#include <cstddef>
#include <span>

#include "tailor/export.h"
#include "tailor/mesh.h"

namespace tailor::internal {

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

}  // namespace tailor::internal
