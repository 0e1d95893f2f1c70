// The metrics of a map as a file holds it, for callers that hold its pixels (map_texture): the
// public compute_stored_uv_metrics takes the stored repeats instead.
#pragma once

#include <span>

#include "tailor/mesh.h"
#include "tailor/metrics.h"
#include "tailor/topology.h"

namespace tailor::internal {

//! Whether the UVs in pixels `uv_px` come back bit for bit from the repeats a file stores
//! (uv_repeats_from_px, then times the texture size as a reader scales them): always for a
//! power-of-two texture size, barring underflow and negative zeros. O(F), no allocation.
bool stored_round_trip_exact(std::span<const float> uv_px, float width, float height);

//! compute_stored_uv_metrics on UVs in pixels that are already what the file gives back
//! (stored_round_trip_exact): the same figures, without the copy of the UVs.
Status compute_stored_uv_metrics_px(const Mesh& mesh, const Topology* topology, std::span<const float> uv_px,
                                    const MetricsOptions& options, UvMetrics& metrics, StoredSurface* surface);

}  // namespace tailor::internal
